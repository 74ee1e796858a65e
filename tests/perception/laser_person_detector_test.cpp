// LaserPersonDetector on ray-cast scans: legs, body sections, walls and furniture.

#include "egress/perception/laser_person_detector.h"

#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "synthetic.h"

namespace egress::perception {
namespace {

using testing::CastScanAtDiscs;
using testing::Disc;
using testing::MakeScan;

constexpr int kBeams = 1081;  // the HSR's base laser: 0.25 degree over 270 degrees

std::vector<LaserPersonDetection> DetectDiscs(const std::vector<Disc>& discs,
                                              const Pose2& X_ML = Pose2(),
                                              const OccupancyGrid* grid = nullptr,
                                              LaserPersonDetectorConfig config = {}) {
  LaserScan scan = MakeScan(kBeams);
  CastScanAtDiscs(discs, X_ML, &scan, grid);
  const LaserPersonDetector detector(config);
  if (grid == nullptr) return detector.Detect(scan, X_ML);
  // A return within 0.15 m of an occupied cell is on the map.
  return detector.Detect(scan, X_ML, [grid](const Eigen::Vector2d& p) {
    for (double dx = -0.15; dx <= 0.15; dx += 0.05) {
      for (double dy = -0.15; dy <= 0.15; dy += 0.05) {
        if (grid->IsOccupied(p + Eigen::Vector2d(dx, dy))) return true;
      }
    }
    return false;
  });
}

TEST(LaserPersonDetectorTest, TwoLegsAreOnePersonBetweenThem) {
  const auto people = DetectDiscs({{{2.0, 0.15}, 0.06}, {{2.05, -0.15}, 0.06}});
  ASSERT_EQ(people.size(), 1u);
  EXPECT_EQ(people[0].legs, 2);
  EXPECT_NEAR(people[0].p_MP.x(), 2.025, 0.05);
  EXPECT_NEAR(people[0].p_MP.y(), 0.0, 0.03);
}

TEST(LaserPersonDetectorTest, ABodySectionIsFoundAtItsCentreNotItsNearSide) {
  for (const double range : {1.0, 3.0, 6.0}) {
    const Eigen::Vector2d centre(range * std::cos(0.4), range * std::sin(0.4));
    const auto people = DetectDiscs({{centre, 0.25}});
    ASSERT_EQ(people.size(), 1u) << range;
    EXPECT_EQ(people[0].legs, 0);
    EXPECT_LT((people[0].p_MP - centre).norm(), 0.05) << range;
    EXPECT_NEAR(people[0].radius, 0.25, 0.05) << range;
  }
}

// A wide body (a wheelchair user, 0.33 m) just past the edge of the 270 degree view shows a
// leg-wide sliver: reported as a leg, its centre is 0.3 m off the person's, so it is marked
// at_edge (the tracker does not let it drag a track). A leg-wide sliver inside the view is an
// unmarked leg.
TEST(LaserPersonDetectorTest, ASliverAtTheEdgeOfTheViewIsMarked) {
  constexpr double kRadius = 0.33;
  constexpr double kEdge = 135.0 * std::numbers::pi / 180.0;
  int marked = 0;
  for (const double side : {-1.0, 1.0}) {
    for (const double past_deg : {3.0, 5.0, 7.0}) {
      const double bearing = side * (kEdge + past_deg * std::numbers::pi / 180.0);
      const Eigen::Vector2d centre(2.0 * std::cos(bearing), 2.0 * std::sin(bearing));
      for (const auto& person : DetectDiscs({{centre, kRadius}})) {
        EXPECT_TRUE(person.at_edge || (person.p_MP - centre).norm() < 0.15)
            << "side " << side << ", " << past_deg << " deg past the edge: a person at "
            << person.p_MP.transpose() << ", " << person.legs << " legs, unmarked";
        marked += person.at_edge;
      }
    }
  }
  EXPECT_GT(marked, 0);
  const double inside = kEdge - 5.0 * std::numbers::pi / 180.0;
  const Eigen::Vector2d leg(2.0 * std::cos(inside), 2.0 * std::sin(inside));
  const auto people = DetectDiscs({{leg, 0.06}});
  ASSERT_EQ(people.size(), 1u);
  EXPECT_EQ(people[0].legs, 1);
  EXPECT_FALSE(people[0].at_edge);
}

TEST(LaserPersonDetectorTest, PeopleAllRoundTheRobotAreFoundInTheMapFrame) {
  // Behind the robot's right shoulder, beside it and ahead: where the head camera is not.
  const Pose2 X_ML{5.0, 3.0, std::numbers::pi / 2};
  const std::vector<Eigen::Vector2d> centres = {{6.5, 3.0}, {3.5, 3.2}, {5.0, 5.0}, {6.2, 2.0}};
  std::vector<Disc> discs;
  for (const auto& c : centres)
    discs.push_back({c, 0.23});
  const auto people = DetectDiscs(discs, X_ML);
  ASSERT_EQ(people.size(), centres.size());
  for (const auto& c : centres) {
    double nearest = 1e9;
    for (const auto& p : people)
      nearest = std::min(nearest, (p.p_MP - c).norm());
    EXPECT_LT(nearest, 0.06) << c.transpose();
  }
}

TEST(LaserPersonDetectorTest, PeopleSideBySideStaySeparate) {
  const auto people = DetectDiscs({{{3.0, 0.35}, 0.23}, {{3.0, -0.35}, 0.23}});
  ASSERT_EQ(people.size(), 2u);
  EXPECT_GT((people[0].p_MP - people[1].p_MP).norm(), 0.5);
}

TEST(LaserPersonDetectorTest, WallsAndWideFurnitureAreNotPeople) {
  const OccupancyGrid map = testing::TwoRoomMap();
  // From inside the west room, a person by the divider; the walls are mapped (background).
  const Pose2 X_ML{3.0, 4.0, 0.0};
  auto people = DetectDiscs({{{5.0, 4.6}, 0.23}}, X_ML, &map);
  ASSERT_EQ(people.size(), 1u);
  EXPECT_LT((people[0].p_MP - Eigen::Vector2d(5.0, 4.6)).norm(), 0.06);
  // A crate 1.2 m across off the map: too wide to be anyone.
  people = DetectDiscs({{{2.0, 0.0}, 0.6}});
  EXPECT_TRUE(people.empty());
  // Nothing but walls.
  EXPECT_TRUE(DetectDiscs({}, X_ML, &map).empty());
}

// A scan from the origin (facing +x) of straight faces, each from a to b.
LaserScan ScanOfFaces(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& faces) {
  LaserScan scan = MakeScan(kBeams);
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const Eigen::Vector2d d(std::cos(scan.AngleAt(i)), std::sin(scan.AngleAt(i)));
    for (const auto& [a, b] : faces) {
      // a + s (b - a) = t d, s in [0, 1], t > 0.
      Eigen::Matrix2d m;
      m << d, a - b;
      if (std::abs(m.determinant()) < 1e-12) continue;
      const Eigen::Vector2d ts = m.inverse() * a;
      if (ts.x() > 0 && ts.y() >= 0 && ts.y() <= 1 && ts.x() < scan.ranges[i])
        scan.ranges[i] = float(ts.x());
    }
  }
  return scan;
}

// A cabinet's flat face, or its corner, off the map and as wide as a body (S7: a phantom person
// beside the robot that then "entered" the door zone): no body section.
TEST(LaserPersonDetectorTest, AFlatFaceOrABoxCornerAsWideAsABodyIsNotAPerson) {
  const LaserPersonDetector detector;
  for (const double range : {0.6, 1.0, 2.5}) {
    for (const double width : {0.3, 0.4, 0.6}) {
      const LaserScan scan = ScanOfFaces({{{range, -width / 2}, {range, width / 2}}});
      EXPECT_TRUE(detector.Detect(scan, Pose2()).empty()) << width << " m face at " << range;
      // The corner of a box seen across its diagonal: two faces of `width` each (a smaller one
      // fits a body's circle within the range noise: the header's limits).
      if (width < 0.4) continue;
      const Eigen::Vector2d corner(range, 0.0);
      const Eigen::Vector2d u(std::sqrt(0.5), std::sqrt(0.5)), v(std::sqrt(0.5), -std::sqrt(0.5));
      const LaserScan corner_scan =
          ScanOfFaces({{corner, corner + u * width}, {corner, corner + v * width}});
      EXPECT_TRUE(detector.Detect(corner_scan, Pose2()).empty())
          << width << " m corner at " << range;
    }
  }
  // A body of the same width there still is one.
  EXPECT_EQ(DetectDiscs({{{1.2, 0.0}, 0.2}}).size(), 1u);
}

TEST(LaserPersonDetectorTest, OneLegAloneIsStillReportedAndSpeckleIsNot) {
  auto people = DetectDiscs({{{1.5, -0.5}, 0.06}});
  ASSERT_EQ(people.size(), 1u);
  EXPECT_EQ(people[0].legs, 1);
  // A 1 cm wire at 4 m: a return or two, noise.
  people = DetectDiscs({{{4.0, 0.0}, 0.005}});
  EXPECT_TRUE(people.empty());
}

TEST(LaserPersonDetectorTest, BadInputIsRefusedNamingIt) {
  LaserScan scan = MakeScan(kBeams);
  const LaserPersonDetector detector;
  const Pose2 not_finite{std::nan(""), 0.0, 0.0};
  EXPECT_THROW(detector.Detect(scan, not_finite), InvalidArgument);
  scan.angle_increment = -1.0;
  EXPECT_THROW(detector.Detect(scan, Pose2()), InvalidArgument);
  LaserPersonDetectorConfig config;
  config.leg_max_width = 1.0;  // wider than body_max_width
  EXPECT_THROW(LaserPersonDetector{config}, InvalidArgument);
  // NaN and inf beams are skipped, not crashed on.
  scan = MakeScan(kBeams);
  scan.ranges[10] = std::nanf("");
  EXPECT_TRUE(detector.Detect(scan, Pose2()).empty());
}

}  // namespace
}  // namespace egress::perception
