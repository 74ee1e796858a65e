// Morton codes of OctoMap keys (perception/src/morton_code.h), against their definition bit by bit.
#include "morton_code.h"

#include <random>

#include <gtest/gtest.h>

namespace egress::perception::detail {
namespace {

// The definition: bit b of x, y and z at bits 3b, 3b + 1 and 3b + 2.
std::uint64_t MortonByBits(const octomap::OcTreeKey& key) {
  std::uint64_t code = 0;
  for (int b = 0; b < kKeyBits; ++b)
    for (int axis = 0; axis < 3; ++axis)
      code |= std::uint64_t((key[unsigned(axis)] >> b) & 1u) << (3 * b + axis);
  return code;
}

TEST(MortonCodeTest, CodesAreTheKeysBitsInterleavedAndDecodeToTheKey) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<unsigned> any(0, 0xffff);
  std::vector<octomap::OcTreeKey> keys{{0, 0, 0},
                                       {0xffff, 0xffff, 0xffff},
                                       {1, 0, 0},
                                       {0, 1, 0},
                                       {0, 0, 1},
                                       {0x8000, 0x7fff, 0x1234},
                                       {32768, 32768, 32768}};
  for (int k = 0; k < 20000; ++k)
    keys.emplace_back(octomap::key_type(any(rng)), octomap::key_type(any(rng)),
                      octomap::key_type(any(rng)));
  for (const auto& key : keys) {
    const std::uint64_t code = MortonCode(key);
    ASSERT_EQ(code, MortonByBits(key)) << key[0] << " " << key[1] << " " << key[2];
    EXPECT_EQ(KeyOfMortonCode(code), key);
    // Bits above a key's 48 are ignored.
    EXPECT_EQ(KeyOfMortonCode(code | ~kMortonMask), key);
  }
  // Codes sort as a depth-first walk: the top bits (the root's child) first.
  EXPECT_LT(MortonCode({0x7fff, 0x7fff, 0x7fff}), MortonCode({0x8000, 0, 0}));
  EXPECT_LT(MortonCode({0xffff, 0x7fff, 0}), MortonCode({0, 0x8000, 0}));
}

}  // namespace
}  // namespace egress::perception::detail
