#pragma once
/// @file
/// Clocks. Code below apps/ never reads the wall clock directly: it is handed a Clock. A twin
/// run uses SimClock (time advances only when the simulation steps, so a run is a pure
/// function of its scenario and seed); the real robot and services use SteadyClock.

#include <atomic>
#include <chrono>

#include "egress/hsr_interface/time.h"

namespace egress {

/// Source of the current time. Implementations are thread-safe for Now().
class Clock {
 public:
  virtual ~Clock() = default;
  /// The current time since this clock's epoch. Never decreases.
  virtual Time Now() const = 0;
};

/// Simulated time, advanced explicitly by the simulation loop. Starts at `start`.
class SimClock final : public Clock {
 public:
  explicit SimClock(Time start = Time{0}) : now_ns_(start.count()) {}
  Time Now() const override { return Time{now_ns_.load(std::memory_order_acquire)}; }
  /// Advances by `dt`. @throws InvalidArgument if dt is negative.
  void AdvanceBy(Duration dt);
  /// Jumps to `t`. @throws InvalidArgument if t is earlier than Now() (time never runs back).
  void AdvanceTo(Time t);

 private:
  std::atomic<std::int64_t> now_ns_;
};

/// Monotonic time from std::chrono::steady_clock, with its epoch at construction.
class SteadyClock final : public Clock {
 public:
  SteadyClock() : origin_(std::chrono::steady_clock::now()) {}
  Time Now() const override;

 private:
  std::chrono::steady_clock::time_point origin_;
};

}  // namespace egress
