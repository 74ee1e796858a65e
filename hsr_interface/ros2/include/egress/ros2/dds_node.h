#pragma once
/// @file
/// DdsNode: a Fast DDS participant that speaks as a ROS 2 node does on the wire: topic
/// `/a/b` is DDS topic `rt/a/b`, types carry ROS 2's DDS names (fastddsgen -typeros2), and the
/// QoS profiles are ROS 2's. Typed publishers and subscriptions over the generated types.
///
/// Services (and so actions' goals) as rmw_fastrtps lays them out: service `/a` is the topics
/// `rq/aRequest` and `rr/aReply`; a request carries its client's reply reader as its related
/// sample identity, and a reply carries the request's sample identity, by which a client tells
/// the replies to it from those to other clients.
///
/// Subscriptions call back on Fast DDS's own listener thread: keep callbacks short and
/// thread-safe (Ros2RobotPort copies the message under a mutex).

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include <fastdds/rtps/common/WriteParams.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
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
/// "/gripper_controller/grasp/_action/send_goal" -> the request and reply topics
/// {"rq/gripper_controller/grasp/_action/send_goalRequest", "rr/..._action/send_goalReply"}.
/// @throws InvalidArgument as DdsTopicName.
std::pair<std::string, std::string> DdsServiceTopicNames(std::string_view ros_service);
/// An action's goal service: "/a" -> "/a/_action/send_goal".
std::string ActionSendGoalService(std::string_view ros_action);

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

/// Calls a ROS 2 service (see the file comment for the wire protocol); replies call back on
/// Fast DDS's listener thread with the sequence number Call() returned.
template <class RequestType, class ReplyType>
class ServiceClient final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  using Request = typename RequestType::type;
  using Reply = typename ReplyType::type;
  using Callback = std::function<void(std::int64_t sequence, const Reply&)>;
  /// Sends `request`; returns its sequence number. @throws std::runtime_error if DDS refuses.
  std::int64_t Call(const Request& request) {
    eprosima::fastrtps::rtps::WriteParams params;
    params.related_sample_identity().writer_guid(reader_->guid());
    if (!writer_->write(const_cast<Request*>(&request), params))
      throw std::runtime_error("DDS write failed on the request of " + service_);
    return params.sample_identity().sequence_number().to64long();
  }
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&reply_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || info.related_sample_identity.writer_guid() != writer_->guid())
        continue;  // a reply to another client
      callback_(info.related_sample_identity.sequence_number().to64long(), reply_);
    }
  }
  /// Whether a server reads the requests and writes replies this client reads (a request sent
  /// before is lost: service topics are volatile, as in ROS 2).
  bool ServerMatched() const {
    eprosima::fastdds::dds::PublicationMatchedStatus out;
    eprosima::fastdds::dds::SubscriptionMatchedStatus in;
    writer_->get_publication_matched_status(out);
    reader_->get_subscription_matched_status(in);
    return out.current_count > 0 && in.current_count > 0;
  }
  /// Waits (wall time, bounded) until ServerMatched(); returns whether it is.
  bool WaitForServer(std::chrono::milliseconds timeout) const {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!ServerMatched()) {
      if (std::chrono::steady_clock::now() >= until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
  }
  const std::string& service() const { return service_; }
  ~ServiceClient() override;

 private:
  friend class DdsNode;
  ServiceClient(DdsNode* node, std::string service, Callback callback)
      : node_(node), service_(std::move(service)), callback_(std::move(callback)) {}
  DdsNode* node_;
  std::string service_;
  Callback callback_;
  eprosima::fastdds::dds::DataWriter* writer_{nullptr};
  eprosima::fastdds::dds::DataReader* reader_{nullptr};
  Reply reply_;  // reused: only the listener thread touches it
};

/// The readers a service's reply writer is matched with, and the replies held for a client
/// whose reply reader it has not matched yet (a reply written before that match would be lost;
/// rmw_fastrtps waits for it in the replying thread, but a reply written from a listener must
/// not block the thread that may deliver the match: it is held and sent on the match).
class ReplyGate final : public eprosima::fastdds::dds::DataWriterListener {
 public:
  void on_publication_matched(
      eprosima::fastdds::dds::DataWriter* writer,
      const eprosima::fastdds::dds::PublicationMatchedStatus& info) override;
  /// Runs `send` now if `reader` is matched (or unknown), else once it is. At most
  /// kMaxHeldReplies are held; the oldest is dropped past that.
  void SendWhenMatched(const eprosima::fastrtps::rtps::GUID_t& reader, std::function<void()> send);
  static constexpr std::size_t kMaxHeldReplies = 64;

 private:
  std::mutex mutex_;
  std::set<eprosima::fastrtps::rtps::GUID_t> readers_;
  std::vector<std::pair<eprosima::fastrtps::rtps::GUID_t, std::function<void()>>> held_;
};

/// Serves a ROS 2 service: `handler` answers each request, on Fast DDS's listener thread.
template <class RequestType, class ReplyType>
class ServiceServer final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  using Request = typename RequestType::type;
  using Reply = typename ReplyType::type;
  using Handler = std::function<Reply(const Request&)>;
  /// Whether a client writes requests here.
  bool ClientMatched() const {
    eprosima::fastdds::dds::SubscriptionMatchedStatus in;
    reader_->get_subscription_matched_status(in);
    return in.current_count > 0;
  }
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&request_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      auto reply = std::make_shared<Reply>(handler_(request_));
      const auto identity = info.sample_identity;
      gate_.SendWhenMatched(info.related_sample_identity.writer_guid(), [this, reply, identity] {
        eprosima::fastrtps::rtps::WriteParams params;
        params.related_sample_identity(identity);
        writer_->write(reply.get(), params);
      });
    }
  }
  ~ServiceServer() override;

 private:
  friend class DdsNode;
  ServiceServer(DdsNode* node, Handler handler) : node_(node), handler_(std::move(handler)) {}
  DdsNode* node_;
  Handler handler_;
  ReplyGate gate_;
  eprosima::fastdds::dds::DataWriter* writer_{nullptr};
  eprosima::fastdds::dds::DataReader* reader_{nullptr};
  Request request_;
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

  /// Services use ROS 2's services QoS (reliable, volatile, keep last 10).
  template <class RequestType, class ReplyType>
  std::unique_ptr<ServiceClient<RequestType, ReplyType>> CreateServiceClient(
      std::string_view ros_service,
      typename ServiceClient<RequestType, ReplyType>::Callback callback) {
    const auto [request, reply] = DdsServiceTopicNames(ros_service);
    std::unique_ptr<ServiceClient<RequestType, ReplyType>> client(
        new ServiceClient<RequestType, ReplyType>(this, std::string(ros_service),
                                                  std::move(callback)));
    client->writer_ = CreateWriter(request, std::make_unique<RequestType>(), QosProfile::Default());
    client->reader_ =
        CreateReader(reply, std::make_unique<ReplyType>(), QosProfile::Default(), client.get());
    return client;
  }
  template <class RequestType, class ReplyType>
  std::unique_ptr<ServiceServer<RequestType, ReplyType>> CreateServiceServer(
      std::string_view ros_service,
      typename ServiceServer<RequestType, ReplyType>::Handler handler) {
    const auto [request, reply] = DdsServiceTopicNames(ros_service);
    std::unique_ptr<ServiceServer<RequestType, ReplyType>> server(
        new ServiceServer<RequestType, ReplyType>(this, std::move(handler)));
    server->writer_ =
        CreateWriter(reply, std::make_unique<ReplyType>(), QosProfile::Default(), &server->gate_);
    server->reader_ =
        CreateReader(request, std::make_unique<RequestType>(), QosProfile::Default(), server.get());
    return server;
  }

  const std::string& name() const { return name_; }

  // For Publisher/Subscription destructors.
  void DeleteWriter(eprosima::fastdds::dds::DataWriter* writer);
  void DeleteReader(eprosima::fastdds::dds::DataReader* reader);

 private:
  eprosima::fastdds::dds::DataWriter* CreateWriter(
      const std::string& topic, std::unique_ptr<eprosima::fastdds::dds::TopicDataType> type,
      const QosProfile& qos, eprosima::fastdds::dds::DataWriterListener* listener = nullptr);
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

template <class RequestType, class ReplyType>
ServiceClient<RequestType, ReplyType>::~ServiceClient() {
  if (reader_ != nullptr) node_->DeleteReader(reader_);
  if (writer_ != nullptr) node_->DeleteWriter(writer_);
}

template <class RequestType, class ReplyType>
ServiceServer<RequestType, ReplyType>::~ServiceServer() {
  if (writer_ != nullptr) writer_->set_listener(nullptr);  // no held reply sent from here on
  if (reader_ != nullptr) node_->DeleteReader(reader_);
  if (writer_ != nullptr) node_->DeleteWriter(writer_);
}

}  // namespace egress::ros2
