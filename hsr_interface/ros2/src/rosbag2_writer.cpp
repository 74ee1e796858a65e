#include "egress/ros2/rosbag2_writer.h"

#include <fstream>
#include <sstream>

#include <sqlite3.h>

#include "egress/hsr_interface/error.h"

namespace egress::ros2 {
namespace {

void Exec(sqlite3* db, const char* sql, const std::filesystem::path& file) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string what = error != nullptr ? error : "unknown error";
    sqlite3_free(error);
    throw std::runtime_error("rosbag2 '" + file.string() + "': " + what);
  }
}

// The offered QoS as rosbag2 (Humble) writes it: the rmw enums (history keep last = 1,
// reliability reliable = 1 / best effort = 2, durability transient local = 1 / volatile = 2),
// infinite deadline and lifespan, automatic liveliness.
std::string QosYaml(const QosProfile& q) {
  std::ostringstream s;
  s << "- history: 1\n  depth: " << q.depth << "\n  reliability: " << (q.reliable ? 1 : 2)
    << "\n  durability: " << (q.transient_local ? 1 : 2)
    << "\n  deadline:\n    sec: 2147483647\n    nsec: 4294967295\n  lifespan:\n    sec: "
       "2147483647\n    nsec: 4294967295\n  liveliness: 1\n  liveliness_lease_duration:\n    "
       "sec: 2147483647\n    nsec: 4294967295\n  avoid_ros_namespace_conventions: false";
  return s.str();
}

std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string Rosbag2Writer::RosTypeName(std::string_view dds) {
  std::string name(dds);
  const auto at = name.find("::msg::dds_::");
  ThrowUnless(at != std::string::npos && name.size() > at + 13 && name.back() == '_', "rosbag2: '",
              dds, "' is not a ROS 2 DDS type name (pkg::msg::dds_::Type_)");
  return name.substr(0, at) + "/msg/" + name.substr(at + 13, name.size() - at - 14);
}

Rosbag2Writer::Rosbag2Writer(const std::filesystem::path& dir) : dir_(dir) {
  ThrowUnless(!dir.empty() && !std::filesystem::exists(dir), "rosbag2: '", dir.string(),
              "' already exists (a bag is never overwritten; remove it or pick another name)");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  ThrowUnless(!ec, "rosbag2: cannot create '", dir.string(), "': ", ec.message());
  file_name_ = dir.filename().string() + "_0.db3";
  const std::filesystem::path file = dir / file_name_;
  if (sqlite3_open(file.c_str(), &db_) != SQLITE_OK) {
    const std::string what = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error("rosbag2 '" + file.string() + "': " + what);
  }
  // rosbag2's sqlite3 storage (Humble): schema version 3.
  Exec(db_,
       "PRAGMA journal_mode=MEMORY; PRAGMA synchronous=OFF;"
       "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
       "INSERT INTO schema VALUES (3, 'humble');"
       "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
       " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
       "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,"
       " timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
       "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
       "BEGIN TRANSACTION;",
       file);
  if (sqlite3_prepare_v2(db_, "INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)",
                         -1, &insert_, nullptr) != SQLITE_OK)
    throw std::runtime_error("rosbag2 '" + file.string() + "': " + sqlite3_errmsg(db_));
}

Rosbag2Writer::~Rosbag2Writer() {
  try {
    Close();
  } catch (...) {
  }
}

void Rosbag2Writer::WriteSerialized(std::string_view topic, std::string_view dds_type,
                                    const QosProfile& qos, Time t, const unsigned char* data,
                                    std::size_t size) {
  ThrowUnless(db_ != nullptr, "rosbag2 '", dir_.string(), "': already closed");
  DdsTopicName(topic);  // a valid ROS 2 name
  auto it = topics_.find(std::string(topic));
  if (it == topics_.end()) {
    Topic entry{int(topics_.size()) + 1, RosTypeName(dds_type), QosYaml(qos)};
    sqlite3_stmt* add = nullptr;
    sqlite3_prepare_v2(db_,
                       "INSERT INTO topics (id, name, type, serialization_format, "
                       "offered_qos_profiles) VALUES (?, ?, ?, 'cdr', ?)",
                       -1, &add, nullptr);
    sqlite3_bind_int(add, 1, entry.id);
    sqlite3_bind_text(add, 2, std::string(topic).c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(add, 3, entry.type.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(add, 4, entry.qos_yaml.c_str(), -1, SQLITE_TRANSIENT);
    const int rc = sqlite3_step(add);
    sqlite3_finalize(add);
    if (rc != SQLITE_DONE)
      throw std::runtime_error("rosbag2 '" + dir_.string() + "': " + sqlite3_errmsg(db_));
    it = topics_.emplace(std::string(topic), std::move(entry)).first;
  } else {
    ThrowUnless(it->second.type == RosTypeName(dds_type), "rosbag2: topic '", topic,
                "' is recorded as ", it->second.type, ", not ", RosTypeName(dds_type));
  }
  sqlite3_reset(insert_);
  sqlite3_bind_int64(insert_, 1, t.count());
  sqlite3_bind_int(insert_, 2, it->second.id);
  sqlite3_bind_blob(insert_, 3, data, int(size), SQLITE_TRANSIENT);
  if (sqlite3_step(insert_) != SQLITE_DONE)
    throw std::runtime_error("rosbag2 '" + dir_.string() + "': " + sqlite3_errmsg(db_));
  ++it->second.count;
  ++message_count_;
  first_ = std::min(first_, t);
  last_ = std::max(last_, t);
}

void Rosbag2Writer::Close() {
  if (db_ == nullptr) return;
  sqlite3_finalize(insert_);
  insert_ = nullptr;
  Exec(db_, "COMMIT;", dir_ / file_name_);
  sqlite3_close(db_);
  db_ = nullptr;
  const std::int64_t start = message_count_ > 0 ? first_.count() : 0;
  const std::int64_t duration = message_count_ > 0 ? (last_ - first_).count() : 0;
  std::ofstream out(dir_ / "metadata.yaml");
  out << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
      << "  duration:\n    nanoseconds: " << duration << "\n"
      << "  starting_time:\n    nanoseconds_since_epoch: " << start << "\n"
      << "  message_count: " << message_count_ << "\n  topics_with_message_count:\n";
  for (const auto& [name, topic] : topics_) {
    out << "    - topic_metadata:\n        name: " << name << "\n        type: " << topic.type
        << "\n        serialization_format: cdr\n        offered_qos_profiles: "
        << Quoted(topic.qos_yaml) << "\n      message_count: " << topic.count << "\n";
  }
  out << "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - "
      << file_name_ << "\n  files:\n    - path: " << file_name_
      << "\n      starting_time:\n        nanoseconds_since_epoch: " << start
      << "\n      duration:\n        nanoseconds: " << duration
      << "\n      message_count: " << message_count_ << "\n";
  if (!out) throw std::runtime_error("rosbag2: cannot write " + (dir_ / "metadata.yaml").string());
}

}  // namespace egress::ros2
