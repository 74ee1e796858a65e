#pragma once
/// @file
/// Rosbag2Writer: records messages as a rosbag2 bag (ROS 2 Humble's default storage: one SQLite
/// `.db3` file of CDR-serialized messages, and `metadata.yaml`), which `ros2 bag play/info` and
/// Foxglove open. Messages are the fastddsgen types, serialized as they go on the wire (the CDR
/// encapsulation header included, as rmw hands them to rosbag2).

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "egress/hsr_interface/time.h"
#include "egress/ros2/dds_node.h"

struct sqlite3;
struct sqlite3_stmt;

namespace egress::ros2 {

class Rosbag2Writer {
 public:
  /// Creates the bag folder `dir` (its file `<name>_0.db3`, `<name>` the folder's name).
  /// @throws InvalidArgument if `dir` exists (a bag is never overwritten), or it cannot be made.
  explicit Rosbag2Writer(const std::filesystem::path& dir);
  /// Close()s.
  ~Rosbag2Writer();
  Rosbag2Writer(const Rosbag2Writer&) = delete;
  Rosbag2Writer& operator=(const Rosbag2Writer&) = delete;

  /// Records `message` on ROS 2 topic `topic` at time `t` (the recording clock's).
  template <class PubSubType>
  void Write(std::string_view topic, const typename PubSubType::type& message, Time t,
             const QosProfile& qos = QosProfile::Default()) {
    PubSubType type;
    auto* data = const_cast<typename PubSubType::type*>(&message);
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
    if (!type.serialize(data, &payload))
      throw std::runtime_error("rosbag2: cannot serialize a message for " + std::string(topic));
    WriteSerialized(topic, type.getName(), qos, t, payload.data, payload.length);
  }
  /// Writes metadata.yaml and closes the database. Idempotent.
  void Close();
  std::size_t message_count() const { return message_count_; }
  const std::filesystem::path& dir() const { return dir_; }

  /// "sensor_msgs::msg::dds_::LaserScan_" -> "sensor_msgs/msg/LaserScan".
  static std::string RosTypeName(std::string_view dds_type_name);

 private:
  void WriteSerialized(std::string_view topic, std::string_view dds_type, const QosProfile& qos,
                       Time t, const unsigned char* data, std::size_t size);
  struct Topic {
    int id;
    std::string type;
    std::string qos_yaml;
    std::size_t count{0};
  };
  std::filesystem::path dir_;
  std::string file_name_;
  sqlite3* db_{nullptr};
  sqlite3_stmt* insert_{nullptr};
  std::map<std::string, Topic> topics_;
  std::size_t message_count_{0};
  Time first_{Time::max()}, last_{Time::min()};
};

}  // namespace egress::ros2
