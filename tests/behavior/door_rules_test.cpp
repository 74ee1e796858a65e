// Door rules (egress/behavior/door_rules.h) that need no task services: which laser returns may be
// a swinging leaf's.

#include <vector>

#include <gtest/gtest.h>

#include "egress/behavior/door_rules.h"

namespace egress::behavior {
namespace {

// A 1 m leaf hinged at the origin, closed along +x, opening counter-clockwise (into +y).
perception::TrackedDoor Door(bool observed, double steady_for) {
  perception::TrackedDoor door;
  door.model.id = "door";
  door.model.p_MHinge = {0.0, 0.0};
  door.model.p_MLatch = {1.0, 0.0};
  door.model.swing_sign = 1.0;
  door.state.observed = observed;
  door.state.steady_for = steady_for;
  return door;
}

// Returns in the sweep of a leaf that may be swinging (never seen, or not steady for
// kLeafSettledSec) go; those of a settled leaf, and everything outside the sweep, stay.
TEST(DoorRulesTest, ReturnsOnASwingingLeafAreDropped) {
  const Eigen::Vector2d in_sweep(0.6, 0.6), behind(0.5, -0.5), far(3.0, 3.0);
  for (const auto& [door, dropped] : std::vector<std::pair<perception::TrackedDoor, bool>>{
           {Door(false, 10.0), true},
           {Door(true, 0.5 * kLeafSettledSec), true},
           {Door(true, 2.0 * kLeafSettledSec), false}}) {
    EXPECT_EQ(MayBeSwinging(door), dropped);
    std::vector<Eigen::Vector2d> returns = {in_sweep, behind, far};
    DropReturnsOnSwingingLeaves({door}, 0.1, &returns);
    ASSERT_EQ(returns.size(), dropped ? 2u : 3u);
    EXPECT_EQ(returns.back(), far);
    EXPECT_EQ(returns[dropped ? 0 : 1], behind);
  }
}

}  // namespace
}  // namespace egress::behavior
