#include "egress/ros2/dds_node.h"

#include <chrono>
#include <condition_variable>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <geometry_msgs/msg/TwistPubSubTypes.h>

#include <sensor_msgs/msg/LaserScanPubSubTypes.h>
#include "dds_domain.h"
#include "egress/ros2/asan_options.h"  // this test program runs Fast DDS

namespace egress::ros2 {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Waits (bounded: a broken discovery fails the test, it does not hang it) for `done`.
template <class Pred>
bool WaitFor(Pred done, std::chrono::seconds limit = std::chrono::seconds(20)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

TEST(DdsNodeTest, TopicNamesFollowRos2) {
  EXPECT_EQ(DdsTopicName("/omni_base_controller/cmd_vel"), "rt/omni_base_controller/cmd_vel");
  EXPECT_THAT([] { DdsTopicName("scan"); }, ThrowsMessage<InvalidArgument>(HasSubstr("absolute")));
  EXPECT_THAT([] { DdsTopicName("/a//b"); }, ThrowsMessage<InvalidArgument>(HasSubstr("//")));
  EXPECT_THAT([] { DdsTopicName("/a b"); }, ThrowsMessage<InvalidArgument>(HasSubstr("' '")));
  EXPECT_THAT([] { DdsNode("x", 300); }, ThrowsMessage<InvalidArgument>(HasSubstr("domain")));
}

// Two participants (as two processes would be): a scan published by one arrives whole at the
// other, over DDS discovery and the network stack (loopback or shared memory).
TEST(DdsNodeTest, AScanCrossesBetweenTwoParticipants) {
  const egress::testing::DdsDomain claim;
  const int domain = claim.id();
  DdsNode robot("robot", domain), brain("brain", domain);
  std::mutex mutex;
  std::vector<sensor_msgs::msg::LaserScan> received;
  auto sub = brain.CreateSubscription<sensor_msgs::msg::LaserScanPubSubType>(
      "/scan", QosProfile::SensorData(), [&](const sensor_msgs::msg::LaserScan& m) {
        const std::lock_guard<std::mutex> lock(mutex);
        received.push_back(m);
      });
  auto pub = robot.CreatePublisher<sensor_msgs::msg::LaserScanPubSubType>("/scan",
                                                                          QosProfile::SensorData());
  ASSERT_TRUE(WaitFor([&] { return pub->MatchedSubscriptions() == 1; }));
  sensor_msgs::msg::LaserScan scan;
  scan.header().frame_id("base_range_sensor_link");
  scan.header().stamp().sec(42);
  scan.ranges(std::vector<float>(1081, 2.5f));
  scan.ranges()[7] = 1.25f;
  // Best effort: publish until one arrives (a first sample may go before the reader is ready).
  ASSERT_TRUE(WaitFor([&] {
    pub->Publish(scan);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::lock_guard<std::mutex> lock(mutex);
    return !received.empty();
  }));
  const std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(received[0].header().frame_id(), "base_range_sensor_link");
  EXPECT_EQ(received[0].header().stamp().sec(), 42);
  ASSERT_EQ(received[0].ranges().size(), 1081u);
  EXPECT_FLOAT_EQ(received[0].ranges()[7], 1.25f);
}

TEST(DdsNodeTest, ReliableCommandsArriveInOrderAndATopicKeepsOneType) {
  const egress::testing::DdsDomain claim;
  const int domain = claim.id();
  DdsNode robot("robot", domain), brain("brain", domain);
  std::mutex mutex;
  std::vector<double> vx;
  auto sub = robot.CreateSubscription<geometry_msgs::msg::TwistPubSubType>(
      "/omni_base_controller/cmd_vel", QosProfile::Default(),
      [&](const geometry_msgs::msg::Twist& m) {
        const std::lock_guard<std::mutex> lock(mutex);
        vx.push_back(m.linear().x());
      });
  auto pub = brain.CreatePublisher<geometry_msgs::msg::TwistPubSubType>(
      "/omni_base_controller/cmd_vel", QosProfile::Default());
  ASSERT_TRUE(
      WaitFor([&] { return pub->MatchedSubscriptions() == 1 && sub->MatchedPublications() == 1; }));
  for (int i = 0; i < 5; ++i) {
    geometry_msgs::msg::Twist t;
    t.linear().x(0.1 * i);
    pub->Publish(t);
  }
  ASSERT_TRUE(WaitFor([&] {
    const std::lock_guard<std::mutex> lock(mutex);
    return vx.size() == 5;
  }));
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(vx[std::size_t(i)], 0.1 * i) << "command " << i << " out of order or altered";
  EXPECT_THAT(
      [&] {
        brain.CreatePublisher<sensor_msgs::msg::LaserScanPubSubType>(
            "/omni_base_controller/cmd_vel", QosProfile::Default());
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("already used with type")));
}

}  // namespace
}  // namespace egress::ros2
