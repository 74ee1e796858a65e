#pragma once
/// @file
/// DdsNode: a Fast DDS participant that speaks as a ROS 2 node does on the wire: topic
/// `/a/b` is DDS topic `rt/a/b`, types carry ROS 2's DDS names (fastddsgen -typeros2), and the
/// QoS profiles are ROS 2's. Typed publishers and subscriptions over the generated types.
///
/// Subscriptions call back on Fast DDS's own listener thread: keep callbacks short and
/// thread-safe (Ros2RobotPort copies the message under a mutex).

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>

#include "egress/hsr_interface/error.h"

namespace egress::ros2 {

/// ROS 2's QoS profiles, as rmw sets them on the DDS entities (volatile unless transient_local).
struct QosProfile {
  bool reliable{true};
  int depth{10};  ///< KEEP_LAST depth
  bool transient_local{false};

  static QosProfile Default() { return {true, 10, false}; }     ///< rmw_qos_profile_default
  static QosProfile SensorData() { return {false, 5, false}; }  ///< rmw_qos_profile_sensor_data
  static QosProfile Clock() { return {false, 1, false}; }       ///< rclcpp::ClockQoS
  /// Latched topics (/tf_static, /map): a late subscriber gets the last message.
  static QosProfile TransientLocal() { return {true, 1, true}; }
};

/// "/omni_base_controller/cmd_vel" -> "rt/omni_base_controller/cmd_vel" (ROS 2's topic prefix).
/// @throws InvalidArgument for a name that is not an absolute ROS 2 topic name.
std::string DdsTopicName(std::string_view ros_topic);

class DdsNode;

/// Writes messages of one type on one topic. Owned by the caller; outlived by its DdsNode.
template <class PubSubType>
class Publisher {
 public:
  using Message = typename PubSubType::type;
  /// @throws std::runtime_error if DDS refuses the sample (never for a well-formed message).
  void Publish(const Message& message) {
    if (!writer_->write(const_cast<Message*>(&message)))
      throw std::runtime_error("DDS write failed on " + topic_);
  }
  /// Readers currently matched (for tests and for waiting until a peer is there).
  int MatchedSubscriptions() const {
    eprosima::fastdds::dds::PublicationMatchedStatus status;
    writer_->get_publication_matched_status(status);
    return status.current_count;
  }
  const std::string& topic() const { return topic_; }
  ~Publisher();

 private:
  friend class DdsNode;
  Publisher(DdsNode* node, eprosima::fastdds::dds::DataWriter* writer, std::string topic)
      : node_(node), writer_(writer), topic_(std::move(topic)) {}
  DdsNode* node_;
  eprosima::fastdds::dds::DataWriter* writer_;
  std::string topic_;
};

/// Calls back for each message received on one topic.
template <class PubSubType>
class Subscription final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  using Message = typename PubSubType::type;
  using Callback = std::function<void(const Message&)>;
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&message_, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) callback_(message_);
    }
  }
  int MatchedPublications() const {
    eprosima::fastdds::dds::SubscriptionMatchedStatus status;
    reader_->get_subscription_matched_status(status);
    return status.current_count;
  }
  const std::string& topic() const { return topic_; }
  ~Subscription() override;

 private:
  friend class DdsNode;
  Subscription(DdsNode* node, std::string topic, Callback callback)
      : node_(node), topic_(std::move(topic)), callback_(std::move(callback)) {}
  DdsNode* node_;
  eprosima::fastdds::dds::DataReader* reader_{nullptr};
  std::string topic_;
  Callback callback_;
  Message message_;  // reused: only the listener thread touches it
};

/// One DDS participant (a "node"). Not copyable; create endpoints from one thread.
class DdsNode {
 public:
  /// `udp_only`: UDP (loopback included) without Fast DDS's shared-memory transport. Lock-step
  /// simulation needs it: under its bursts, Fast DDS 2.9's shared memory dropped samples, and a
  /// reliable reader then holds every later sample until the repair (a 3 s heartbeat away;
  /// 20 ms for this node's reliable writers).
  /// @throws std::runtime_error if the participant cannot be created (e.g. no network interface).
  explicit DdsNode(std::string_view name, int domain_id = 0, bool udp_only = false);
  ~DdsNode();
  DdsNode(const DdsNode&) = delete;
  DdsNode& operator=(const DdsNode&) = delete;

  template <class PubSubType>
  std::unique_ptr<Publisher<PubSubType>> CreatePublisher(std::string_view ros_topic,
                                                         const QosProfile& qos) {
    const std::string name = DdsTopicName(ros_topic);
    auto* writer = CreateWriter(name, std::make_unique<PubSubType>(), qos);
    return std::unique_ptr<Publisher<PubSubType>>(
        new Publisher<PubSubType>(this, writer, std::string(ros_topic)));
  }
  template <class PubSubType>
  std::unique_ptr<Subscription<PubSubType>> CreateSubscription(
      std::string_view ros_topic, const QosProfile& qos,
      typename Subscription<PubSubType>::Callback callback) {
    const std::string name = DdsTopicName(ros_topic);
    std::unique_ptr<Subscription<PubSubType>> subscription(
        new Subscription<PubSubType>(this, std::string(ros_topic), std::move(callback)));
    subscription->reader_ =
        CreateReader(name, std::make_unique<PubSubType>(), qos, subscription.get());
    return subscription;
  }

  const std::string& name() const { return name_; }

  // For Publisher/Subscription destructors.
  void DeleteWriter(eprosima::fastdds::dds::DataWriter* writer);
  void DeleteReader(eprosima::fastdds::dds::DataReader* reader);

 private:
  eprosima::fastdds::dds::DataWriter* CreateWriter(
      const std::string& topic, std::unique_ptr<eprosima::fastdds::dds::TopicDataType> type,
      const QosProfile& qos);
  eprosima::fastdds::dds::DataReader* CreateReader(
      const std::string& topic, std::unique_ptr<eprosima::fastdds::dds::TopicDataType> type,
      const QosProfile& qos, eprosima::fastdds::dds::DataReaderListener* listener);
  eprosima::fastdds::dds::Topic* TopicFor(
      const std::string& topic, std::unique_ptr<eprosima::fastdds::dds::TopicDataType> type);

  std::string name_;
  bool udp_only_{false};
  eprosima::fastdds::dds::DomainParticipant* participant_{nullptr};
  eprosima::fastdds::dds::Publisher* publisher_{nullptr};
  eprosima::fastdds::dds::Subscriber* subscriber_{nullptr};
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::mutex mutex_;
};

template <class PubSubType>
Publisher<PubSubType>::~Publisher() {
  node_->DeleteWriter(writer_);
}

template <class PubSubType>
Subscription<PubSubType>::~Subscription() {
  if (reader_ != nullptr) node_->DeleteReader(reader_);
}

}  // namespace egress::ros2
