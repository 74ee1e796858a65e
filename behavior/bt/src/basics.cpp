// NodeStatus names, type names and the built-in string conversions.

#include <cxxabi.h>

#include <cstdlib>
#include <memory>

#include "egress/bt/any.h"
#include "egress/bt/ports.h"
#include "egress/bt/status.h"

namespace egress::bt {

std::string_view ToString(NodeStatus status) {
  switch (status) {
    case NodeStatus::kIdle:
      return "IDLE";
    case NodeStatus::kRunning:
      return "RUNNING";
    case NodeStatus::kSuccess:
      return "SUCCESS";
    case NodeStatus::kFailure:
      return "FAILURE";
    case NodeStatus::kSkipped:
      return "SKIPPED";
  }
  return "UNKNOWN";
}

std::optional<NodeStatus> ParseNodeStatus(std::string_view text) {
  for (NodeStatus s : {NodeStatus::kIdle, NodeStatus::kRunning, NodeStatus::kSuccess,
                       NodeStatus::kFailure, NodeStatus::kSkipped}) {
    if (text == ToString(s)) return s;
  }
  return std::nullopt;
}

std::string_view ToString(PortDirection direction) {
  switch (direction) {
    case PortDirection::kInput:
      return "input";
    case PortDirection::kOutput:
      return "output";
    case PortDirection::kInOut:
      return "inout";
  }
  return "unknown";
}

std::string TypeName(const std::type_info& type) {
  if (type == typeid(std::string)) return "std::string";
  if (type == typeid(std::int64_t)) return "int64_t";
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> name(
      abi::__cxa_demangle(type.name(), nullptr, nullptr, &status), std::free);
  return status == 0 && name ? std::string(name.get()) : std::string(type.name());
}

void TypeRegistry::Register(std::type_index type, std::string name, Converter converter) {
  converters_[type] = {std::move(name), std::move(converter)};
}

const TypeRegistry::Converter* TypeRegistry::Find(std::type_index type) const {
  auto it = converters_.find(type);
  return it == converters_.end() ? nullptr : &it->second.second;
}

namespace {
std::string_view Trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  return text;
}
}  // namespace

std::int64_t ParseInteger(std::string_view text) {
  const std::string_view t = Trim(text);
  std::int64_t value = 0;
  const char* begin = t.data();
  const char* end = t.data() + t.size();
  if (!t.empty() && *begin == '+') ++begin;
  auto [ptr, error] = std::from_chars(begin, end, value);
  if (error != std::errc() || ptr != end || t.empty()) {
    throw RuntimeError(Cat("'", text, "' is not an integer"));
  }
  return value;
}

double ParseReal(std::string_view text) {
  const std::string_view t = Trim(text);
  const std::string copy(t);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size()) {
    throw RuntimeError(Cat("'", text, "' is not a number"));
  }
  return value;
}

bool StringConverter<bool>::Convert(std::string_view text) {
  const std::string_view t = Trim(text);
  if (t == "1" || t == "true" || t == "TRUE" || t == "True") return true;
  if (t == "0" || t == "false" || t == "FALSE" || t == "False") return false;
  throw RuntimeError(Cat("'", text, "' is not a bool (true/false/1/0)"));
}

NodeStatus StringConverter<NodeStatus>::Convert(std::string_view text) {
  if (auto status = ParseNodeStatus(Trim(text))) return *status;
  throw RuntimeError(
      Cat("'", text, "' is not a NodeStatus (IDLE, RUNNING, SUCCESS, FAILURE, SKIPPED)"));
}

std::vector<std::string_view> SplitSemicolons(std::string_view text) {
  std::vector<std::string_view> parts;
  while (!text.empty()) {
    const std::size_t end = text.find(';');
    parts.push_back(Trim(text.substr(0, end)));
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return parts;
}

double Any::AsDouble() const {
  if (const auto* d = Peek<double>()) return *d;
  if (const auto* i = Peek<std::int64_t>()) return double(*i);
  if (const auto* b = Peek<bool>()) return *b ? 1.0 : 0.0;
  return 0.0;
}

void Any::ThrowMismatch(const std::type_info& wanted) const {
  throw RuntimeError(Cat("cannot convert a value of type ",
                         TypeName(enum_type_ != nullptr ? *enum_type_ : type()), " to ",
                         TypeName(wanted)));
}

std::string Any::ToString() const {
  if (empty()) return "";
  if (const auto* s = Peek<std::string>()) return *s;
  if (const auto* b = Peek<bool>()) return *b ? "true" : "false";
  if (const auto* i = Peek<std::int64_t>()) return std::to_string(*i);
  if (const auto* d = Peek<double>()) {
    std::ostringstream out;
    out.precision(15);
    out << *d;
    return out.str();
  }
  std::string text = "<";  // built up stepwise: GCC 12 warns falsely on "<" + string
  text += TypeName(type());
  text += '>';
  return text;
}

std::optional<std::string> BlackboardKeyOf(std::string_view text, std::string_view port_name) {
  const std::string_view t = Trim(text);
  if (t == "=") return std::string(port_name);
  if (t.size() >= 2 && t.front() == '{' && t.back() == '}') {
    const std::string_view key = Trim(t.substr(1, t.size() - 2));
    if (key == "=") return std::string(port_name);
    return std::string(key);
  }
  return std::nullopt;
}

}  // namespace egress::bt
