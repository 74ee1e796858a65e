#pragma once
/// @file
/// People: positions and velocities with exponential smoothing (the paper's alpha = 0.3), a
/// short-horizon forecast (4 steps of 0.2 s), and intent relative to a door: crossing the
/// doorway, holding the door, walking past, approaching, or stationary. The doorway-zone
/// occupancy forecast is what IsPathClear reads.

#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/time.h"
#include "egress/perception/door_estimation.h"

namespace egress::perception {

enum class PersonIntent {
  kUnknown,
  kStationary,
  kApproaching,
  kCrossing,
  kWalkingPast,
  kHoldingDoor
};
std::string_view ToString(PersonIntent intent);

struct PersonTrackerConfig {
  double alpha{0.3};          ///< Exponential smoothing of position and velocity.
  double gate_distance{1.0};  ///< Max jump between frames for the same person [m].
  int drop_misses{5};         ///< Frames without a detection before a track is dropped.
  int forecast_steps{4};
  double forecast_dt{0.2};  ///< [s]
  void Validate() const;
};

struct TrackedPerson {
  int id{0};
  Eigen::Vector2d p_MP{Eigen::Vector2d::Zero()};         ///< Smoothed position [m].
  Eigen::Vector2d v_MP{Eigen::Vector2d::Zero()};         ///< Smoothed velocity [m/s].
  Eigen::Vector2d p_MMeasured{Eigen::Vector2d::Zero()};  ///< The last detection, unsmoothed [m].
  std::vector<Eigen::Vector2d> forecast;  ///< Positions at k·forecast_dt, k = 1..steps.
  int hits{0};
  int misses{0};
  Time last_seen{};
  PersonIntent intent{PersonIntent::kUnknown};
  /// Where the person last stood (UpdateRestPoint) [m].
  Eigen::Vector2d p_MRest{Eigen::Vector2d::Zero()};
};

/// A tracked person slower than this [m/s] is standing: their rest point follows them.
inline constexpr double kRestSpeedMps = 0.2;

/// Moves the person's rest point to where they are while they are slower than kRestSpeedMps,
/// and leaves it where they last stood once they are faster. How far they are from it tells
/// someone walking off from a tracker's wobble: a standing person's smoothed velocity goes over
/// walking pace for a frame or two now and then (a detection placed a little off), but they
/// stay within centimetres of where they stood.
void UpdateRestPoint(TrackedPerson& person);

class PersonTracker {
 public:
  explicit PersonTracker(PersonTrackerConfig config = {});
  /// One frame of person positions in M (from placed "person" detections).
  void Update(const std::vector<Eigen::Vector2d>& p_MDetections, Time stamp);
  const std::vector<TrackedPerson>& people() const { return people_; }
  std::vector<TrackedPerson>& mutable_people() { return people_; }
  const PersonTrackerConfig& config() const { return config_; }

 private:
  PersonTrackerConfig config_;
  std::vector<TrackedPerson> people_;
  int next_id_{1};
  Time last_stamp_{};
  bool has_stamp_{false};
};

/// The doorway zone: the opening between the jambs, `depth` to each side of the door line.
struct DoorZone {
  DoorModel door;
  double depth{1.0};          ///< [m]
  double person_radius{0.3};  ///< People occupy the zone when within this of it [m].
  /// True when a person at p_MP (a disc of person_radius) overlaps the zone.
  bool Contains(const Eigen::Vector2d& p_MP) const;
};

struct IntentConfig {
  double stationary_speed{0.15};  ///< Below this a person is not walking [m/s].
  double holding_distance{0.7};   ///< From the leaf (hinge to free edge), for holding it [m].
  double holding_min_open{0.25};  ///< The door must be open at least this fraction.
  double parallel_ratio{0.5};     ///< |v·normal| < ratio·|v|: walking past.
  double crossing_horizon{2.0};   ///< Reaching the door line within this: crossing [s].
};

/// Classifies one person's intent with respect to a door (and its state, if observed).
PersonIntent ClassifyIntent(const TrackedPerson& person, const DoorZone& zone,
                            const DoorState& door, const IntentConfig& config = {});

/// Whether anyone occupies the zone now (index 0) and at each forecast step (1..steps).
std::vector<bool> ForecastZoneOccupancy(const std::vector<TrackedPerson>& people,
                                        const DoorZone& zone);

}  // namespace egress::perception
