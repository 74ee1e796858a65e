#include "egress/twin/world_description.h"

#include <gtest/gtest.h>

namespace egress::twin {
namespace {

// The lab door: hinge at (0.475, 3), leaf 0.95 x 0.04 x 2 m centred at (0, 3, 1), opens to +y.
DoorDescription LabDoor() {
  DoorDescription d;
  d.name = "lab_door";
  d.p_WH = {0.475, 3.0, 1.0};
  d.X_WL = Pose3(Eigen::Vector3d(0.0, 3.0, 1.0));
  d.leaf_size = {0.95, 0.04, 2.0};
  d.open_sign = -1.0;
  d.max_open_angle = 1.57;
  return d;
}

TEST(DoorDescriptionTest, LeafReachPoseAndFreeEdgeFollowTheOpeningAngle) {
  const DoorDescription d = LabDoor();
  EXPECT_NEAR(d.LeafReach(), 0.95, 1e-12);
  EXPECT_TRUE(d.CalcFreeEdge(0.0).isApprox(Eigen::Vector3d(-0.475, 3.0, 1.0), 1e-12));
  // Open 90°: the free edge points away from the robot (+y), 0.95 m from the hinge.
  EXPECT_TRUE(d.CalcFreeEdge(M_PI / 2).isApprox(Eigen::Vector3d(0.475, 3.95, 1.0), 1e-9));
  const Pose3 X_WL = d.CalcLeafPose(M_PI / 2);
  EXPECT_TRUE(X_WL.translation().isApprox(Eigen::Vector3d(0.475, 3.475, 1.0), 1e-9));
  EXPECT_NEAR(std::abs(X_WL.rotation()(1, 0)), 1.0, 1e-9);  // the leaf's long axis now along y
}

TEST(FloorFootprintTest, UprightShapesKeepTheirOutlineOthersUseBounds) {
  ShapeDescription wall;
  wall.model = "wall";
  wall.kind = ShapeKind::kBox;
  wall.box_size = {4.0, 0.1, 2.0};
  wall.X_WS = Pose3::FromPose2({1.0, 2.0, M_PI / 2}) * Pose3(Eigen::Vector3d(0, 0, 1.0));
  const auto f = CalcFloorFootprint(wall);
  ASSERT_TRUE(f.has_value());
  EXPECT_NEAR(f->X_WF.yaw, M_PI / 2, 1e-9);
  EXPECT_TRUE(f->size.isApprox(Eigen::Vector2d(4.0, 0.1)));
  ShapeDescription pole = wall;
  pole.kind = ShapeKind::kCylinder;
  pole.radius = 0.1;
  pole.length = 1.0;
  EXPECT_TRUE(CalcFloorFootprint(pole)->size.isApprox(Eigen::Vector2d(0.2, 0.2)));
  // A lamp hanging at 2.5–3 m is above the robot's and people's height band.
  ShapeDescription lamp = wall;
  lamp.X_WS = Pose3(Eigen::Vector3d(0, 0, 2.75));
  lamp.box_size = {0.3, 0.3, 0.5};
  EXPECT_FALSE(CalcFloorFootprint(lamp).has_value());
  ShapeDescription floor;
  floor.kind = ShapeKind::kPlane;
  EXPECT_FALSE(CalcFloorFootprint(floor).has_value());
  // A tilted box uses its world bounds.
  ShapeDescription ramp = wall;
  ramp.X_WS = Pose3::FromXyzRpy({0, 0, 0.5}, {0.3, 0, 0});
  const auto r = CalcFloorFootprint(ramp);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->X_WF.yaw, 0.0);
  EXPECT_GT(r->size.y(), 0.1);
  WorldDescription w;
  w.shapes = {wall, lamp, floor};
  EXPECT_EQ(CalcFloorFootprints(w).size(), 1u);
  EXPECT_EQ(w.ShapesOfModel("wall").size(), 2u);
  EXPECT_EQ(w.FindDoor("wall"), nullptr);
}

}  // namespace
}  // namespace egress::twin
