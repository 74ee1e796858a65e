#include "egress/ros2/rosbag2_writer.h"

#include <unistd.h>

#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nav_msgs/msg/OdometryPubSubTypes.h>
#include <sensor_msgs/msg/LaserScanPubSubTypes.h>

#include "egress/hsr_interface/error.h"
#include "egress/ros2/conversions.h"

namespace egress::ros2 {
namespace {

using ::testing::HasSubstr;

std::filesystem::path TempBag(const std::string& name) {
  return std::filesystem::path(::testing::TempDir()) / (name + "_" + std::to_string(::getpid()));
}

TEST(Rosbag2WriterTest, TypeNamesAsRos2WritesThem) {
  EXPECT_EQ(Rosbag2Writer::RosTypeName("sensor_msgs::msg::dds_::LaserScan_"),
            "sensor_msgs/msg/LaserScan");
  EXPECT_THROW(Rosbag2Writer::RosTypeName("LaserScan"), InvalidArgument);
}

// A bag read back as a rosbag2 reader would: the sqlite tables, each message's CDR decoded
// into its type, and metadata.yaml's counts and times.
TEST(Rosbag2WriterTest, ABagReadsBackAsRosbag2Does) {
  const auto dir = TempBag("run");
  std::filesystem::remove_all(dir);
  LaserScan scan;
  scan.stamp = Time{1'500'000'000};
  scan.angle_min = -1.0;
  scan.angle_increment = 0.5;
  scan.range_min = 0.1;
  scan.range_max = 10.0;
  scan.ranges = {1.0f, 2.0f, 3.25f, 4.0f, 5.0f};
  Odometry odometry;
  odometry.X_OB = {0.5, 0.25, 0.1};
  {
    Rosbag2Writer bag(dir);
    bag.Write<sensor_msgs::msg::LaserScanPubSubType>("/scan", ToRos(scan), scan.stamp,
                                                     QosProfile::SensorData());
    for (int i = 0; i < 2; ++i) {
      odometry.stamp = Time{1'000'000'000 + i * 20'000'000};
      bag.Write<nav_msgs::msg::OdometryPubSubType>("/odom", ToRos(odometry), odometry.stamp);
    }
    EXPECT_THAT(
        [&] {
          bag.Write<nav_msgs::msg::OdometryPubSubType>("/scan", ToRos(odometry), odometry.stamp);
        },
        ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("sensor_msgs/msg/LaserScan")));
    EXPECT_EQ(bag.message_count(), 3u);
  }
  // Never overwritten.
  EXPECT_THAT([&] { Rosbag2Writer again(dir); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("already exists")));

  const auto file = dir / (dir.filename().string() + "_0.db3");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* q = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db,
                               "SELECT t.name, t.type, t.serialization_format, m.timestamp, "
                               "m.data FROM messages m JOIN topics t ON m.topic_id = t.id "
                               "ORDER BY m.timestamp",
                               -1, &q, nullptr),
            SQLITE_OK);
  std::vector<std::string> topics;
  std::vector<std::int64_t> stamps;
  sensor_msgs::msg::LaserScan read_scan;
  while (sqlite3_step(q) == SQLITE_ROW) {
    const std::string name = reinterpret_cast<const char*>(sqlite3_column_text(q, 0));
    topics.push_back(name);
    stamps.push_back(sqlite3_column_int64(q, 3));
    EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(q, 2)), "cdr");
    if (name != "/scan") continue;
    EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(q, 1)),
                 "sensor_msgs/msg/LaserScan");
    const int size = sqlite3_column_bytes(q, 4);
    eprosima::fastrtps::rtps::SerializedPayload_t payload{std::uint32_t(size)};
    std::memcpy(payload.data, sqlite3_column_blob(q, 4), std::size_t(size));
    payload.length = std::uint32_t(size);
    sensor_msgs::msg::LaserScanPubSubType type;
    ASSERT_TRUE(type.deserialize(&payload, &read_scan));
  }
  sqlite3_finalize(q);
  sqlite3_close(db);
  EXPECT_THAT(topics, ::testing::ElementsAre("/odom", "/odom", "/scan"));
  EXPECT_EQ(stamps.back(), 1'500'000'000);
  ASSERT_EQ(read_scan.ranges().size(), 5u);
  EXPECT_FLOAT_EQ(read_scan.ranges()[2], 3.25f);
  EXPECT_EQ(read_scan.header().stamp().sec(), 1);

  const YAML::Node meta = YAML::LoadFile((dir / "metadata.yaml").string());
  const YAML::Node info = meta["rosbag2_bagfile_information"];
  EXPECT_EQ(info["storage_identifier"].as<std::string>(), "sqlite3");
  EXPECT_EQ(info["message_count"].as<int>(), 3);
  EXPECT_EQ(info["starting_time"]["nanoseconds_since_epoch"].as<std::int64_t>(), 1'000'000'000);
  EXPECT_EQ(info["duration"]["nanoseconds"].as<std::int64_t>(), 500'000'000);
  EXPECT_EQ(info["relative_file_paths"][0].as<std::string>(), file.filename().string());
  int counted = 0;
  for (const auto& t : info["topics_with_message_count"]) {
    counted += t["message_count"].as<int>();
    if (t["topic_metadata"]["name"].as<std::string>() == "/scan") {
      EXPECT_THAT(t["topic_metadata"]["offered_qos_profiles"].as<std::string>(),
                  HasSubstr("reliability: 2"));  // best effort
    }
  }
  EXPECT_EQ(counted, 3);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace egress::ros2
