#pragma once
// Internal to twin/src: FieldReader, the scenario parser's typed access to YAML nodes. Every
// error names the file, the line and the field ("file:line: field 'a.b[2].c': what is wrong").

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <string>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/twin/scenario.h"

namespace egress::twin {

// Reads YAML nodes with errors of the form "file:line: field 'a.b[2].c': what is wrong".
class FieldReader {
 public:
  explicit FieldReader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& field,
                         const std::string& message) const {
    // StrCat, not "literal" + std::string: GCC 12 warns falsely (-Wrestrict) on that.
    const std::string what =
        field.empty() ? StrCat("top level: ", message) : StrCat("field '", field, "': ", message);
    if (node.IsDefined() && node.Mark().line >= 0)
      throw LoadError(StrCat(source_, ":", node.Mark().line + 1, ": ", what));
    throw LoadError(StrCat(source_, ": ", what));
  }

  // Runs `read`, naming by line any error yaml-cpp lets out of it (a subscript on a scalar, a
  // bad conversion): none may escape as yaml-cpp's own exception and abort a program.
  template <class F>
  auto Guard(F read) const -> decltype(read()) {
    try {
      return read();
    } catch (const YAML::Exception& e) {
      if (e.mark.is_null()) throw LoadError(StrCat(source_, ": ", e.msg));
      throw LoadError(StrCat(source_, ":", e.mark.line + 1, ": ", e.msg));
    }
  }

  // Refuses keys outside `allowed`, so a typo never becomes a silent default.
  void CheckKeys(const YAML::Node& map, const std::string& field,
                 const std::set<std::string>& allowed) const {
    if (!map.IsMap()) Fail(map, field, "expected a mapping");
    for (const auto& kv : map) {
      const std::string key = Key(kv.first, field);
      if (allowed.count(key) == 0) {
        std::string list;
        for (const auto& a : allowed)
          list += (list.empty() ? "" : ", ") + a;
        Fail(kv.first, Join(field, key), "unknown field (expected one of: " + list + ")");
      }
    }
  }

  // A mapping's key as a name. A complex key (`? [a, b]`) is no name: said by line, not
  // yaml-cpp's raw "bad conversion".
  std::string Key(const YAML::Node& key, const std::string& field) const {
    if (!key.IsScalar()) Fail(key, field, "a key must be a plain name");
    return key.Scalar();
  }

  static std::string Join(const std::string& parent, const std::string& key) {
    return parent.empty() ? key : parent + "." + key;
  }

  double Number(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) Fail(node, field, "expected a number");
    double value = 0.0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      Fail(node, field, "'" + node.Scalar() + "' is not a number");
    }
    if (!std::isfinite(value)) Fail(node, field, "must be finite");
    return value;
  }

  double Positive(const YAML::Node& node, const std::string& field) const {
    const double v = Number(node, field);
    if (!(v > 0.0)) Fail(node, field, "must be positive");
    return v;
  }

  double NonNegative(const YAML::Node& node, const std::string& field) const {
    const double v = Number(node, field);
    if (v < 0.0) Fail(node, field, "must not be negative");
    return v;
  }

  double Fraction(const YAML::Node& node, const std::string& field) const {
    const double v = Number(node, field);
    if (v < 0.0 || v > 1.0) Fail(node, field, "must be in [0, 1]");
    return v;
  }

  std::string String(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar() || node.Scalar().empty()) Fail(node, field, "expected a non-empty string");
    return node.Scalar();
  }

  bool Bool(const YAML::Node& node, const std::string& field) const {
    bool value = false;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) {
      Fail(node, field, "expected true or false");
    }
    return value;
  }

  // A number (fixed) or a two-element list [min, max].
  Range ReadRange(const YAML::Node& node, const std::string& field) const {
    if (node.IsScalar()) {
      const double v = Number(node, field);
      return {v, v};
    }
    if (!node.IsSequence() || node.size() != 2)
      Fail(node, field, "expected a number or [min, max]");
    const Range r{Number(node[0], field + "[0]"), Number(node[1], field + "[1]")};
    if (r.min > r.max) Fail(node, field, "min is larger than max");
    return r;
  }

  Eigen::Vector2d Point(const YAML::Node& node, const std::string& field) const {
    if (node.IsSequence() && node.size() == 2) {
      return {Number(node[0], field + "[0]"), Number(node[1], field + "[1]")};
    }
    if (!node.IsMap()) Fail(node, field, "expected {x: .., y: ..} or [x, y]");
    CheckKeys(node, field, {"x", "y"});
    return {Number(Required(node, field, "x"), field + ".x"),
            Number(Required(node, field, "y"), field + ".y")};
  }

  Pose2 ReadPose2(const YAML::Node& node, const std::string& field) const {
    CheckKeys(node, field, {"x", "y", "yaw", "yaw_deg"});
    Pose2 pose;
    pose.x = Number(Required(node, field, "x"), field + ".x");
    pose.y = Number(Required(node, field, "y"), field + ".y");
    if (node["yaw"]) pose.yaw = Number(node["yaw"], field + ".yaw");
    if (node["yaw_deg"])
      pose.yaw =
          Number(node["yaw_deg"], field + ".yaw_deg") * (M_PI / 180.0);  // degrees in the file
    return pose;
  }

  YAML::Node Required(const YAML::Node& map, const std::string& field, const char* key) const {
    YAML::Node child = map[key];
    if (!child) Fail(map, Join(field, key), "is required");
    return child;
  }

  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

}  // namespace egress::twin
