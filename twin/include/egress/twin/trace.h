#pragma once
/// @file
/// Run trace: robot pose, people, door angles and phases, the held payload and the events since
/// the previous sample, at a fixed rate (default 20 Hz) of simulated time. Written as JSON lines
/// (one header line with the floor plan, then one object per sample) with fixed precision, so
/// two runs of the same scenario and seed produce byte-identical files; Hash() fingerprints them.
///
/// Header: {"scenario", "seed", "rate_hz", "robot_radius", "walls": [[x, y, yaw, size_x, size_y]],
///   "doors": [{"name", "hinge": [x, y], "latch": [x, y], "swing": ±1 (+1 opens counter-clockwise),
///   "glass"}], "people": [names], "payloads": [names]}.
/// Sample: {"t", "robot": [x, y, yaw], "doors": [[angle, phase]], "people": [[x, y, phase]],
///   "payloads": [[x, y, z]], "held": name or null, "events": [{"t", "kind", "subject",
///   "detail"}], optional "label" and "path": [[x, y]] from the driver}. Frame W, SI units.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "egress/twin/twin_world.h"

namespace egress::twin {

/// What whoever drives the robot wants shown with a sample (the brain: its running action and
/// its planned path). Not ground truth, and the twin does not read it.
struct TraceAnnotation {
  std::string label;                  ///< e.g. the behavior tree's running action
  std::vector<Eigen::Vector2d> path;  ///< planned base path in W [m]
  /// The driver's costmap (a snapshot now and then: it is large), as the row-major indices of
  /// its inflated and lethal cells, and of the free cells deep in someone's personal space
  /// (the proxemic layer at half its peak or more); cell (0, 0) has its corner at `origin` in W.
  struct Grid {
    Eigen::Vector2d origin{Eigen::Vector2d::Zero()};  ///< [m]
    double resolution{0.05};                          ///< [m]
    int width{0};
    int height{0};
    std::vector<std::uint32_t> inflated;
    std::vector<std::uint32_t> lethal;
    std::vector<std::uint32_t> personal;
  };
  std::optional<Grid> costmap;
};

class TraceRecorder {
 public:
  explicit TraceRecorder(double rate_hz = 20.0);
  /// Call after every world step; records a sample when one is due, with `annotation` (if any)
  /// as "label" and "path".
  void Observe(const TwinWorld& world, const TraceAnnotation* annotation = nullptr);
  /// Whether Observe at `world`'s time would record a sample.
  bool SampleDue(const TwinWorld& world) const { return world.time() + 1e-9 >= next_; }
  /// The whole trace as JSON lines.
  std::string ToJsonLines() const;
  /// Writes ToJsonLines() to `path`. @throws LoadError if it cannot be written.
  void Write(const std::filesystem::path& path) const;
  /// 64-bit FNV-1a of ToJsonLines().
  std::uint64_t Hash() const;
  std::size_t sample_count() const { return samples_.size(); }

 private:
  double period_;
  double next_{0.0};
  std::string header_;
  std::vector<std::string> samples_;
  std::size_t events_seen_{0};
};

/// Escapes a string for a JSON string literal (without the quotes).
std::string JsonEscape(const std::string& text);

}  // namespace egress::twin
