#include "egress/twin/sdf_world_loader.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/perception/occupancy_grid.h"
#include "test_paths.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

using ::testing::HasSubstr;
using testing::ReferenceDir;
using testing::WorldsDir;

#define REQUIRE_REFERENCE_WORLDS()                                                             \
  if (ReferenceDir().empty() || !std::filesystem::exists(ReferenceDir() / "worlds")) {         \
    GTEST_SKIP() << "the paper's worlds are not here: set EGRESS_REFERENCE_DIR to the folder " \
                    "holding worlds/door.world (../shared/reference)";                         \
  }

int CountNotes(const WorldDescription& w, const std::string& needle) {
  int n = 0;
  for (const auto& note : w.notes)
    n += note.find(needle) != std::string::npos ? 1 : 0;
  return n;
}

TEST(SdfWorldLoaderTest, PaperDoorWorldHasItsWallsDoorAndButton) {
  REQUIRE_REFERENCE_WORLDS();
  const WorldDescription w = LoadSdfWorld(ReferenceDir() / "worlds/door.world");
  // Ground plane, two hallway walls, the button (the door frame link has no collision).
  ASSERT_EQ(w.shapes.size(), 4u);
  const auto left = w.ShapesOfModel("hallway_wall_left");
  ASSERT_EQ(left.size(), 1u);
  EXPECT_NEAR(left[0]->X_WS.translation().x(), -2.6, 1e-9);
  EXPECT_NEAR(left[0]->box_size.x(), 3.1, 1e-9);
  ASSERT_EQ(w.doors.size(), 1u);
  const DoorDescription& door = w.doors[0];
  EXPECT_EQ(door.name, "handicap_door");
  EXPECT_EQ(door.joint, "door_hinge");
  // Hinge on the right of the opening at x = 0, leaf covering x −1..0, opening to +y (q < 0).
  EXPECT_TRUE(door.p_WH.isApprox(Eigen::Vector3d(0.0, 4.5, 1.0), 1e-9));
  EXPECT_NEAR(door.X_WL.translation().x(), -0.5, 1e-9);
  EXPECT_NEAR(door.LeafReach(), 1.0, 1e-9);
  EXPECT_EQ(door.open_sign, -1.0);
  EXPECT_NEAR(door.max_open_angle, 1.57, 1e-9);
  EXPECT_NEAR(door.max_velocity, 0.6, 1e-9);
  EXPECT_NEAR(door.damping, 5.0, 1e-9);
  EXPECT_GT(door.CalcFreeEdge(M_PI / 2).y(), 5.4);  // swings away from the robot (+y)
  const auto button = w.ShapesOfModel("ada_button");
  ASSERT_EQ(button.size(), 1u);
  EXPECT_TRUE(button[0]->box_size.isApprox(Eigen::Vector3d(0.15, 0.02, 0.15)));
  EXPECT_NEAR(button[0]->X_WS.translation().y(), 4.44, 1e-9);
  // Five world plugins, two on the door, one on the button: one note each; and the sensor.
  EXPECT_EQ(CountNotes(w, "ignoring plugin"), 8);
  EXPECT_EQ(CountNotes(w, "TouchPlugin"), 1);
  EXPECT_EQ(CountNotes(w, "ignoring sensor 'button_contact_sensor'"), 1);
}

TEST(SdfWorldLoaderTest, PaperDoubleDoorWorldHasTwoDoorsOpeningAway) {
  REQUIRE_REFERENCE_WORLDS();
  const WorldDescription w = LoadSdfWorld(ReferenceDir() / "worlds/double_door.world");
  ASSERT_EQ(w.doors.size(), 2u);
  const DoorDescription* left = w.FindDoor("handicap_door_left");
  const DoorDescription* right = w.FindDoor("handicap_door_right");
  ASSERT_NE(left, nullptr);
  ASSERT_NE(right, nullptr);
  EXPECT_EQ(left->open_sign, 1.0);
  EXPECT_EQ(right->open_sign, -1.0);
  EXPECT_NEAR(left->p_WH.x(), -1.0, 1e-9);
  EXPECT_NEAR(right->p_WH.x(), 1.0, 1e-9);
  for (const DoorDescription* d : {left, right}) {
    EXPECT_GT(d->CalcFreeEdge(1.2).y(), 4.5 + 0.5) << d->name;  // both open away (+y)
  }
  EXPECT_EQ(w.ShapesOfModel("ada_button").size(), 1u);
  EXPECT_NEAR(w.ShapesOfModel("ada_button")[0]->X_WS.translation().x(), -1.7, 1e-9);
}

TEST(SdfWorldLoaderTest, OurWorldsLoad) {
  const WorldDescription lab = LoadSdfWorld(WorldsDir() / "lab/lab.sdf");
  ASSERT_EQ(lab.doors.size(), 1u);
  EXPECT_EQ(lab.doors[0].open_sign, -1.0);
  EXPECT_NEAR(lab.doors[0].LeafReach(), 0.95, 1e-9);
  const WorldDescription office = LoadSdfWorld(WorldsDir() / "office/office.sdf");
  ASSERT_EQ(office.doors.size(), 2u);
  // Both office doors open into the room with larger x.
  for (const auto& d : office.doors)
    EXPECT_GT(d.CalcFreeEdge(1.2).x(), d.p_WH.x() + 0.5) << d.name;
  EXPECT_EQ(office.ShapesOfModel("table").size(), 1u);
}

TEST(SdfWorldLoaderTest, OfficeSdfRasterizesToTheOfficeMap) {
  // One office: the SDF the twin simulates and the map_server map the planners load agree.
  const WorldDescription office = LoadSdfWorld(WorldsDir() / "office/office.sdf");
  std::vector<perception::Box2> boxes;
  for (const auto& f : CalcFloorFootprints(office))
    boxes.push_back({f.X_WF, f.size});
  const auto from_sdf = perception::OccupancyGrid::FromBoxes(boxes, {0, 0}, {14, 6}, 0.05);
  const auto from_pgm =
      perception::OccupancyGrid::LoadMapServerYaml(WorldsDir() / "office/office.yaml");
  ASSERT_EQ(from_sdf.geometry().width, from_pgm.geometry().width);
  ASSERT_EQ(from_sdf.geometry().height, from_pgm.geometry().height);
  int differ = 0, occupied = 0;
  for (std::size_t i = 0; i < from_pgm.cells().size(); ++i) {
    differ += from_sdf.cells()[i] != from_pgm.cells()[i] ? 1 : 0;
    occupied += from_pgm.cells()[i] == perception::kLethalCost ? 1 : 0;
  }
  EXPECT_GT(occupied, 1000);
  EXPECT_EQ(differ,
            0);  // door leaves are doorways, not walls; the 2 cm buttons cover no cell centre
}

std::string DoorSdf(const std::string& leaf_geometry) {
  return R"(<?xml version="1.0"?>
<sdf version="1.6"><world name="w">
  <model name="d"><pose>0 0 1 0 0 0</pose>
    <link name="frame"/>
    <link name="leaf"><collision name="c"><pose>-0.5 0 0 0 0 0</pose><geometry>)" +
         leaf_geometry + R"(</geometry></collision></link>
    <joint name="hinge" type="revolute"><parent>frame</parent><child>leaf</child>
      <axis><xyz>0 0 1</xyz><limit><lower>0</lower><upper>1.5</upper></limit></axis></joint>
  </model>
</world></sdf>)";
}

TEST(SdfWorldLoaderTest, DoorFromStringAndNonBoxLeafIsRefused) {
  const WorldDescription w =
      LoadSdfWorldFromString(DoorSdf("<box><size>1 0.05 2</size></box>"), "door.sdf");
  ASSERT_EQ(w.doors.size(), 1u);
  EXPECT_EQ(w.doors[0].open_sign, 1.0);
  try {
    LoadSdfWorldFromString(DoorSdf("<sphere><radius>0.3</radius></sphere>"), "ball_door.sdf");
    FAIL() << "a spherical leaf was accepted";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("ball_door.sdf"));
    EXPECT_THAT(e.what(), HasSubstr("not a box"));
  }
}

TEST(SdfWorldLoaderTest, MalformedSdfNamesFileAndLine) {
  const auto path = egress::testing::TestTempPath("broken.world");
  {
    std::ofstream out(path);
    out << "<?xml version=\"1.0\"?>\n<sdf version=\"1.6\">\n<world name=\"w\">\n"
           "<model name=\"m\"><static>true</static>\n<link name=\"l\"><collision name=\"c\">"
           "<geometry><box><size>1 1</size></box></geometry></collision></link></model>\n"
           "</world></sdf>\n";
  }
  try {
    LoadSdfWorld(path);
    FAIL() << "a two-component box size was accepted";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path.string()));
  }
  std::filesystem::remove(path);
  EXPECT_THROW(LoadSdfWorldFromString("<sdf version='1.6'><world name='w'>", "cut.sdf"), LoadError);
  try {
    LoadSdfWorld("/nonexistent/nowhere.world");
    FAIL();
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/nowhere.world: no such world file"));
  }
}

// Fuzzer finding: libsdformat reads a document that is not SDF again as URDF, through
// urdfdom, which leaks on a robot whose joints form a cycle (and recursed past the stack on a
// self-joint). The loader refuses the URDF first, naming the line of its <robot>.
TEST(SdfWorldLoaderTest, AUrdfIsRefusedBeforeLibsdformatConvertsIt) {
  const std::string urdf =
      "<?xml version=\"1.0\"?>\n\n<robot name=\"r\">\n"
      "  <link name=\"a\"/><link name=\"b\"/>\n"
      "  <joint name=\"ab\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>\n"
      "  <joint name=\"ba\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint>\n"
      "</robot>\n";
  try {
    LoadSdfWorldFromString(urdf, "cycle.urdf");
    FAIL() << "a URDF was read as a world";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cycle.urdf:3: a <robot> element (URDF)"));
  }
}

// Found by probing (issue 19): degenerate or absurd shapes were accepted and failed later
// without a file or field (a zero plane normal, a negative radius, a box 1e300 m long, door
// limits of 1e300 rad). Each is refused by model and collision.
TEST(SdfWorldLoaderTest, DegenerateShapesAreRefusedByName) {
  const auto error_of = [](const std::string& geometry) {
    const std::string sdf =
        "<?xml version='1.0'?><sdf version='1.9'><world name='w'><model name='m'>"
        "<static>true</static><link name='l'><collision name='c'><geometry>" +
        geometry + "</geometry></collision></link></model></world></sdf>";
    try {
      LoadSdfWorldFromString(sdf, "shapes.sdf");
    } catch (const LoadError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of("<box><size>1 1 1</size></box>"), "");
  for (const char* bad :
       {"<box><size>1e300 0.1 2</size></box>", "<box><size>1 0 1</size></box>",
        "<cylinder><radius>-1</radius><length>2</length></cylinder>",
        "<cylinder><radius>0.2</radius><length>nan</length></cylinder>",
        "<sphere><radius>0</radius></sphere>", "<plane><normal>0 0 0</normal></plane>"}) {
    const std::string error = error_of(bad);
    EXPECT_THAT(error, HasSubstr("shapes.sdf: model 'm' collision 'c'")) << bad;
  }
  std::string door = DoorSdf("<box><size>1 0.05 2</size></box>");
  door.replace(door.find("<upper>1.5</upper>"), 18, "<upper>1e300</upper>");
  try {
    LoadSdfWorldFromString(door, "door.sdf");
    ADD_FAILURE() << "a door limit of 1e300 rad was accepted";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("within +-2 pi rad"));
  }
}

TEST(SdfWorldLoaderTest, MeshCollisionFromObjRelativeToTheWorldFile) {
  const auto dir = egress::testing::TestTempPath("mesh_world");
  std::filesystem::create_directories(dir);
  {
    std::ofstream obj(dir / "wedge.obj");
    obj << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    std::ofstream sdf(dir / "w.sdf");
    sdf << R"(<?xml version="1.0"?><sdf version="1.6"><world name="w"><model name="rock">
      <static>true</static><pose>2 0 0 0 0 0</pose><link name="l"><collision name="c">
      <geometry><mesh><uri>wedge.obj</uri><scale>2 2 2</scale></mesh></geometry></collision>
      </link></model></world></sdf>)";
  }
  const WorldDescription w = LoadSdfWorld(dir / "w.sdf");
  ASSERT_EQ(w.shapes.size(), 1u);
  ASSERT_EQ(w.shapes[0].kind, ShapeKind::kMesh);
  EXPECT_EQ(w.shapes[0].mesh->triangles.size(), 4u);
  Eigen::Vector3d lo, hi;
  w.shapes[0].CalcWorldBounds(&lo, &hi);
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3d(2, 0, 0)));
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3d(4, 2, 2)));
  std::filesystem::remove(dir / "wedge.obj");
  try {
    LoadSdfWorld(dir / "w.sdf");
    FAIL() << "a missing mesh was accepted";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("wedge.obj"));
    EXPECT_THAT(e.what(), HasSubstr("rock"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace egress::twin
