#include "egress/twin/building.h"

#include <set>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_model.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

std::string Box(const std::string& name, double x, double y, double z, double yaw,
                const std::string& size) {
  return StrCat("<model name='", name, "'><static>true</static><pose>", x, " ", y, " ", z, " 0 0 ",
                yaw, "</pose><link name='link'><collision name='c'><geometry><box><size>", size,
                "</size></box></geometry></collision></link></model>");
}

// A door across a corridor along x: hinge at (x, y_hinge), the leaf along +y (`width` long),
// opening clockwise (to +x) when `lower` is negative.
std::string Door(const std::string& name, double x, double y_hinge, double width, double lower,
                 double upper) {
  return StrCat("<model name='", name, "'><pose>", x, " ", y_hinge,
                " 1 0 0 0</pose><link name='frame'/><link name='leaf'><inertial><mass>30</mass>"
                "</inertial><collision name='leaf'><pose>0 ",
                width / 2, " 0 0 0 0</pose><geometry><box><size>0.04 ", width,
                " 2</size></box></geometry></collision></link><joint name='hinge' "
                "type='revolute'><parent>frame</parent><child>leaf</child><axis><xyz>0 0 1</xyz>"
                "<limit><lower>",
                lower, "</lower><upper>", upper,
                "</upper></limit></axis></joint><joint name='fix' type='fixed'><parent>world"
                "</parent><child>frame</child></joint></model>");
}

std::string World(const std::string& models, const std::string& frames = "") {
  return StrCat("<?xml version='1.0'?><sdf version='1.7'><world name='w'>", models, frames,
                "</world></sdf>");
}

// A corridor along x (y in [0, 2]) closed by a wall across x = 5 with a 1 m doorway at y 0.5-1.5;
// the leaf hinged at y = 0.5 opens to +x.
std::string Corridor(const std::string& actuators, const std::string& frames = "") {
  return World(Box("wall_south", 5, -0.05, 1, 0, "10 0.1 2") +
                   Box("wall_north", 5, 2.05, 1, 0, "10 0.1 2") +
                   Box("cross_low", 5, 0.25, 1, 0, "0.1 0.5 2") +
                   Box("cross_high", 5, 1.75, 1, 0, "0.1 0.5 2") +
                   Door("fire_door", 5, 0.5, 1.0, -1.57, 0) + actuators,
               frames);
}

TEST(BuildingTest, ActuatorsOnTheDoorsWallFaceAwayFromIt) {
  const WorldDescription world = LoadSdfWorld(testing::WorldsDir() / "office" / "office.sdf");
  const BuildingDescription b = DescribeBuilding(world);
  ASSERT_EQ(b.doors.size(), 2u);
  const BuildingDoor* door_a = b.FindDoor("door_a");
  ASSERT_NE(door_a, nullptr);
  EXPECT_EQ(door_a->actuators.size(), 2u);
  EXPECT_TRUE(door_a->OpeningSideNormal().isApprox(Eigen::Vector2d(1, 0), 1e-9));
  const BuildingActuator* west = b.FindActuator("door_a_button");
  const BuildingActuator* east = b.FindActuator("door_a_button_east");
  ASSERT_NE(west, nullptr);
  ASSERT_NE(east, nullptr);
  EXPECT_EQ(west->kind, ActuatorKind::kPushButton);
  EXPECT_EQ(west->door, "door_a");
  EXPECT_TRUE(west->n_W.isApprox(Eigen::Vector3d(-1, 0, 0), 1e-9));
  EXPECT_NEAR(west->p_W.x(), 4.93, 1e-9);  // its face, not its centre
  EXPECT_TRUE(east->n_W.isApprox(Eigen::Vector3d(1, 0, 0), 1e-9));
  EXPECT_EQ(b.FindActuator("door_b_plate")->kind, ActuatorKind::kProximityPlate);
  EXPECT_EQ(b.FindActuator("door_b_plate")->door, "door_b");
}

TEST(BuildingTest, AnActuatorOnASideWallFacesIntoTheCorridor) {
  // On the corridor's north wall (inner face y = 2.0), 0.6 m before the door: its thin axis is
  // along y; the door's normal is along x. Another, turned 90 degrees in its own frame.
  const WorldDescription world = LoadSdfWorldFromString(
      Corridor(Box("side_button", 4.4, 1.99, 1, 0, "0.1 0.02 0.1") +
               Box("turned_plate", 5.8, 0.01, 1, M_PI / 2, "0.02 0.15 0.15")),
      "corridor.sdf", ".");
  const BuildingDescription b = DescribeBuilding(world);
  const BuildingActuator* side = b.FindActuator("side_button");
  ASSERT_NE(side, nullptr);
  EXPECT_EQ(side->door, "fire_door");
  EXPECT_TRUE(side->n_W.isApprox(Eigen::Vector3d(0, -1, 0), 1e-9));
  EXPECT_NEAR(side->p_W.y(), 1.98, 1e-9);
  const BuildingActuator* plate = b.FindActuator("turned_plate");
  ASSERT_NE(plate, nullptr);
  EXPECT_EQ(plate->kind, ActuatorKind::kProximityPlate);
  EXPECT_TRUE(plate->n_W.isApprox(Eigen::Vector3d(0, 1, 0), 1e-9));
}

TEST(BuildingTest, FarOrOversizedLookalikesAreNotedNotMatched) {
  const WorldDescription world =
      LoadSdfWorldFromString(Corridor(Box("lost_button", 9.5, 1.99, 1, 0, "0.1 0.02 0.1") +
                                      Box("plate_rack", 4.0, 1.0, 0.5, 0, "1.2 0.4 1.0")),
                             "corridor.sdf", ".");
  const BuildingDescription b = DescribeBuilding(world);
  EXPECT_TRUE(b.actuators.empty());
  ASSERT_EQ(b.notes.size(), 2u);
  EXPECT_NE(b.notes[0].find("lost_button"), std::string::npos);
  EXPECT_NE(b.notes[1].find("plate_rack"), std::string::npos);
}

TEST(BuildingTest, PlacesComeFromWorldFramesAndTheBuildingYaml) {
  const WorldDescription world =
      LoadSdfWorldFromString(Corridor("",
                                      "<frame name='exit_east'><pose>9 1 0 0 0 0</pose></frame>"
                                      "<frame name='lobby'><pose>1 1 0 0 0 1.5708</pose></frame>"),
                             "corridor.sdf", ".");
  const BuildingDescription b = DescribeBuildingFromString(world, R"(
places:
  lobby: {x: 1.5, y: 1.0, kind: room}
  post_responder: {x: 8, y: 0.5, yaw_deg: 180}
doors:
  fire_door: {glass: true}
)",
                                                           "b.yaml");
  ASSERT_EQ(b.places.size(), 3u);
  EXPECT_EQ(b.FindPlace("exit_east")->kind, "exit");
  EXPECT_TRUE(b.FindPlace("exit_east")->has_yaw);
  EXPECT_EQ(b.FindPlace("lobby")->kind, "room");
  EXPECT_DOUBLE_EQ(b.FindPlace("lobby")->X_WP.x, 1.5);  // the YAML overrides the frame
  EXPECT_FALSE(b.FindPlace("lobby")->has_yaw);
  EXPECT_EQ(b.FindPlace("post_responder")->kind, "post");
  EXPECT_NEAR(b.FindPlace("post_responder")->X_WP.yaw, M_PI, 1e-12);
  EXPECT_TRUE(b.FindDoor("fire_door")->glass);
  EXPECT_EQ(b.FindPlace("nowhere"), nullptr);
}

TEST(BuildingTest, TheYamlAssignsActuatorsTheirNamesCannot) {
  const WorldDescription world = LoadSdfWorldFromString(
      Corridor(Box("panel_7", 4.4, 1.99, 1, 0, "0.1 0.02 0.1")), "corridor.sdf", ".");
  EXPECT_TRUE(DescribeBuilding(world).actuators.empty());
  const BuildingDescription b = DescribeBuildingFromString(
      world, "actuators:\n  panel_7: {door: fire_door, type: proximity}\n", "b.yaml");
  ASSERT_EQ(b.actuators.size(), 1u);
  EXPECT_EQ(b.actuators[0].kind, ActuatorKind::kProximityPlate);
}

TEST(BuildingTest, YamlErrorsNameTheFileLineAndField) {
  const WorldDescription world = LoadSdfWorldFromString(Corridor(""), "corridor.sdf", ".");
  const auto message = [&](const std::string& yaml) {
    try {
      DescribeBuildingFromString(world, yaml, "b.yaml");
    } catch (const LoadError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(
      message("doors:\n  back_door: {glass: true}\n").find("b.yaml:2: field 'doors.back_door'"),
      std::string::npos);
  EXPECT_NE(message("places:\n  a: {x: 1}\n").find("field 'places.a.y': is required"),
            std::string::npos);
  EXPECT_NE(message("places:\n  a: {x: 1, y: .nan}\n").find("places.a.y"), std::string::npos);
  EXPECT_NE(message("places:\n  a: {x: 1, y: 1, kind: kitchen}\n").find("places.a.kind"),
            std::string::npos);
  EXPECT_NE(message("rooms: {}\n").find("unknown field"), std::string::npos);
  EXPECT_NE(message("actuators:\n  ghost: {door: fire_door}\n").find("no static model 'ghost'"),
            std::string::npos);
  EXPECT_THROW(DescribeBuilding(world, "/nonexistent/b.yaml"), LoadError);
}

}  // namespace
}  // namespace egress::twin

namespace egress::twin {
namespace {

// The office (worlds/office: door_a push buttons both sides, door_b glass with plates both
// sides, its building YAML beside it), as a scenario that names no door and no coordinate.
testing::Loaded GoalOnlyOffice(const std::string& extra = "") {
  return testing::LoadText(
      "world: office.sdf\nrobot:\n  start: {place: room_start}\n  goal: {place: room_far}\n" +
          extra,
      testing::WorldsDir() / "office");
}

TEST(ScenarioBuildingTest, DoorsActuatorsAndPlacesComeFromTheBuilding) {
  const auto loaded = GoalOnlyOffice("doors: [{door: door_a, operator: push}]\n");
  const TwinModel model(loaded.scenario, loaded.world, testing::Hsr());
  const Scenario& s = model.scenario();
  EXPECT_DOUBLE_EQ(s.robot_start.x, 2.5);
  ASSERT_TRUE(s.goal.has_value());
  EXPECT_DOUBLE_EQ(s.goal->x, 11.0);
  ASSERT_EQ(s.doors.size(), 2u);
  EXPECT_EQ(s.doors[0].door, "door_a");  // listed, its buttons filled in
  EXPECT_EQ(s.doors[0].actuators,
            (std::vector<std::string>{"door_a_button", "door_a_button_east"}));
  EXPECT_EQ(s.doors[1].door, "door_b");  // not listed: an operator of its plates' kind
  EXPECT_EQ(s.doors[1].kind, OperatorKind::kProximityPlate);
  EXPECT_TRUE(s.doors[1].glass);  // the building YAML says so
}

TEST(ScenarioBuildingTest, UnknownPlacesAndMismatchedOperatorsAreNamed) {
  const auto message = [](const testing::Loaded& loaded) {
    try {
      const TwinModel model(loaded.scenario, loaded.world, testing::Hsr());
    } catch (const LoadError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto loaded = GoalOnlyOffice();
  loaded.scenario.goal_place = "kitchen";
  const std::string unknown = message(loaded);
  EXPECT_NE(unknown.find("field 'robot.goal.place': the building has no place 'kitchen'"),
            std::string::npos)
      << unknown;
  EXPECT_NE(unknown.find("room_far"), std::string::npos);  // the places it has
  const std::string plates = message(GoalOnlyOffice("doors: [{door: door_b, operator: push}]\n"));
  EXPECT_NE(plates.find("door 'door_b' has no push button in the building"), std::string::npos)
      << plates;
}

TEST(ScenarioFamilyTest, EachSeedDrawsAVariantAndTheSameSeedTheSameOne) {
  const auto loaded = GoalOnlyOffice(
      "obstacles: [{name: cart, box: [0.6, 0.4, 0.9], x: 7.0, y: 4.0}]\n"
      "randomize:\n  start_places: [room_start, room_middle, room_far]\n"
      "  goal_places: [room_start, room_middle, room_far, exit_east]\n"
      "  open_doors: 1.0\n  obstacle_xy: 0.05\n");
  const TwinModel model(loaded.scenario, loaded.world, testing::Hsr());
  ASSERT_TRUE(model.scenario().randomize.DrawsVariants());
  std::set<std::pair<std::string, std::string>> pairs;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    const Scenario v = DrawScenarioVariant(model.scenario(), model.building(), seed);
    EXPECT_NE(v.start_place, v.goal_place);
    EXPECT_FALSE(v.randomize.DrawsVariants());
    EXPECT_DOUBLE_EQ(v.robot_start.x, model.building().FindPlace(v.start_place)->X_WP.x);
    for (const auto& door : v.doors) {
      ASSERT_FALSE(door.open_at.empty());
      EXPECT_EQ(door.open_at.front(), 0.0);  // open_doors 1: every door opened at the start
    }
    const Eigen::Vector3d moved = v.obstacles[0].X_WS.translation() - Eigen::Vector3d(7, 4, 0.45);
    EXPECT_LE(moved.head<2>().cwiseAbs().maxCoeff(), 0.05);
    pairs.insert({v.start_place, v.goal_place});
    const Scenario again = DrawScenarioVariant(model.scenario(), model.building(), seed);
    EXPECT_EQ(again.goal_place, v.goal_place);
    EXPECT_EQ(again.obstacles[0].X_WS.translation(), v.obstacles[0].X_WS.translation());
  }
  EXPECT_GE(pairs.size(), 5u);
  auto bad = loaded.scenario;
  bad.randomize.goal_places = {"attic"};
  EXPECT_THROW(DrawScenarioVariant(bad, model.building(), 1), LoadError);
}

}  // namespace
}  // namespace egress::twin
