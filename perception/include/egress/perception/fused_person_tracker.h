#pragma once
/// @file
/// FusedPersonTracker: one set of people from two sensors — the head camera's placed person
/// detections (58°, 8 Hz, 125-200 ms late) and the base laser's (LaserPersonDetector: 270°,
/// 10 Hz). Each sensor's frame is an Update() with its own stamp; a frame stamped before the
/// tracks' time (the camera's latency) is compared with where each track was then and moved
/// forward by its velocity before it is fused. Association is greedy nearest-first within a gate;
/// position and velocity are smoothed exponentially (the paper's alpha); velocity is taken from
/// successive measurements of a track, whichever sensor made them, never from two frames a few
/// milliseconds apart. A laser measurement whose returns did not move (PersonObservation::motion
/// kStill, judged along the beams by FreeSpaceMotion) measures zero velocity: the step from the
/// last one is the moving viewpoint's (a leg pair's visible arcs, legs in each other's shadow),
/// which read people standing as walking at up to 3 m/s while the robot drove.
///
/// A track is *confirmed* (a person, not a table leg) once the camera has seen it, or the laser
/// has seen it `confirm_laser_hits` times and it has moved `confirm_motion` within
/// `confirm_window_s` (from where it was first seen, or where it was a window later, and so on),
/// stepping on between each of its last three laser measurements (at confirm_motion /
/// confirm_window_s or faster) and not back where it was before it went elsewhere (ComesBack): a
/// track taking two table legs by turns jumps and stops, or jumps back, where a walker keeps
/// going;
/// a person walks that far in well under the window; the returns of a jamb or a box's edge creep
/// as the robot's viewpoint changes, a few centimetres a second (the clinic's door_c jamb read
/// as a person 0.3 m from its birth after 30 s, and held the robot off its door). A track is
/// dropped when a sensor that covers its position has not measured it for `drop_after_s`, or when
/// nothing has for `drop_unseen_s`.
///
/// Static spots: a place where the laser has kept finding a "person" within `static_radius` for
/// `static_after_s` (with no gap over `static_gap_s`) is a thing, not a person — a table's leg, a
/// bin. A person's legs do not stay put that long while they walk (a stance lasts ~0.6 s), and
/// one standing still never confirmed on the laser alone anyway. Laser observations at a static
/// spot neither start a track nor join an unconfirmed one (a confirmed person standing by a table
/// keeps them). Without this, a track born on one of O2's table legs took the next leg, 0.52 m
/// off, when the first was occluded, and that jump confirmed a person walking into the doorway.
/// A static spot unseen for `static_forget_s` is forgotten, any other once unseen for
/// `static_gap_s` (a walker leaves one every few centimetres). Before a spot is static, an
/// unconfirmed track's laser observation that jumped faster than `max_person_speed` from its last
/// one took something else: its confirm window starts again there.
///
/// The brain reads it with PerceptionConfig::laser_people (on by default); with
/// `--camera-people-only`, the camera's PersonTracker alone.

#include <array>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/time.h"
#include "egress/perception/free_space_motion.h"
#include "egress/perception/person_tracker.h"

namespace egress::perception {

enum class PersonSource { kCamera, kLaser };

struct PersonObservation {
  Eigen::Vector2d p_MP{Eigen::Vector2d::Zero()};  ///< In M [m].
  PersonSource source{PersonSource::kLaser};
  /// Cut by the sensor's field of view (LaserPersonDetection::at_edge): the person may be up to
  /// a body's radius off it. It starts tracks and keeps them alive, but moves a confirmed track
  /// only within FusedPersonTrackerConfig::edge_gate of its prediction.
  bool at_edge{false};
  /// Whether its returns moved, judged along the laser's beams (FreeSpaceMotion): kStill
  /// measures no velocity (the step from its last measurement is the viewpoint's, not theirs).
  PlaceMotion motion{PlaceMotion::kUnknown};
};

struct FusedPersonTrackerConfig {
  double alpha{0.3};             ///< Exponential smoothing of position and velocity.
  double gate_distance{0.8};     ///< Farthest an observation may be from a track's prediction [m].
  double drop_after_s{1.0};      ///< Unmeasured this long where a sensor covers it: dropped [s].
  double drop_unseen_s{3.0};     ///< Unmeasured this long anywhere: dropped [s].
  int confirm_laser_hits{3};     ///< Laser measurements before a laser-only track can confirm.
  double confirm_motion{0.3};    ///< ... and how far it must have moved from its birth [m] ...
  double confirm_window_s{2.0};  ///< ... within this [s].
  double max_latency_s{0.5};     ///< Oldest a frame may be against the tracks' time [s].
  double min_velocity_dt{0.05};  ///< Measurements closer in time than this update no velocity [s].
  /// A track no sensor has measured for this long has coasted on its velocity: its next
  /// measurement places it outright, and its velocity is measured afresh from there (differenced
  /// from that measurement, not smoothed into the old velocity) for `reacquire_velocity_s`. The
  /// one it followed may have gone out of view and the track taken up someone else: two wards
  /// seed 25's track coasted 0.6 s after a walker into the laser's blind sector, took the walker
  /// behind her 0.6 m short of its prediction, differenced that as -0.6 m/s, and read her at
  /// 0.5 m/s 0.1 s later while she walked at 1.4 [s].
  double reacquire_after_s{0.4};
  double reacquire_velocity_s{0.3};  ///< See reacquire_after_s [s].
  /// A camera observation within this long of the track's last laser measurement (before or
  /// after it: the camera's frames come later) measures no velocity: the laser places people to
  /// centimetres and judges their motion along its beams, the camera's depth places them to
  /// decimetres (school seed 19: a resident standing in a group, placed by the camera 0.8 m
  /// apart in consecutive frames, read as walking at 0.8 m/s at the robot, laser measurements
  /// judging them still in between) [s].
  double camera_velocity_after_laser_s{0.5};
  int forecast_steps{4};
  double forecast_dt{0.2};  ///< [s]
  /// An unconfirmed track whose laser observation jumped faster than this since the last one
  /// took something else (a neighbouring table leg): it starts its confirm window there [m/s].
  double max_person_speed{4.0};
  /// An at_edge observation farther than this from a confirmed track's prediction moves it not
  /// at all (it only keeps it alive): a wide body's sliver at the laser's edge lies 0.3 m off
  /// its centre, and pulled a standing person's track there as if they walked [m].
  double edge_gate{0.2};
  double static_radius{0.08};    ///< Laser observations this near are the same spot [m].
  double static_after_s{0.8};    ///< Seen at one spot this long: a thing, not a person [s].
  double static_gap_s{1.0};      ///< A spot unseen longer than this starts its count again [s].
  double static_forget_s{30.0};  ///< A spot unseen this long is forgotten [s].
  /// @throws InvalidArgument naming the field that is out of range.
  void Validate() const;
};

/// A place where the laser keeps finding a "person" (FusedPersonTracker's static spots).
struct StaticSpot {
  Eigen::Vector2d p_M{Eigen::Vector2d::Zero()};  ///< [m]
  Time first_seen{};                             ///< Since when, without a gap over static_gap_s.
  Time last_seen{};
  bool is_static{false};  ///< Seen static_after_s on end, once; until forgotten.
};

struct FusedTrack {
  TrackedPerson person;  ///< id, smoothed p_MP / v_MP at the tracker's time, forecast, hits.
  int camera_hits{0};
  int laser_hits{0};
  bool confirmed{false};
  Eigen::Vector2d p_MBirth{Eigen::Vector2d::Zero()};  ///< Where its confirm window began.
  Time birth{};                                       ///< When its confirm window began.
  Time last_measured{};  ///< The latest stamp of a measurement of it, either sensor.
  /// Per sensor (index PersonSource): its last measurement, for velocity from the same sensor
  /// (the camera's placement and the laser's leg midpoint disagree by a few centimetres).
  std::array<std::optional<std::pair<Time, Eigen::Vector2d>>, 2> last_by_source;
  /// Since it was reacquired (FusedPersonTrackerConfig::reacquire_after_s), for
  /// reacquire_velocity_s: that measurement (stamp, position, sensor), its velocity's origin.
  struct VelocityAnchor {
    Time stamp{};
    Eigen::Vector2d p_MP{Eigen::Vector2d::Zero()};
    PersonSource source{PersonSource::kLaser};
  };
  std::optional<VelocityAnchor> reacquired;
  /// Until confirmed: its laser measurements (stamp, position) since its confirm window began.
  std::vector<std::pair<Time, Eigen::Vector2d>> laser_path;
};

class FusedPersonTracker {
 public:
  explicit FusedPersonTracker(FusedPersonTrackerConfig config = {});

  /// One sensor frame taken at `stamp`. `covers(p_M)` says whether that sensor could have seen
  /// a person at p_M (its field of view and range); a track it covers and did not measure ages
  /// towards drop_after_s. Null: the sensor covers everything.
  /// @throws InvalidArgument for a non-finite observation or a frame older than max_latency_s.
  void Update(const std::vector<PersonObservation>& observations, Time stamp,
              const std::function<bool(const Eigen::Vector2d&)>& covers = {});

  const std::vector<FusedTrack>& tracks() const { return tracks_; }
  /// The places the laser keeps finding something (static ones are things, not people).
  const std::vector<StaticSpot>& spots() const { return spots_; }
  /// The confirmed tracks, as the rest of perception reads people.
  std::vector<TrackedPerson> ConfirmedPeople() const;
  /// The tracks' time: the latest stamp seen.
  Time now() const { return now_; }

 private:
  void Predict(Time stamp);
  void Forecast();
  /// Records the frame's laser observations in spots_; which of them lie at a static spot.
  std::vector<bool> UpdateSpots(const std::vector<PersonObservation>& observations, Time stamp);

  FusedPersonTrackerConfig config_;
  std::vector<FusedTrack> tracks_;
  std::vector<StaticSpot> spots_;
  int next_id_{1};
  Time now_{};
  bool started_{false};
};

}  // namespace egress::perception
