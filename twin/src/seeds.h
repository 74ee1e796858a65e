#pragma once
// Independent random streams from one seed (SplitMix64): each component of a twin run draws
// from its own stream, so adding a sensor or a person never shifts what the others draw.

#include <cstdint>

namespace egress::twin {

inline std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace egress::twin
