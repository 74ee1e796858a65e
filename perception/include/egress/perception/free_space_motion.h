#pragma once
/// @file
/// FreeSpaceMotion: whether what the laser sees at a place moved, judged along the beams, so that
/// the robot's own motion does not read as the world's. A return that lies where an earlier
/// scan's beams passed through (seen free then) is something that came there; an earlier return
/// where the latest scan's beams pass through is something that has left. A return the earlier
/// scan also hit, or could not see (behind something nearer), says nothing of motion.
///
/// Why along the beams: seen from a laser that moves, a person standing still shows a different
/// arc of each leg, legs slide in and out of each other's shadows, and a leg-pair's or a body
/// section's centre shifts by centimetres to decimetres between scans. Differenced, that read a
/// standing group as walking at 0.4-3 m/s (the escort's residents waiting by a door; the robot
/// broke off its approach for people "coming"). None of those shifts puts a surface where a beam
/// passed before: a standing body's surface stays where it was, only which part of it is visible
/// changes. ScanMotion, which compares returns by distance, must stop judging once the laser moves.
///
/// Each scan is kept with its laser pose X_ML (in M) as it was estimated then; `margin` and
/// `beam_halo` absorb the pose estimate's wander between the two scans and the beams'
/// discreteness at a surface's silhouette (a return counts as seen through only when the earlier
/// beams on its bearing and `beam_halo` either side all reached `margin` beyond it).

#include <deque>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"
#include "egress/hsr_interface/time.h"

namespace egress::perception {

struct FreeSpaceMotionConfig {
  /// Compare the latest scan with the newest one at least this much older [s]: a walker's leg
  /// travels 0.3-0.6 m in that time, a slow walker (0.4 m/s) 0.16 m, well past `margin`.
  double baseline{0.4};
  double margin{0.08};    ///< A beam passed through a point when it reached this far beyond it [m].
  int beam_halo{2};       ///< ... and so did this many beams either side of its bearing.
  double max_range{6.0};  ///< Returns farther than this from the laser are not judged [m].
  /// Earlier returns this much farther than the place's radius are judged for having left: a
  /// walker going straight away left her returns of `baseline` ago ~0.5 m behind her [m].
  double leave_reach{0.4};
  /// A place moved when at least this many of its returns did, and at least `min_moved_share`
  /// of those judged. Escorts (lab, office, atrium, 6 trials each, against ground truth): people
  /// standing read moved in 1.2 % of scans with the robot driving (0.2 % with it still), walkers
  /// read still in 3-6 % (3 and 0.2: 0.5 % and 6-9 %; 1 and 0: 7.6 % and 1-3 %).
  int min_moved_points{2};
  double min_moved_share{0.1};  ///< See min_moved_points.
  int min_judged_points{4};     ///< Fewer returns judged than this: unknown.
  /// @throws InvalidArgument naming the field that is non-finite or out of range.
  void Validate() const;
};

enum class PlaceMotion {
  kUnknown,  ///< No earlier scan, or too few of the place's returns could be judged.
  kStill,    ///< Its returns stayed where the earlier scan saw surfaces (or could not see).
  kMoved,    ///< Something came where the earlier scan saw free space, or left where it was.
};

class FreeSpaceMotion {
 public:
  explicit FreeSpaceMotion(FreeSpaceMotionConfig config = {});

  /// Feeds a scan taken by a laser at X_ML (in M). Stamps must not go back.
  /// @throws InvalidArgument for a malformed scan, a non-finite pose or a stamp going back.
  void AddScan(const LaserScan& scan, const Pose2& X_ML);

  /// Whether the returns of the latest scan within `radius` of p_M (and the earlier scan's within
  /// radius + leave_reach) moved. kUnknown until a scan `baseline` older than the latest is held.
  /// @throws InvalidArgument for a non-finite place or radius.
  PlaceMotion Judge(const Eigen::Vector2d& p_M, double radius) const;

  const FreeSpaceMotionConfig& config() const { return config_; }

 private:
  struct Scan {
    LaserScan scan;
    Pose2 X_ML;
    Eigen::Matrix2d R_ML;  ///< X_ML's rotation (R_LM is its transpose).
  };
  enum class Seen { kThrough, kSurface, kHidden };
  /// How `earlier` saw the point p_M: its beams passed through it, hit it, or stopped short.
  Seen SeenBy(const Scan& earlier, const Eigen::Vector2d& p_M) const;
  /// Calls `visit(p_M)` for each return of `scan` (within max_range of the laser) within
  /// `radius` of p_C: only the beams whose bearing can reach that disc are looked at.
  template <typename Visit>
  void ForEachReturnNear(const Scan& scan, const Eigen::Vector2d& p_C, double radius,
                         Visit&& visit) const;
  /// The newest held scan at least `baseline` older than the latest; null if none.
  const Scan* Reference() const;

  FreeSpaceMotionConfig config_;
  std::deque<Scan> history_;
  /// The beams' directions in L, for the scan geometry they were computed for (a scan's are its
  /// angle_min + i angle_increment: computed once, not per return).
  std::vector<Eigen::Vector2d> u_L_;
  double u_angle_min_{0.0}, u_angle_increment_{0.0};
};

}  // namespace egress::perception
