#pragma once
/// @file
/// The BehaviorTree.CPP v4 scripting language, used by Script, ScriptCondition, Precondition
/// and the `_skipIf`/`_while`/`_onSuccess`/... attributes.
///
/// Statements are separated by `;`; the last one's value is the result. Literals: integers
/// (also 0x hex), reals, `true`/`false`, strings in single *or* double quotes (BT.CPP 4.9+ takes
/// only single quotes; real trees use both). Identifiers are blackboard keys (`@key` for the
/// root blackboard) unless they name a registered enum. Operators, loosest first: assignment
/// (`:=` creates, `=` requires the key, `+= -= *= /=`), ternary `?:`, `||`, `&&` (both sides
/// are always evaluated, as in BT.CPP), comparisons (chainable: `a < b < c`), `|` `^`, `&`,
/// `+ -` and `..` (concatenation), `* /`, unary `- ! ~`. Numbers are doubles; `+` also joins
/// two strings. Scripts are parsed when a tree is loaded, so syntax errors surface before the
/// first tick.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>

#include "egress/bt/any.h"

namespace egress::bt {

class Blackboard;

/// Named integer constants usable in scripts (and as values of integer ports).
using ScriptEnums = std::unordered_map<std::string, std::int64_t>;

/// What a script runs against.
struct ScriptEnvironment {
  Blackboard* blackboard{nullptr};
  const ScriptEnums* enums{nullptr};
};

class Script {
 public:
  /// Parses `code`. @throws LogicError "invalid script '<code>': <what> at column N".
  static std::shared_ptr<const Script> Parse(std::string_view code);
  ~Script();

  /// Runs the script; returns the last statement's value (a double or a std::string).
  /// @throws RuntimeError for an undefined variable, a type mismatch or `=` on a missing key.
  Any Evaluate(const ScriptEnvironment& environment) const;
  /// Runs the script and interprets the result as a condition: numbers are true when non-zero;
  /// strings "true"/"1" and "false"/"0"/"" are accepted. @throws RuntimeError otherwise.
  bool EvaluateCondition(const ScriptEnvironment& environment) const;
  const std::string& source() const { return source_; }

  struct Node;

 private:
  Script() = default;
  std::string source_;
  std::unique_ptr<Node> program_;
};

}  // namespace egress::bt
