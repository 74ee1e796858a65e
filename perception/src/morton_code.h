#pragma once
/// @file
/// Morton codes of OctoMap keys (internal to OccupancyMap3D): a key's bits interleaved from the
/// top, x lowest in each group of three, so that codes sort in the order of a depth-first walk
/// of the tree visiting children 0..7, each group of three a child index. By bit spreading
/// (a handful of shifts and masks) rather than a loop over the 16 bits.

#include <cstddef>
#include <cstdint>
#include <vector>  // OcTreeKey.h uses it without including it

#include <octomap/OcTreeKey.h>

namespace egress::perception::detail {

constexpr int kKeyBits = 16;  // OctoMap's tree depth
constexpr std::uint64_t kMortonMask = (std::uint64_t{1} << (3 * kKeyBits)) - 1;

// The 16 bits of x spread to every third bit (bit b to bit 3b).
constexpr std::uint64_t SpreadBy3(std::uint64_t x) {
  x &= 0xffff;
  x = (x | x << 16) & 0x0000ff0000ffULL;
  x = (x | x << 8) & 0x00f00f00f00f00fULL;
  x = (x | x << 4) & 0x0c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x249249249249249ULL;
  return x;
}

// The inverse: every third bit (from bit 0) gathered into 16 bits.
constexpr std::uint64_t GatherBy3(std::uint64_t x) {
  x &= 0x249249249249249ULL;
  x = (x | x >> 2) & 0x0c30c30c30c30c3ULL;
  x = (x | x >> 4) & 0x00f00f00f00f00fULL;
  x = (x | x >> 8) & 0x0000ff0000ffULL;
  x = (x | x >> 16) & 0xffff;
  return x;
}

inline std::uint64_t MortonCode(const octomap::OcTreeKey& key) {
  return SpreadBy3(key[0]) | SpreadBy3(key[1]) << 1 | SpreadBy3(key[2]) << 2;
}

/// The key of a code (bits above the 48 of a key ignored).
inline octomap::OcTreeKey KeyOfMortonCode(std::uint64_t code) {
  code &= kMortonMask;
  return octomap::OcTreeKey(octomap::key_type(GatherBy3(code)),
                            octomap::key_type(GatherBy3(code >> 1)),
                            octomap::key_type(GatherBy3(code >> 2)));
}

}  // namespace egress::perception::detail
