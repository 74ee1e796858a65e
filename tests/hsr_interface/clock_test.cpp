#include "egress/hsr_interface/clock.h"

#include <cmath>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {

using std::chrono::milliseconds;

TEST(SimClockTest, AdvancesOnlyWhenTold) {
  SimClock clock;
  EXPECT_EQ(clock.Now(), Time{0});
  EXPECT_EQ(clock.Now(), Time{0});  // No hidden wall-clock progress.
  clock.AdvanceBy(milliseconds(100));
  EXPECT_EQ(clock.Now(), milliseconds(100));
  clock.AdvanceTo(Time{milliseconds(250)});
  EXPECT_EQ(clock.Now(), milliseconds(250));
  clock.AdvanceTo(Time{milliseconds(250)});  // Standing still is allowed.
  EXPECT_EQ(clock.Now(), milliseconds(250));
}

TEST(SimClockTest, NeverRunsBack) {
  SimClock clock(Time{milliseconds(500)});
  EXPECT_THROW(clock.AdvanceBy(Duration{-1}), InvalidArgument);
  EXPECT_THROW(clock.AdvanceTo(Time{milliseconds(499)}), InvalidArgument);
  EXPECT_EQ(clock.Now(), milliseconds(500));
}

TEST(SimClockTest, IntegerStepsDoNotDrift) {
  // Integer nanoseconds: 1000 control steps of 10 ms land exactly on 10 s.
  SimClock clock;
  const Duration dt = SecondsToDuration(1.0 / 100.0);  // 100 Hz control: exact in ns
  for (int i = 0; i < 1000; ++i)
    clock.AdvanceBy(dt);
  EXPECT_EQ(clock.Now(), std::chrono::seconds(10));
}

TEST(SteadyClockTest, IsMonotonic) {
  SteadyClock clock;
  Time previous = clock.Now();
  EXPECT_GE(previous.count(), 0);
  for (int i = 0; i < 1000; ++i) {
    const Time now = clock.Now();
    EXPECT_GE(now, previous);
    previous = now;
  }
}

TEST(TimeTest, SecondsConversions) {
  EXPECT_EQ(SecondsToDuration(1.5), milliseconds(1500));
  EXPECT_EQ(SecondsToDuration(-0.25), milliseconds(-250));
  EXPECT_EQ(SecondsToDuration(1e-9), Duration{1});
  EXPECT_DOUBLE_EQ(ToSeconds(milliseconds(1500)), 1.5);
  EXPECT_THROW(SecondsToDuration(std::nan("")), InvalidArgument);
  EXPECT_THROW(SecondsToDuration(1e12), InvalidArgument);
}

}  // namespace
}  // namespace egress
