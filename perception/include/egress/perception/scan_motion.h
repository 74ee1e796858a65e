#pragma once
/// @file
/// ScanMotion: which of the laser's returns off the map are moving — the legs of someone
/// walking, as opposed to someone (or something) standing. A return moved when, against the
/// returns of about `window` seconds earlier, none lies within `step` of it but one lies within
/// `reach` that has itself gone (no return within `step` of it now): a walker's swinging leg
/// travels 0.3-0.6 m in half a second and leaves where it was, a standing one moves only by the
/// laser's noise (a centimetre or two). A return with nothing near it earlier came out from
/// behind an occluder, and one whose earlier neighbours are all still there is more of a standing
/// body seen past a shadow's edge (a ray that grazed a leg and now hits it): not motion either.
/// Points are in M (the map frame).
/// Only scans taken from the same spot are compared: seen from a moving laser, legs standing
/// still slide in and out of each other's shadows, which looks like motion; while the laser moves
/// (more than `still_distance` or `still_angle` from where the reference was taken) nothing is
/// reported moving; nor is anything farther than `max_range` from the laser.

#include <deque>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/time.h"

namespace egress::perception {

struct ScanMotionConfig {
  double window{0.5};           ///< Compare with the returns this long before [s].
  double step{0.15};            ///< A return farther than this from every earlier one moved [m].
  double reach{1.0};            ///< ... if an earlier one lies within this [m].
  double still_distance{0.03};  ///< The laser counts as still within this of the reference [m].
  double still_angle{0.03};     ///< ... and within this of its heading [rad].
  /// Returns farther than this from the laser are not judged [m]: there the pose estimate's
  /// heading error (a hundredth of a radian) shifts a wall's grazed returns by tens of
  /// centimetres off and along it as the estimate wanders, which looks like motion (in the
  /// clinic's corridor, its walls 8-14 m off "moved" while the robot stood still).
  double max_range{6.0};
  /// @throws InvalidArgument unless 0 < step < reach, window > 0 and max_range > 0 (all finite).
  void Validate() const;
};

class ScanMotion {
 public:
  explicit ScanMotion(ScanMotionConfig config = {});

  /// Feeds the returns off the map p_MR (in M) of a scan taken at `stamp` by a laser at X_ML;
  /// returns those that moved (empty until a scan from the same spot `window` older has been
  /// fed). Stamps must not go back.
  /// @throws InvalidArgument for a stamp earlier than the last one or a non-finite pose.
  const std::vector<Eigen::Vector2d>& Update(Time stamp, const Pose2& X_ML,
                                             std::vector<Eigen::Vector2d> p_MR);

  const std::vector<Eigen::Vector2d>& moving() const { return moving_; }

 private:
  ScanMotionConfig config_;
  struct Scan {
    Time stamp{};
    Pose2 X_ML;
    std::vector<Eigen::Vector2d> p_MR;
  };
  std::deque<Scan> history_;
  std::vector<Eigen::Vector2d> moving_;
};

}  // namespace egress::perception
