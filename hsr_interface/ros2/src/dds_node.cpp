#include "egress/ros2/dds_node.h"

#include <cctype>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

namespace egress::ros2 {

namespace dds = eprosima::fastdds::dds;

std::string DdsTopicName(std::string_view ros_topic) {
  ThrowUnless(ros_topic.size() > 1 && ros_topic.front() == '/' && ros_topic.back() != '/',
              "ROS 2 topic '", ros_topic, "' must be an absolute name (/a/b), not empty");
  for (std::size_t i = 0; i < ros_topic.size(); ++i) {
    const char c = ros_topic[i];
    ThrowUnless(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/',
                "ROS 2 topic '", ros_topic, "': character '", c, "' is not allowed");
    ThrowUnless(!(c == '/' && i + 1 < ros_topic.size() && ros_topic[i + 1] == '/'), "ROS 2 topic '",
                ros_topic, "' has an empty level (//)");
  }
  return "rt" + std::string(ros_topic);
}

std::pair<std::string, std::string> DdsServiceTopicNames(std::string_view ros_service) {
  const std::string path = DdsTopicName(ros_service).substr(2);  // validated, "/a/b"
  return {"rq" + path + "Request", "rr" + path + "Reply"};
}

std::string ActionSendGoalService(std::string_view ros_action) {
  return std::string(ros_action) + "/_action/send_goal";
}

void ReplyGate::on_publication_matched(dds::DataWriter*,
                                       const dds::PublicationMatchedStatus& info) {
  const auto reader = eprosima::fastrtps::rtps::iHandle2GUID(info.last_subscription_handle);
  std::vector<std::function<void()>> ready;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (info.current_count_change > 0) {
      readers_.insert(reader);
      for (auto it = held_.begin(); it != held_.end();) {
        if (it->first == reader) {
          ready.push_back(std::move(it->second));
          it = held_.erase(it);
        } else {
          ++it;
        }
      }
    } else if (info.current_count_change < 0) {
      readers_.erase(reader);
    }
  }
  for (auto& send : ready)
    send();
}

void ReplyGate::SendWhenMatched(const eprosima::fastrtps::rtps::GUID_t& reader,
                                std::function<void()> send) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (reader != eprosima::fastrtps::rtps::GUID_t::unknown() && readers_.count(reader) == 0) {
      if (held_.size() >= kMaxHeldReplies) held_.erase(held_.begin());
      held_.emplace_back(reader, std::move(send));
      return;
    }
  }
  send();
}

namespace {
template <class Qos>
void Apply(const QosProfile& profile, Qos* qos) {
  qos->reliability().kind =
      profile.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos->durability().kind =
      profile.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  qos->history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos->history().depth = profile.depth;
  // Messages with unbounded sequences (scans, images): grow buffers as needed, as rmw does.
  qos->endpoint().history_memory_policy =
      eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
}
}  // namespace

DdsNode::DdsNode(std::string_view name, int domain_id, bool udp_only)
    : name_(name), udp_only_(udp_only) {
  ThrowUnless(domain_id >= 0 && domain_id <= 232, "DDS domain id ", domain_id,
              " must be in [0, 232] (ROS_DOMAIN_ID)");
  dds::DomainParticipantQos qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos.name(name_);
  if (udp_only) {
    qos.transport().use_builtin_transports = false;
    qos.transport().user_transports.push_back(
        std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
  }
  participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(domain_id, qos);
  if (participant_ == nullptr)
    throw std::runtime_error("DDS: cannot create participant '" + name_ + "' on domain " +
                             std::to_string(domain_id));
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr)
    throw std::runtime_error("DDS: cannot create the publisher/subscriber of '" + name_ + "'");
}

DdsNode::~DdsNode() {
  if (participant_ == nullptr) return;
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

dds::Topic* DdsNode::TopicFor(const std::string& topic,
                              std::unique_ptr<dds::TopicDataType> type_ptr) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::string type_name = type_ptr->getName();
  if (auto it = topics_.find(topic); it != topics_.end()) {
    ThrowUnless(it->second->get_type_name() == type_name, "ROS 2 topic '", topic.substr(2),
                "' is already used with type ", it->second->get_type_name(), ", not ", type_name);
    return it->second;
  }
  if (participant_->find_type(type_name).empty()) {
    dds::TypeSupport type(type_ptr.release());
    if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK)
      throw std::runtime_error("DDS: cannot register type " + type_name);
  }
  dds::Topic* t = participant_->create_topic(topic, type_name, dds::TOPIC_QOS_DEFAULT);
  if (t == nullptr) throw std::runtime_error("DDS: cannot create topic " + topic);
  topics_[topic] = t;
  return t;
}

dds::DataWriter* DdsNode::CreateWriter(const std::string& topic,
                                       std::unique_ptr<dds::TopicDataType> type,
                                       const QosProfile& profile,
                                       dds::DataWriterListener* listener) {
  dds::Topic* t = TopicFor(topic, std::move(type));
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  Apply(profile, &qos);
  // Lock-step: a lost sample is repaired within 20 ms, not Fast DDS's default 3 s heartbeat
  // (a reliable reader holds every later sample until then).
  if (udp_only_) qos.reliable_writer_qos().times.heartbeatPeriod = {0, 20'000'000};
  dds::DataWriter* writer = publisher_->create_datawriter(t, qos, listener);
  if (writer == nullptr) throw std::runtime_error("DDS: cannot create a writer on " + topic);
  return writer;
}

dds::DataReader* DdsNode::CreateReader(const std::string& topic,
                                       std::unique_ptr<dds::TopicDataType> type,
                                       const QosProfile& profile,
                                       dds::DataReaderListener* listener) {
  dds::Topic* t = TopicFor(topic, std::move(type));
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  Apply(profile, &qos);
  dds::DataReader* reader = subscriber_->create_datareader(t, qos, listener);
  if (reader == nullptr) throw std::runtime_error("DDS: cannot create a reader on " + topic);
  return reader;
}

void DdsNode::DeleteWriter(dds::DataWriter* writer) {
  publisher_->delete_datawriter(writer);
}

void DdsNode::DeleteReader(dds::DataReader* reader) {
  reader->set_listener(nullptr);  // no callback into a subscription being destroyed
  subscriber_->delete_datareader(reader);
}

}  // namespace egress::ros2
