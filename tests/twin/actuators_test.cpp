#include "egress/twin/actuators.h"

#include <limits>

#include <gtest/gtest.h>

namespace egress::twin {
namespace {

// A 0.1 x 0.02 x 0.1 m button on a wall along x whose face looks towards −y, at y = 2.93.
ActuatorBox WallButton() {
  return {Pose3(Eigen::Vector3d(1.0, 2.94, 1.0)), {0.1, 0.02, 0.1}};
}

// Moves the fingertip from 5 cm in front of the face to `depth` behind it in `steps` steps.
PushButton::Result Poke(PushButton* b, double x, double z, double depth, int steps) {
  PushButton::Result result = PushButton::Result::kNone;
  const double y0 = 2.93 - 0.05, y1 = 2.93 + depth;
  for (int i = 0; i <= steps; ++i) {
    const auto r = b->Update({x, y0 + (y1 - y0) * i / steps, z});
    if (r != PushButton::Result::kNone) result = r;
  }
  return result;
}

TEST(PushButtonTest, PressCountsAfterTheStrokeWithSmallForce) {
  PushButton b(WallButton(), 0.004, 5.0, 22.0);
  EXPECT_EQ(Poke(&b, 1.0, 1.0, 0.005, 200), PushButton::Result::kPressed);
  EXPECT_LT(b.force(), 22.0);
  // Held in: no second press until released.
  EXPECT_EQ(b.Update({1.0, 2.935, 1.0}), PushButton::Result::kNone);
  b.Update({1.0, 2.85, 1.0});
  EXPECT_EQ(Poke(&b, 1.02, 0.98, 0.005, 200), PushButton::Result::kPressed);
}

TEST(PushButtonTest, NearMissesDoNotPress) {
  PushButton b(WallButton(), 0.004, 5.0, 22.0);
  EXPECT_EQ(Poke(&b, 1.0, 1.0, 0.002, 200), PushButton::Result::kNone);   // too shallow
  EXPECT_EQ(Poke(&b, 1.07, 1.0, 0.005, 200), PushButton::Result::kNone);  // beside the cap
  EXPECT_EQ(Poke(&b, 1.0, 1.06, 0.005, 200), PushButton::Result::kNone);  // above it
}

// A finger that pushes on past the cap's centre (toward the wall behind it) keeps the cap
// pressed: one press, not a release and a second press as it goes deeper and comes back.
TEST(PushButtonTest, PushingPastTheCentreKeepsOnePress) {
  PushButton b(WallButton(), 0.004, 5.0, 1000.0);
  int presses = 0;
  for (int i = 0; i <= 300; ++i) {  // in to the wall plane behind the button (2 cm), and out
    const double y = i <= 150 ? 2.88 + 0.07 * i / 150 : 2.95 - 0.07 * (i - 150) / 150;
    presses += b.Update({1.0, y, 1.0}) == PushButton::Result::kPressed;
    if (i == 150) {
      EXPECT_NEAR(b.travel(), 0.02, 1e-9);  // the whole cap's depth
    }
  }
  EXPECT_EQ(presses, 1);
  EXPECT_EQ(b.travel(), 0.0);  // released once out
}

TEST(PushButtonTest, AJabPastTheBottomIsRefusedAsOverForce) {
  PushButton b(WallButton(), 0.004, 5.0, 22.0);
  // 5 cm approach + 8 mm in two steps: the first sample inside is already past the bottom.
  EXPECT_EQ(Poke(&b, 1.0, 1.0, 0.008, 2), PushButton::Result::kOverForce);
  EXPECT_GT(b.force(), 22.0);
}

// The finger was behind the button's plane, away from it (the robot in a room behind that
// wall), and comes round to press it from the front: a press, counted from the front face.
TEST(PushButtonTest, AFingerFromBehindThePlaneElsewherePressesFromTheFront) {
  PushButton b(WallButton(), 0.004, 5.0, 22.0);
  EXPECT_EQ(b.Update({4.0, 3.5, 1.0}), PushButton::Result::kNone);  // behind, 3 m along
  EXPECT_EQ(b.Update({1.0, 3.5, 0.4}), PushButton::Result::kNone);  // behind, below it
  EXPECT_EQ(b.Update({1.5, 2.5, 1.0}), PushButton::Result::kNone);  // in front, beside it
  // In from beside the cap, 5 cm out from the face, then the stroke.
  for (int i = 0; i <= 20; ++i)
    EXPECT_EQ(b.Update({1.5 - 0.5 * i / 20, 2.88, 1.0}), PushButton::Result::kNone);
  EXPECT_EQ(Poke(&b, 1.0, 1.0, 0.005, 200), PushButton::Result::kPressed);
  EXPECT_LT(b.force(), 22.0);
  // A finger still behind the wall that comes over the cap's back is on the back: no press from
  // the front face's count.
  PushButton back(WallButton(), 0.004, 5.0, 22.0);
  EXPECT_EQ(back.Update({1.5, 3.5, 1.0}), PushButton::Result::kNone);
  EXPECT_EQ(back.Update({1.0, 3.5, 1.0}), PushButton::Result::kNone);
  EXPECT_EQ(back.travel(), 0.0);
}

TEST(ProximityPlateTest, TriggersWithinRangeOnceUntilTheHandLeaves) {
  ProximityPlate plate(WallButton(), 0.3);
  EXPECT_FALSE(plate.Update({{1.0, 2.93 - 0.35, 1.0}}));
  EXPECT_TRUE(plate.Update({{1.0, 2.93 - 0.25, 1.0}}));
  EXPECT_FALSE(plate.Update({{1.0, 2.93 - 0.1, 1.0}}));  // still there: one trigger
  EXPECT_FALSE(plate.Update({{1.0, 2.93 - 0.5, 1.0}}));  // leaves beyond 1.5 x range: re-armed
  EXPECT_TRUE(plate.Update({{1.0, 2.93 - 0.2, 1.0}}));
  EXPECT_NEAR(plate.DistanceTo({1.0, 2.83, 1.0}), 0.1, 1e-9);
}

TEST(ProximityPlateTest, AMountedPlateDoesNotSenseAHandBehindItsWall) {
  // The wall behind the plate: y from 2.95 to 3.05; the plate's face looks towards -y.
  ProximityPlate plate(WallButton(), 0.3, Eigen::Vector3d(0.0, -1.0, 0.0));
  const Eigen::Vector3d behind_wall(1.0, 3.15, 1.0);  // 0.14 m from the box, beyond the wall
  EXPECT_EQ(plate.DistanceTo(behind_wall), std::numeric_limits<double>::infinity());
  EXPECT_FALSE(plate.Update({behind_wall}));
  // Beside it on the wall's face and in front of it, it senses as before.
  EXPECT_NEAR(plate.DistanceTo({1.2, 2.94, 1.0}), 0.15, 1e-9);
  EXPECT_TRUE(plate.Update({{1.0, 2.93 - 0.25, 1.0}}));
  // An unmounted plate (no facing) senses all round, the hand behind included.
  ProximityPlate free_standing(WallButton(), 0.3);
  EXPECT_TRUE(free_standing.Update({behind_wall}));
  EXPECT_THROW(ProximityPlate(WallButton(), 0.3, Eigen::Vector3d(0.0, -2.0, 0.0)), std::exception);
}

}  // namespace
}  // namespace egress::twin
