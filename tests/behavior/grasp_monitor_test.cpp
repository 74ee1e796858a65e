#include "egress/behavior/grasp_monitor.h"

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

GripperState Reading(double t, double position, double effort) {
  GripperState s;
  s.stamp = SecondsToDuration(t) + Time{};
  s.hand_motor_position = position;
  s.effort = effort;
  return s;
}

GripperCommand Command(GripperCommand::Mode mode) {
  GripperCommand c;
  c.mode = mode;
  c.effort = mode == GripperCommand::Mode::kGrasp ? 10.0 : 0.0;
  return c;
}

// Feeds readings every 10 ms from t0 to t1 with the angle moving linearly from q0 to q1.
void Feed(GraspMonitor* m, double t0, double t1, double q0, double q1, double effort) {
  for (double t = t0; t <= t1 + 1e-9; t += 0.01)
    m->Update(Reading(t, q0 + (q1 - q0) * (t - t0) / (t1 - t0 > 0 ? t1 - t0 : 1), effort));
}

TEST(GraspMonitorTest, FingersStoppedShortOfClosedAndSqueezingHoldSomething) {
  GraspMonitor m;
  m.OnCommand(Command(GripperCommand::Mode::kGrasp));
  Feed(&m, 0.0, 0.8, 1.24, 0.45, 0.0);  // closing
  EXPECT_FALSE(m.holding());
  Feed(&m, 0.81, 0.9, 0.45, 0.45, 10.0);  // stopped on the bottle, but not yet settled
  EXPECT_FALSE(m.holding());
  Feed(&m, 0.91, 1.2, 0.45, 0.45, 10.0);
  EXPECT_TRUE(m.holding());
  // Opening lets go.
  m.OnCommand(Command(GripperCommand::Mode::kOpen));
  m.Update(Reading(1.21, 0.46, 0.0));
  EXPECT_FALSE(m.holding());
}

TEST(GraspMonitorTest, TheFingersAreAtRestOnceTheyMovedAfterTheCommandAndStopped) {
  GraspMonitor m;
  Feed(&m, 0.0, 0.5, 1.24, 1.24, 0.0);  // open and still before any command: not "done"
  m.OnCommand(Command(GripperCommand::Mode::kGrasp));
  Feed(&m, 0.51, 0.6, 1.24, 1.24, 0.0);  // the command has not reached the fingers yet
  EXPECT_FALSE(m.at_rest());
  Feed(&m, 0.61, 1.4, 1.24, 0.45, 0.0);  // closing
  EXPECT_FALSE(m.at_rest());
  Feed(&m, 1.41, 1.5, 0.45, 0.45, 10.0);  // stopped, not settled yet
  EXPECT_FALSE(m.at_rest());
  Feed(&m, 1.51, 1.8, 0.45, 0.45, 10.0);
  EXPECT_TRUE(m.at_rest());
  EXPECT_TRUE(m.holding());
  // A new command starts over, whatever it is.
  m.OnCommand(Command(GripperCommand::Mode::kOpen));
  m.Update(Reading(1.81, 0.45, 0.0));
  EXPECT_FALSE(m.at_rest());
}

TEST(GraspMonitorTest, ClosingOnNothingOrASlipIsNotHolding) {
  GraspMonitor m;
  m.OnCommand(Command(GripperCommand::Mode::kGrasp));
  Feed(&m, 0.0, 1.5, 1.24, -0.3, 0.0);
  Feed(&m, 1.51, 2.0, -0.3, -0.3, 0.0);  // closed fully: nothing between the fingers
  EXPECT_FALSE(m.holding());

  GraspMonitor slip;
  slip.OnCommand(Command(GripperCommand::Mode::kGrasp));
  Feed(&slip, 0.0, 0.5, 0.16, 0.16, 10.0);  // the flashlight
  EXPECT_TRUE(slip.holding());
  Feed(&slip, 0.51, 0.9, 0.16, -0.3, 0.0);  // it slips out, the fingers close
  EXPECT_FALSE(slip.holding());
  // Squeezing without force (a stalled motor reading no effort) is not taken for a grasp.
  GraspMonitor weak;
  weak.OnCommand(Command(GripperCommand::Mode::kGrasp));
  Feed(&weak, 0.0, 0.5, 0.45, 0.45, 0.0);
  EXPECT_FALSE(weak.holding());
}

TEST(GraspMonitorTest, WithoutAGraspCommandNothingIsHeldAndBadInputIsNamed) {
  GraspMonitor m;
  Feed(&m, 0.0, 0.5, 0.45, 0.45, 10.0);
  EXPECT_FALSE(m.holding());
  EXPECT_THROW(m.Update(Reading(0.1, 0.4, 1.0)), InvalidArgument);  // older than the last
  GraspMonitorConfig bad;
  bad.min_opening = 0.0;
  EXPECT_THROW(GraspMonitor{bad}, InvalidArgument);
}

}  // namespace
}  // namespace egress::behavior
