#include "egress/perception/person_tracker.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::perception {
namespace {

using std::chrono::milliseconds;
constexpr double kDeg = std::numbers::pi / 180.0;

// The door of the lab: along y = 0 from x = 0 (hinge) to x = 0.9, opening toward +y.
DoorZone LabZone() {
  return {{"lab", {0.0, 0.0}, {0.9, 0.0}, 1.0, std::numbers::pi / 2}, 1.0, 0.3};
}

// Feeds a straight walk at 10 Hz (the detector's ~8 Hz rounded) and returns the tracker.
PersonTracker Walk(Eigen::Vector2d start, Eigen::Vector2d velocity, int frames) {
  PersonTracker tracker;
  for (int i = 0; i < frames; ++i) {
    tracker.Update({start + velocity * (0.1 * i)}, milliseconds(100 * i));
  }
  return tracker;
}

TEST(PersonTrackerTest, SmoothedVelocityAndForecast) {
  const PersonTracker tracker = Walk({0.45, -4.0}, {0.0, 1.2}, 25);
  ASSERT_EQ(tracker.people().size(), 1u);
  const TrackedPerson& person = tracker.people()[0];
  EXPECT_NEAR(person.v_MP.y(), 1.2, 0.06);
  EXPECT_NEAR(person.v_MP.x(), 0.0, 0.02);
  ASSERT_EQ(person.forecast.size(), 4u);  // 4 x 0.2 s
  EXPECT_NEAR(person.forecast[3].y() - person.p_MP.y(), 1.2 * 0.8, 0.06);
}

// H2's fast person stands, then sets off at 1.6 m/s: within half a second (4 frames at 8 Hz) the
// track must say most of that speed, or nothing downstream sees them coming in time. Smoothing
// the smoothed positions' differences read a third of it.
TEST(PersonTrackerTest, APersonWhoSetsOffReadsMostOfTheirSpeedWithinHalfASecond) {
  PersonTracker tracker;
  const Eigen::Vector2d p_MStart(0.45, -3.0);
  int ms = 0;
  for (int i = 0; i < 8; ++i, ms += 125)
    tracker.Update({p_MStart}, milliseconds(ms));
  ASSERT_EQ(tracker.people().size(), 1u);
  EXPECT_LT(tracker.people()[0].v_MP.norm(), 1e-9);
  const int set_off_ms = ms - 125;
  for (int i = 0; i < 4; ++i, ms += 125) {
    const double walked = 1.6 * (ms - set_off_ms) / 1000.0;
    tracker.Update({p_MStart + Eigen::Vector2d(0.0, walked)}, milliseconds(ms));
  }
  ASSERT_EQ(tracker.people().size(), 1u);
  EXPECT_GT(tracker.people()[0].v_MP.y(), 0.7 * 1.6);
  EXPECT_LT(tracker.people()[0].v_MP.y(), 1.6);  // still smoothed, not the raw difference
}

// The rest point: where the person stood. A standing person's detections placed a few
// centimetres off now and then push the smoothed velocity past walking pace for a frame or two;
// they stay by their rest point. Walking off, they leave it behind.
TEST(PersonTrackerTest, TheRestPointStaysWhereTheyStoodOnceTheyWalkOff) {
  PersonTracker tracker;
  const Eigen::Vector2d p_MStand(1.0, 2.0);
  int ms = 0;
  double fastest = 0.0;
  for (int i = 0; i < 20; ++i, ms += 100) {
    const Eigen::Vector2d off = i % 5 == 4 ? Eigen::Vector2d(0.1, 0.0) : Eigen::Vector2d::Zero();
    tracker.Update({p_MStand + off}, milliseconds(ms));
    ASSERT_EQ(tracker.people().size(), 1u);
    const TrackedPerson& person = tracker.people()[0];
    fastest = std::max(fastest, person.v_MP.norm());
    EXPECT_LT((person.p_MP - person.p_MRest).norm(), 0.1) << "frame " << i;
  }
  EXPECT_GT(fastest, kRestSpeedMps) << "the test's wobble reads as walking pace";
  for (int i = 1; i <= 10; ++i, ms += 100)
    tracker.Update({p_MStand + Eigen::Vector2d(0.12 * i, 0.0)}, milliseconds(ms));
  const TrackedPerson& walker = tracker.people()[0];
  EXPECT_LT((walker.p_MRest - p_MStand).norm(), 0.15);
  EXPECT_GT((walker.p_MP - walker.p_MRest).norm(), 0.8);
}

// A missed frame: the velocity divides by the time between the two detections, not by the
// frame interval (a walker does not read twice their speed after a miss).
TEST(PersonTrackerTest, VelocitySpansTheMissedFrames) {
  PersonTracker tracker;
  for (int i = 0; i < 20; ++i) {
    if (i == 10 || i == 11) {
      tracker.Update({}, milliseconds(100 * i));
      continue;
    }
    tracker.Update({Eigen::Vector2d(0.1 * i, 0.0)}, milliseconds(100 * i));
    if (i == 12) {
      ASSERT_EQ(tracker.people().size(), 1u);
      EXPECT_NEAR(tracker.people()[0].v_MP.x(), 1.0, 0.05);
    }
  }
}

TEST(PersonTrackerTest, IntentOnScriptedTracks) {
  const DoorZone zone = LabZone();
  DoorState closed;
  // Walking straight at the opening, 1.6 m away: crossing within the horizon.
  const PersonTracker toward = Walk({0.45, -4.0}, {0.0, 1.2}, 20);
  EXPECT_EQ(ClassifyIntent(toward.people()[0], zone, closed), PersonIntent::kCrossing);
  // Parallel to the door 1.5 m in front of it: walking past.
  const PersonTracker past = Walk({-3.0, -1.5}, {1.2, 0.0}, 20);
  EXPECT_EQ(ClassifyIntent(past.people()[0], zone, closed), PersonIntent::kWalkingPast);
  // Toward the door but far away: approaching.
  const PersonTracker far = Walk({0.45, -9.0}, {0.0, 1.0}, 20);
  EXPECT_EQ(ClassifyIntent(far.people()[0], zone, closed), PersonIntent::kApproaching);
  // Standing at the leaf's free edge of a door open at 70 degrees: holding it.
  DoorState open;
  open.observed = true;
  open.angle = 70 * kDeg;
  open.open_fraction = 70.0 / 90.0;
  const Eigen::Vector2d tip = zone.door.LeafTip(open.angle);
  const PersonTracker holder = Walk(tip + Eigen::Vector2d(0.3, 0.2), {0.0, 0.0}, 15);
  EXPECT_EQ(ClassifyIntent(holder.people()[0], zone, open), PersonIntent::kHoldingDoor);
  EXPECT_EQ(ClassifyIntent(holder.people()[0], zone, closed), PersonIntent::kStationary);
}

TEST(PersonTrackerTest, DoorZoneOccupancyForecast) {
  const DoorZone zone = LabZone();
  // 1.9 m from the zone's edge... at 1.2 m/s it enters within 0.8 s? Place it closer.
  const PersonTracker tracker = Walk({0.45, -2.5}, {0.0, 1.2}, 10);  // now at y ~ -1.42
  const auto occupied = ForecastZoneOccupancy(tracker.people(), zone);
  ASSERT_EQ(occupied.size(), 5u);
  EXPECT_FALSE(occupied[0]);  // not yet in the zone (depth 1 m + radius 0.3 m)
  EXPECT_TRUE(occupied[4]);   // forecast into it within 0.8 s
  EXPECT_TRUE(ForecastZoneOccupancy({}, zone).size() == 1u);
}

TEST(PersonTrackerTest, TracksSeveralPeopleAndDropsLostOnes) {
  PersonTracker tracker;
  tracker.Update({{0, 0}, {5, 5}}, milliseconds(0));
  tracker.Update({{0.1, 0}, {5, 5.1}}, milliseconds(100));
  EXPECT_EQ(tracker.people().size(), 2u);
  for (int i = 0; i < 5; ++i)
    tracker.Update({{0.2 + 0.1 * i, 0}}, milliseconds(200 + 100 * i));
  EXPECT_EQ(tracker.people().size(), 1u);
  EXPECT_THROW(tracker.Update({{std::nan(""), 0}}, milliseconds(800)), InvalidArgument);
  EXPECT_THROW(tracker.Update({}, milliseconds(10)), InvalidArgument);  // time went backwards
}

}  // namespace
}  // namespace egress::perception
