#pragma once
/// @file
/// Any: a blackboard or port value, and the string conversions of BehaviorTree.CPP v4.
///
/// Numbers are normalized when stored (every integer type becomes int64_t, every floating type
/// double) so that a value written as an int can be read as a double or a long; a read
/// converts between numeric types when the value fits exactly. Strings convert to any type
/// that has a converter: the built-in ones (numbers, bool, NodeStatus, `;`-separated vectors)
/// or ones registered with a TypeRegistry for user types.

#include <any>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <typeindex>
#include <vector>

#include "egress/bt/errors.h"
#include "egress/bt/status.h"

namespace egress::bt {

/// Human-readable name of a C++ type ("int", "double", "std::string", "MyPose").
std::string TypeName(const std::type_info& type);

/// Runtime converters from string for user types, registered by the application.
class TypeRegistry {
 public:
  using Converter = std::function<std::any(std::string_view)>;
  void Register(std::type_index type, std::string name, Converter converter);
  const Converter* Find(std::type_index type) const;

 private:
  std::map<std::type_index, std::pair<std::string, Converter>> converters_;
};

/// Built-in conversions from text. Specialize for your own type, or register a converter with
/// BehaviorTreeFactory::RegisterConverter<T>().
template <typename T, typename Enable = void>
struct StringConverter {
  static constexpr bool kAvailable = false;
};

template <>
struct StringConverter<std::string> {
  static constexpr bool kAvailable = true;
  static std::string Convert(std::string_view text) { return std::string(text); }
};

template <>
struct StringConverter<bool> {
  static constexpr bool kAvailable = true;
  static bool Convert(std::string_view text);
};

template <>
struct StringConverter<NodeStatus> {
  static constexpr bool kAvailable = true;
  static NodeStatus Convert(std::string_view text);
};

/// Parses a whole string as a number; throws RuntimeError on trailing text or overflow.
std::int64_t ParseInteger(std::string_view text);
double ParseReal(std::string_view text);

template <typename T>
struct StringConverter<T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>>> {
  static constexpr bool kAvailable = true;
  static T Convert(std::string_view text) {
    const std::int64_t value = ParseInteger(text);
    if (value < std::int64_t(std::numeric_limits<T>::min()) ||
        (value > 0 && std::uint64_t(value) > std::uint64_t(std::numeric_limits<T>::max()))) {
      throw RuntimeError(Cat("'", text, "' is out of range for ", TypeName(typeid(T))));
    }
    return static_cast<T>(value);
  }
};

template <typename T>
struct StringConverter<T, std::enable_if_t<std::is_floating_point_v<T>>> {
  static constexpr bool kAvailable = true;
  static T Convert(std::string_view text) { return static_cast<T>(ParseReal(text)); }
};

/// Splits on ';' (BehaviorTree.CPP's vector convention).
std::vector<std::string_view> SplitSemicolons(std::string_view text);

template <typename T>
struct StringConverter<std::vector<T>, std::enable_if_t<StringConverter<T>::kAvailable>> {
  static constexpr bool kAvailable = true;
  static std::vector<T> Convert(std::string_view text) {
    std::vector<T> out;
    for (std::string_view part : SplitSemicolons(text))
      out.push_back(StringConverter<T>::Convert(part));
    return out;
  }
};

/// A queue a Loop node pops from in place (BehaviorTree.CPP 4's SharedQueue): a node that
/// writes one to the blackboard sees it shrink as the loop runs.
template <typename T>
using SharedQueue = std::shared_ptr<std::deque<T>>;

template <typename T>
struct StringConverter<SharedQueue<T>, std::enable_if_t<StringConverter<T>::kAvailable>> {
  static constexpr bool kAvailable = true;
  static SharedQueue<T> Convert(std::string_view text) {
    auto out = std::make_shared<std::deque<T>>();
    if (text.empty()) return out;
    for (std::string_view part : SplitSemicolons(text))
      out->push_back(StringConverter<T>::Convert(part));
    return out;
  }
};

/// Converts text to T with the built-in converters, else the registry's.
/// @throws RuntimeError if no converter exists or the text does not parse.
template <typename T>
T ConvertFromString(std::string_view text, const TypeRegistry* registry) {
  if constexpr (StringConverter<T>::kAvailable) {
    return StringConverter<T>::Convert(text);
  } else {
    if (registry != nullptr) {
      if (const auto* converter = registry->Find(typeid(T)))
        return std::any_cast<T>((*converter)(text));
    }
    throw RuntimeError(Cat("no converter from string to ", TypeName(typeid(T)),
                           "; register one with BehaviorTreeFactory::RegisterConverter"));
  }
}

/// A type-erased value with BehaviorTree.CPP's conversion rules.
class Any {
 public:
  Any() = default;
  template <typename T, typename D = std::decay_t<T>,
            typename = std::enable_if_t<!std::is_same_v<D, Any> && !std::is_same_v<D, std::any>>>
  Any(T&& value) {  // NOLINT(google-explicit-constructor): values convert implicitly, as in BT.CPP
    if constexpr (std::is_same_v<D, bool>) {
      value_ = bool(value);
    } else if constexpr (std::is_integral_v<D>) {
      value_ = static_cast<std::int64_t>(value);
    } else if constexpr (std::is_floating_point_v<D>) {
      value_ = static_cast<double>(value);
    } else if constexpr (std::is_convertible_v<D, std::string_view>) {
      value_ = std::string(std::string_view(value));
    } else if constexpr (std::is_enum_v<D>) {
      value_ = static_cast<std::int64_t>(value);
      enum_type_ = &typeid(D);
    } else {
      value_ = std::forward<T>(value);
    }
  }

  bool empty() const { return !value_.has_value(); }
  const std::type_info& type() const { return value_.type(); }
  bool IsNumber() const { return IsType<std::int64_t>() || IsType<double>() || IsType<bool>(); }
  bool IsString() const { return IsType<std::string>(); }
  template <typename T>
  bool IsType() const {
    return value_.type() == typeid(T);
  }
  /// The stored value if it is exactly a T (after normalization), else nullptr.
  template <typename T>
  const T* Peek() const {
    return std::any_cast<T>(&value_);
  }

  /// Reads the value as T, converting numbers and strings as documented above.
  /// @throws RuntimeError naming both types when no conversion applies.
  template <typename T>
  T Cast(const TypeRegistry* registry = nullptr) const;

  /// A printable form ("3", "0.5", "text", "<MyPose>").
  std::string ToString() const;

 private:
  [[noreturn]] void ThrowMismatch(const std::type_info& wanted) const;
  double AsDouble() const;

  std::any value_;
  const std::type_info* enum_type_{nullptr};
};

template <typename T>
T Any::Cast(const TypeRegistry* registry) const {
  using D = std::decay_t<T>;
  if (empty()) throw RuntimeError(Cat("value is empty; expected ", TypeName(typeid(D))));
  if constexpr (std::is_same_v<D, Any>) {
    return *this;
  } else if constexpr (std::is_same_v<D, std::string>) {
    if (const auto* s = Peek<std::string>()) return *s;
    if (IsNumber()) return ToString();
    ThrowMismatch(typeid(D));
  } else if constexpr (std::is_arithmetic_v<D> || std::is_enum_v<D>) {
    if constexpr (std::is_same_v<D, bool>) {
      if (const auto* b = Peek<bool>()) return *b;
    }
    if (IsNumber()) {
      const double v = AsDouble();
      if constexpr (std::is_same_v<D, bool>) {
        if (v == 0.0 || v == 1.0) return v == 1.0;
        throw RuntimeError(Cat("value ", ToString(), " is not a bool (0 or 1)"));
      } else if constexpr (std::is_floating_point_v<D>) {
        return static_cast<D>(v);
      } else {
        if (const auto* i = Peek<std::int64_t>()) {
          using Limits =
              std::numeric_limits<std::conditional_t<std::is_enum_v<D>, std::int64_t, D>>;
          if (*i < std::int64_t(Limits::min()) ||
              (*i > 0 && std::uint64_t(*i) > std::uint64_t(Limits::max()))) {
            throw RuntimeError(Cat("value ", *i, " is out of range for ", TypeName(typeid(D))));
          }
          return static_cast<D>(*i);
        }
        if (std::trunc(v) != v || std::abs(v) > 9.007199254740992e15) {
          throw RuntimeError(
              Cat("value ", ToString(), " is not an integer; expected ", TypeName(typeid(D))));
        }
        return static_cast<D>(static_cast<std::int64_t>(v));
      }
    }
    if (const auto* s = Peek<std::string>()) {
      if constexpr (std::is_enum_v<D>) {
        if constexpr (StringConverter<D>::kAvailable) return StringConverter<D>::Convert(*s);
        return static_cast<D>(ParseInteger(*s));
      } else {
        return ConvertFromString<D>(*s, registry);
      }
    }
    ThrowMismatch(typeid(D));
  } else {
    if (const auto* v = Peek<D>()) return *v;
    if (const auto* s = Peek<std::string>()) return ConvertFromString<D>(*s, registry);
    ThrowMismatch(typeid(D));
  }
}

}  // namespace egress::bt
