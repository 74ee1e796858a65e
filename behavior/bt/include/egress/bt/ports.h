#pragma once
/// @file
/// Port declarations. Each node type declares its ports (name, direction, C++ type, default,
/// description) in a static `ProvidedPorts()`; the XML loader checks a tree against them.

#include <charconv>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <typeindex>
#include <utility>

#include "egress/bt/any.h"

namespace egress::bt {

enum class PortDirection { kInput, kOutput, kInOut };

std::string_view ToString(PortDirection direction);

struct PortInfo {
  PortDirection direction{PortDirection::kInput};
  /// The port's C++ type; nullopt means "any" (a stand-in node's port, or Any).
  std::optional<std::type_index> type;
  std::string type_name;
  /// Used when the XML does not set the port: a literal, "{key}" or "{=}".
  std::optional<std::string> default_value;
  std::string description;
  /// Converts a literal to the port's type (checked at load time); null for types without a
  /// compile-time converter (the factory's TypeRegistry is tried instead).
  std::function<Any(std::string_view, const TypeRegistry*)> parse;
  /// An input port without a default must be set in the XML (checked at load time).
  bool required{false};
  /// The port holds a script (Script's `code`, Precondition's `if`): a literal is parsed at
  /// load time so that syntax errors surface before the first tick.
  bool script{false};

  /// True for a concrete type other than std::string or Any: literals are checked at load
  /// time and blackboard keys get this type.
  bool IsStronglyTyped() const {
    return type && *type != typeid(std::string) && *type != typeid(Any);
  }
};

using PortsList = std::map<std::string, PortInfo, std::less<>>;

namespace internal {

template <typename T>
PortInfo MakePort(PortDirection direction, std::string description) {
  PortInfo info;
  info.direction = direction;
  if constexpr (!std::is_same_v<T, Any>) {
    info.type = std::type_index(typeid(T));
    info.type_name = TypeName(typeid(T));
  } else {
    info.type_name = "Any";
  }
  info.description = std::move(description);
  info.parse = [](std::string_view text, const TypeRegistry* registry) -> Any {
    if constexpr (std::is_same_v<T, Any>) {
      return Any(std::string(text));
    } else if constexpr (std::is_enum_v<T> && !StringConverter<T>::kAvailable) {
      return Any(static_cast<T>(ParseInteger(text)));
    } else {
      return Any(ConvertFromString<T>(text, registry));
    }
  };
  return info;
}

template <typename T>
std::string DefaultToText(const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    return value ? "true" : "false";
  } else if constexpr (std::is_convertible_v<T, std::string_view>) {
    return std::string(std::string_view(value));
  } else if constexpr (std::is_same_v<T, NodeStatus>) {
    return std::string(ToString(value));
  } else if constexpr (std::is_floating_point_v<T>) {
    char buffer[32];  // shortest text that reads back to the same value: "0.004", not 0.00400…1
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
  } else {
    std::ostringstream out;
    out.precision(17);
    out << value;
    return out.str();
  }
}

}  // namespace internal

/// An input port with no default: the XML must set it.
template <typename T = Any>
std::pair<std::string, PortInfo> InputPort(std::string name, std::string description = {}) {
  PortInfo info = internal::MakePort<T>(PortDirection::kInput, std::move(description));
  info.required = true;
  return {std::move(name), std::move(info)};
}

/// An input port with a default value (a literal of T, or a "{key}" text).
template <typename T = Any, typename D>
std::pair<std::string, PortInfo> InputPort(std::string name, const D& default_value,
                                           std::string description) {
  PortInfo info = internal::MakePort<T>(PortDirection::kInput, std::move(description));
  info.default_value = internal::DefaultToText(default_value);
  return {std::move(name), std::move(info)};
}

/// An output port; its value must be a blackboard reference. `default_key` like "{result}".
template <typename T = Any>
std::pair<std::string, PortInfo> OutputPort(std::string name, std::string description = {},
                                            std::optional<std::string> default_key = {}) {
  PortInfo info = internal::MakePort<T>(PortDirection::kOutput, std::move(description));
  info.default_value = std::move(default_key);
  return {std::move(name), std::move(info)};
}

/// A port read and written by the node; like an input port it must be set unless defaulted.
template <typename T = Any>
std::pair<std::string, PortInfo> BidirectionalPort(std::string name, std::string description = {},
                                                   std::optional<std::string> default_key = {}) {
  PortInfo info = internal::MakePort<T>(PortDirection::kInOut, std::move(description));
  info.default_value = std::move(default_key);
  info.required = !info.default_value.has_value();
  return {std::move(name), std::move(info)};
}

/// If `text` references the blackboard ("{key}", "{@key}", "{=}" or "="), the key ("=" and
/// "{=}" name the port itself); nullopt for a literal.
std::optional<std::string> BlackboardKeyOf(std::string_view text, std::string_view port_name);

}  // namespace egress::bt
