#include "egress/hsr_interface/clock.h"

#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"

namespace egress {

Duration SecondsToDuration(double seconds) {
  ThrowUnless(std::isfinite(seconds), "Invalid duration: seconds (", seconds, ") must be finite.");
  const double ns = std::round(seconds * 1e9);
  ThrowUnless(std::abs(ns) < 9.2e18, "Invalid duration: seconds (", seconds,
              ") overflows 64-bit nanoseconds.");
  return Duration{static_cast<std::int64_t>(ns)};
}

void SimClock::AdvanceBy(Duration dt) {
  ThrowUnless(dt.count() >= 0, "Invalid SimClock::AdvanceBy: dt (", dt.count(),
              " ns) must be >= 0; simulated time never runs back.");
  now_ns_.fetch_add(dt.count(), std::memory_order_acq_rel);
}

void SimClock::AdvanceTo(Time t) {
  const std::int64_t now = now_ns_.load(std::memory_order_acquire);
  ThrowUnless(t.count() >= now, "Invalid SimClock::AdvanceTo: t (", t.count(),
              " ns) is earlier than now (", now, " ns); simulated time never runs back.");
  now_ns_.store(t.count(), std::memory_order_release);
}

Time SteadyClock::Now() const {
  return std::chrono::duration_cast<Time>(std::chrono::steady_clock::now() - origin_);
}

}  // namespace egress
