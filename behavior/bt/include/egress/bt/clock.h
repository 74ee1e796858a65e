#pragma once
/// @file
/// The time source of a tree's timers (Delay, Timeout, Sleep) and of its status-change stamps.
/// Injected, so that a simulation drives a tree deterministically in simulated time.

#include <atomic>
#include <chrono>
#include <cstdint>

namespace egress::bt {

using Duration = std::chrono::nanoseconds;

class Clock {
 public:
  virtual ~Clock() = default;
  /// Monotonic time since the clock's epoch.
  virtual Duration Now() const = 0;
};

/// std::chrono::steady_clock, epoch at construction. The default of a Tree.
class SteadyClock final : public Clock {
 public:
  SteadyClock() : origin_(std::chrono::steady_clock::now()) {}
  Duration Now() const override { return std::chrono::steady_clock::now() - origin_; }

 private:
  std::chrono::steady_clock::time_point origin_;
};

/// A clock advanced by hand (tests, lock-step simulation).
class ManualClock final : public Clock {
 public:
  Duration Now() const override { return Duration{now_.load()}; }
  void Advance(Duration dt) { now_ += dt.count(); }
  void Set(Duration t) { now_ = t.count(); }

 private:
  std::atomic<std::int64_t> now_{0};
};

}  // namespace egress::bt
