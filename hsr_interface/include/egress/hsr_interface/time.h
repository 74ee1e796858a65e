#pragma once
/// @file
/// Time stamps. Every stamp in egress is a `Time`: integer nanoseconds since the epoch of the
/// clock that produced it (the start of a twin run for the simulated clock, the construction of
/// the steady clock otherwise). Integers keep twin runs bit-exact across machines.

#include <chrono>
#include <cstdint>

namespace egress {

using Duration = std::chrono::nanoseconds;
/// Nanoseconds since the producing clock's epoch.
using Time = std::chrono::nanoseconds;

/// Seconds as a double, for arithmetic with SI quantities.
constexpr double ToSeconds(Duration d) {
  return std::chrono::duration<double>(d).count();
}

/// Rounds seconds to the nearest nanosecond.
/// @throws InvalidArgument if `seconds` is not finite or overflows 64-bit nanoseconds.
Duration SecondsToDuration(double seconds);

}  // namespace egress
