#include "egress/bt/script.h"

#include <cctype>
#include <cmath>
#include <variant>
#include <vector>

#include "egress/bt/blackboard.h"

namespace egress::bt {
namespace {

enum class Tok {
  kNumber,
  kString,
  kIdent,
  kOp,
  kLParen,
  kRParen,
  kSemicolon,
  kQuestion,
  kColon,
  kEnd,
};

struct Token {
  Tok kind;
  std::string text;  // operator text, identifier, string contents
  double number{0.0};
  std::size_t column{0};  // 1-based
};

// A long script is quoted around the column only (a message is read, not a dump).
constexpr std::size_t kQuotedScriptChars = 80;

[[noreturn]] void SyntaxError(std::string_view code, std::string_view what, std::size_t column) {
  std::string quoted(code);
  if (code.size() > kQuotedScriptChars) {
    const std::size_t from =
        std::min(column > kQuotedScriptChars / 2 ? column - kQuotedScriptChars / 2 : 0,
                 code.size() - kQuotedScriptChars);
    quoted = (from > 0 ? "..." : "") + std::string(code.substr(from, kQuotedScriptChars)) +
             (from + kQuotedScriptChars < code.size() ? "..." : "");
  }
  throw LogicError(Cat("invalid script '", quoted, "' (", code.size(), " characters): ", what,
                       " at column ", column));
}

std::vector<Token> Tokenize(std::string_view code) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  const auto at = [&](std::size_t k) { return k < code.size() ? code[k] : '\0'; };
  while (i < code.size()) {
    const char c = code[i];
    const std::size_t column = i + 1;
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) ||
        (c == '.' && std::isdigit(static_cast<unsigned char>(at(i + 1))))) {
      std::size_t j = i;
      double value = 0.0;
      if (c == '0' && (at(i + 1) == 'x' || at(i + 1) == 'X')) {
        j = i + 2;
        while (std::isxdigit(static_cast<unsigned char>(at(j))))
          ++j;
        if (j == i + 2) SyntaxError(code, "hexadecimal literal without digits", column);
        // At most 16 hex digits (64 bits); longer ones overflowed std::stoull (found by fuzzing).
        if (j - i - 2 > 16) SyntaxError(code, "hexadecimal literal longer than 64 bits", column);
        value = double(std::stoull(std::string(code.substr(i + 2, j - i - 2)), nullptr, 16));
      } else {
        while (std::isdigit(static_cast<unsigned char>(at(j))))
          ++j;
        // A '.' followed by a digit is a decimal point; ".." is the concatenation operator.
        if (at(j) == '.' && std::isdigit(static_cast<unsigned char>(at(j + 1)))) {
          ++j;
          while (std::isdigit(static_cast<unsigned char>(at(j))))
            ++j;
        }
        if (at(j) == 'e' || at(j) == 'E') {
          std::size_t k = j + 1;
          if (at(k) == '+' || at(k) == '-') ++k;
          if (std::isdigit(static_cast<unsigned char>(at(k)))) {
            j = k;
            while (std::isdigit(static_cast<unsigned char>(at(j))))
              ++j;
          }
        }
        try {
          value = std::stod(std::string(code.substr(i, j - i)));
        } catch (const std::out_of_range&) {
          SyntaxError(code, "number out of range", column);
        }
      }
      if (std::isalpha(static_cast<unsigned char>(at(j))) || at(j) == '_') {
        SyntaxError(code, "a number runs into a name", j + 1);
      }
      tokens.push_back({Tok::kNumber, std::string(code.substr(i, j - i)), value, column});
      i = j;
      continue;
    }
    if (c == '\'' || c == '"') {
      const std::size_t end = code.find(c, i + 1);
      if (end == std::string_view::npos) SyntaxError(code, "unterminated string", column);
      tokens.push_back({Tok::kString, std::string(code.substr(i + 1, end - i - 1)), 0.0, column});
      i = end + 1;
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == '@') {
      std::size_t j = i + 1;
      while (std::isalnum(static_cast<unsigned char>(at(j))) || at(j) == '_')
        ++j;
      if (c == '@' && j == i + 1) SyntaxError(code, "'@' must be followed by a key", column);
      tokens.push_back({Tok::kIdent, std::string(code.substr(i, j - i)), 0.0, column});
      i = j;
      continue;
    }
    switch (c) {
      case '(':
        tokens.push_back({Tok::kLParen, "(", 0.0, column});
        ++i;
        continue;
      case ')':
        tokens.push_back({Tok::kRParen, ")", 0.0, column});
        ++i;
        continue;
      case ';':
        tokens.push_back({Tok::kSemicolon, ";", 0.0, column});
        ++i;
        continue;
      case '?':
        tokens.push_back({Tok::kQuestion, "?", 0.0, column});
        ++i;
        continue;
      default:
        break;
    }
    static constexpr std::string_view kTwoChar[] = {
        ":=", "+=", "-=", "*=", "/=", "==", "!=", "<=", ">=", "&&", "||", ".."};
    bool matched = false;
    for (std::string_view op : kTwoChar) {
      if (code.substr(i, 2) == op) {
        tokens.push_back({Tok::kOp, std::string(op), 0.0, column});
        i += 2;
        matched = true;
        break;
      }
    }
    if (matched) continue;
    if (c == ':') {
      tokens.push_back({Tok::kColon, ":", 0.0, column});
      ++i;
      continue;
    }
    if (std::string_view("=+-*/<>!~&|^").find(c) != std::string_view::npos) {
      tokens.push_back({Tok::kOp, std::string(1, c), 0.0, column});
      ++i;
      continue;
    }
    SyntaxError(code, Cat("unexpected character '", c, "'"), column);
  }
  tokens.push_back({Tok::kEnd, "", 0.0, code.size() + 1});
  return tokens;
}

}  // namespace

struct Script::Node {
  enum class Kind {
    kNumber,
    kString,
    kVariable,
    kUnary,
    kBinary,
    kCompare,
    kTernary,
    kAssign,
    kSequence
  };
  Kind kind;
  std::string text;  // operator, variable name, string literal
  double number{0.0};
  std::vector<std::unique_ptr<Node>> children;
  std::vector<std::string> compare_ops;  // for kCompare: one per adjacent pair
  std::size_t depth{1};                  // levels of this node's subtree (a leaf: 1)
};

namespace {

using NodePtr = std::unique_ptr<Script::Node>;
using Kind = Script::Node::Kind;

NodePtr MakeNode(Kind kind, std::string text = {}) {
  auto node = std::make_unique<Script::Node>();
  node->kind = kind;
  node->text = std::move(text);
  return node;
}

// Expressions nest at most this deep (parentheses, unary operators, chained assignments and
// ternaries, long operator chains): parsing, evaluating and freeing a script recurse once per
// level, and a script is a line of a tree file, not a program.
constexpr std::size_t kMaxScriptDepth = 128;
// Integers the script converts to (bitwise operators, integer blackboard entries) are exact
// int64 values strictly inside +-2^63.
constexpr double kInt64Limit = 9223372036854775808.0;  // 2^63

class Parser {
 public:
  Parser(std::string_view code, std::vector<Token> tokens)
      : code_(code), tokens_(std::move(tokens)) {}

  NodePtr ParseProgram() {
    auto sequence = MakeNode(Kind::kSequence);
    while (Peek().kind != Tok::kEnd) {
      if (Peek().kind == Tok::kSemicolon) {
        Next();
        continue;
      }
      Add(*sequence, ParseAssignment());
      if (Peek().kind != Tok::kSemicolon && Peek().kind != Tok::kEnd) {
        Fail(Cat("unexpected '", Peek().text, "'"));
      }
    }
    if (sequence->children.empty()) Fail("empty script");
    return sequence;
  }

 private:
  const Token& Peek() const { return tokens_[pos_]; }
  const Token& Next() { return tokens_[pos_++]; }
  bool IsOp(std::string_view op) const { return Peek().kind == Tok::kOp && Peek().text == op; }
  [[noreturn]] void Fail(std::string_view what) const { SyntaxError(code_, what, Peek().column); }

  // Appends `child` to `parent`, keeping the depth within kMaxScriptDepth.
  void Add(Script::Node& parent, NodePtr child) {
    parent.depth = std::max(parent.depth, child->depth + 1);
    if (parent.depth > kMaxScriptDepth)
      Fail(Cat("expression nested deeper than ", kMaxScriptDepth, " levels"));
    parent.children.push_back(std::move(child));
  }
  // Counts the parser's own recursion (it recurses before the tree it builds is deep).
  struct Nesting {
    explicit Nesting(Parser& p) : parser(p) {
      if (++parser.nesting_ > kMaxScriptDepth)
        parser.Fail(Cat("expression nested deeper than ", kMaxScriptDepth, " levels"));
    }
    ~Nesting() { --parser.nesting_; }
    Nesting(const Nesting&) = delete;
    Nesting& operator=(const Nesting&) = delete;
    Parser& parser;
  };

  NodePtr ParseAssignment() {
    const Nesting nesting(*this);
    if (Peek().kind == Tok::kIdent && tokens_[pos_ + 1].kind == Tok::kOp) {
      const std::string& op = tokens_[pos_ + 1].text;
      if (op == ":=" || op == "=" || op == "+=" || op == "-=" || op == "*=" || op == "/=") {
        auto node = MakeNode(Kind::kAssign, op);
        Add(*node, MakeNode(Kind::kVariable, Next().text));
        Next();
        Add(*node, ParseAssignment());
        return node;
      }
    }
    return ParseTernary();
  }

  NodePtr ParseTernary() {
    const Nesting nesting(*this);
    NodePtr condition = ParseBinary(0);
    if (Peek().kind != Tok::kQuestion) return condition;
    Next();
    auto node = MakeNode(Kind::kTernary);
    Add(*node, std::move(condition));
    Add(*node, ParseTernary());
    if (Peek().kind != Tok::kColon) Fail("expected ':' in a ternary expression");
    Next();
    Add(*node, ParseTernary());
    return node;
  }

  // Binary levels, loosest first. Level 2 (comparisons) builds a chain node.
  static const std::vector<std::vector<std::string_view>>& Levels() {
    static const std::vector<std::vector<std::string_view>> levels = {
        {"||"},           {"&&"},    {"==", "!=", "<", "<=", ">", ">="}, {"|", "^"}, {"&"},
        {"+", "-", ".."}, {"*", "/"}};
    return levels;
  }

  NodePtr ParseBinary(std::size_t level) {
    if (level == Levels().size()) return ParseUnary();
    NodePtr left = ParseBinary(level + 1);
    const auto matches = [&] {
      if (Peek().kind != Tok::kOp) return false;
      for (std::string_view op : Levels()[level]) {
        if (Peek().text == op) return true;
      }
      return false;
    };
    if (level == 2) {
      if (!matches()) return left;
      auto chain = MakeNode(Kind::kCompare);
      Add(*chain, std::move(left));
      while (matches()) {
        chain->compare_ops.push_back(Next().text);
        Add(*chain, ParseBinary(level + 1));
      }
      return chain;
    }
    while (matches()) {
      auto node = MakeNode(Kind::kBinary, Next().text);
      Add(*node, std::move(left));
      Add(*node, ParseBinary(level + 1));
      left = std::move(node);
    }
    return left;
  }

  NodePtr ParseUnary() {
    const Nesting nesting(*this);
    if (IsOp("-") || IsOp("!") || IsOp("~")) {
      auto node = MakeNode(Kind::kUnary, Next().text);
      Add(*node, ParseUnary());
      return node;
    }
    return ParsePrimary();
  }

  NodePtr ParsePrimary() {
    const Token& token = Peek();
    switch (token.kind) {
      case Tok::kNumber: {
        auto node = MakeNode(Kind::kNumber);
        node->number = Next().number;
        return node;
      }
      case Tok::kString:
        return MakeNode(Kind::kString, Next().text);
      case Tok::kIdent: {
        const std::string name = Next().text;
        if (name == "true" || name == "false") {
          auto node = MakeNode(Kind::kNumber);
          node->number = name == "true" ? 1.0 : 0.0;
          return node;
        }
        return MakeNode(Kind::kVariable, name);
      }
      case Tok::kLParen: {
        Next();
        NodePtr inner = ParseAssignment();
        if (Peek().kind != Tok::kRParen) Fail("expected ')'");
        Next();
        return inner;
      }
      case Tok::kEnd:
        Fail("unexpected end of script");
      default:
        Fail(Cat("unexpected '", token.text, "'"));
    }
  }

  std::string_view code_;
  std::vector<Token> tokens_;
  std::size_t pos_{0};
  std::size_t nesting_{0};
};

// ---- evaluation

using Value = std::variant<double, std::string>;

std::string NumberText(double v) {
  if (std::trunc(v) == v && std::abs(v) < 1e15) return std::to_string(static_cast<std::int64_t>(v));
  std::ostringstream out;
  out.precision(15);
  out << v;
  return out.str();
}

class Evaluator {
 public:
  Evaluator(const ScriptEnvironment& env, const std::string& source) : env_(env), source_(source) {}

  Value Eval(const Script::Node& node) {
    switch (node.kind) {
      case Kind::kNumber:
        return node.number;
      case Kind::kString:
        return node.text;
      case Kind::kVariable:
        return Read(node.text);
      case Kind::kUnary:
        return EvalUnary(node);
      case Kind::kBinary:
        return EvalBinary(node.text, Eval(*node.children[0]), Eval(*node.children[1]));
      case Kind::kCompare: {
        bool result = true;
        Value left = Eval(*node.children[0]);
        for (std::size_t k = 0; k < node.compare_ops.size(); ++k) {
          Value right = Eval(*node.children[k + 1]);
          result = Compare(node.compare_ops[k], left, right) && result;
          left = std::move(right);
        }
        return result ? 1.0 : 0.0;
      }
      case Kind::kTernary:
        return Truthy(Eval(*node.children[0])) ? Eval(*node.children[1]) : Eval(*node.children[2]);
      case Kind::kAssign:
        return Assign(node);
      case Kind::kSequence: {
        Value last = 0.0;
        for (const auto& child : node.children)
          last = Eval(*child);
        return last;
      }
    }
    Fail("unknown expression");
  }

  bool Truthy(const Value& v) {
    if (const double* d = std::get_if<double>(&v)) return *d != 0.0;
    const std::string& s = std::get<std::string>(v);
    if (s == "true" || s == "True" || s == "TRUE" || s == "1") return true;
    if (s.empty() || s == "false" || s == "False" || s == "FALSE" || s == "0") return false;
    Fail(Cat("the string '", s, "' is not a boolean"));
  }

 private:
  [[noreturn]] void Fail(std::string_view what) const {
    throw RuntimeError(Cat("script '", source_, "': ", what));
  }

  Value Read(const std::string& name) {
    if (env_.enums != nullptr) {
      if (auto it = env_.enums->find(name); it != env_.enums->end()) return double(it->second);
    }
    if (env_.blackboard == nullptr) Fail(Cat("variable '", name, "' has no blackboard"));
    const std::optional<Any> value = env_.blackboard->GetAny(name);
    if (!value || value->empty()) Fail(Cat("variable '", name, "' is not defined"));
    return ToValue(*value, name);
  }

  Value ToValue(const Any& any, const std::string& name) {
    if (const auto* s = any.Peek<std::string>()) return *s;
    if (any.IsNumber()) return any.Cast<double>();
    Fail(Cat("variable '", name, "' holds a ", TypeName(any.type()), ", which scripts cannot use"));
  }

  double Number(const Value& v, std::string_view op) {
    if (const double* d = std::get_if<double>(&v)) return *d;
    const std::string& s = std::get<std::string>(v);
    if (env_.enums != nullptr) {
      if (auto it = env_.enums->find(s); it != env_.enums->end()) return double(it->second);
    }
    try {
      return ParseReal(s);
    } catch (const RuntimeError&) {
      Fail(Cat("operator '", op, "' needs a number, got the string '", s, "'"));
    }
  }

  std::int64_t Integer(const Value& v, std::string_view op) {
    const double d = Number(v, op);
    if (std::trunc(d) != d) Fail(Cat("operator '", op, "' needs an integer, got ", d));
    if (!(std::abs(d) < kInt64Limit))
      Fail(Cat("operator '", op, "': ", d, " is outside the 64-bit integer range"));
    return static_cast<std::int64_t>(d);
  }

  Value EvalUnary(const Script::Node& node) {
    const Value operand = Eval(*node.children[0]);
    if (node.text == "-") return -Number(operand, "-");
    if (node.text == "!") return Truthy(operand) ? 0.0 : 1.0;
    return double(~Integer(operand, "~"));
  }

  Value EvalBinary(const std::string& op, const Value& a, const Value& b) {
    if (op == "..") return Text(a) + Text(b);
    if (op == "+" && std::holds_alternative<std::string>(a) &&
        std::holds_alternative<std::string>(b)) {
      return std::get<std::string>(a) + std::get<std::string>(b);
    }
    if (op == "&&" || op == "||") {
      // Both sides are evaluated and must be booleans (BT.CPP does not short-circuit).
      const bool x = Truthy(a), y = Truthy(b);
      return (op == "&&" ? x && y : x || y) ? 1.0 : 0.0;
    }
    if (op == "|") return double(Integer(a, op) | Integer(b, op));
    if (op == "^") return double(Integer(a, op) ^ Integer(b, op));
    if (op == "&") return double(Integer(a, op) & Integer(b, op));
    if ((std::holds_alternative<std::string>(a) || std::holds_alternative<std::string>(b)) &&
        op == "+") {
      Fail("'+' joins two strings or adds two numbers; use '..' to join a string and a number");
    }
    const double x = Number(a, op), y = Number(b, op);
    if (op == "+") return x + y;
    if (op == "-") return x - y;
    if (op == "*") return x * y;
    if (op == "/") {
      if (y == 0.0) Fail("division by zero");
      return x / y;
    }
    Fail(Cat("unknown operator '", op, "'"));
  }

  std::string Text(const Value& v) {
    if (const double* d = std::get_if<double>(&v)) return NumberText(*d);
    return std::get<std::string>(v);
  }

  bool Compare(const std::string& op, const Value& a, const Value& b) {
    const bool strings =
        std::holds_alternative<std::string>(a) && std::holds_alternative<std::string>(b);
    int order;
    if (strings) {
      const int c = std::get<std::string>(a).compare(std::get<std::string>(b));
      order = c < 0 ? -1 : (c > 0 ? 1 : 0);
    } else {
      const double x = Number(a, op), y = Number(b, op);
      order = x < y ? -1 : (x > y ? 1 : 0);
      if (op == "==" || op == "!=") {
        const bool equal =
            std::abs(x - y) <= 1e-12 * std::max(1.0, std::max(std::abs(x), std::abs(y)));
        return (op == "==") == equal;
      }
    }
    if (op == "==") return order == 0;
    if (op == "!=") return order != 0;
    if (op == "<") return order < 0;
    if (op == "<=") return order <= 0;
    if (op == ">") return order > 0;
    return order >= 0;
  }

  Value Assign(const Script::Node& node) {
    const std::string& name = node.children[0]->text;
    const std::string& op = node.text;
    if (env_.enums != nullptr && env_.enums->contains(name)) {
      Fail(Cat("cannot assign to '", name, "': it is an enum constant"));
    }
    if (env_.blackboard == nullptr) Fail(Cat("variable '", name, "' has no blackboard"));
    const bool exists = env_.blackboard->Has(name);
    if (op != ":=" && !exists) {
      Fail(Cat("variable '", name, "' is not defined; use ':=' to create it"));
    }
    Value value = Eval(*node.children[1]);
    if (op.size() == 2 && op[1] == '=' && op[0] != ':') {
      const Value current = Read(name);
      value = EvalBinary(std::string(1, op[0]), current, value);
    }
    Any stored;
    if (const double* d = std::get_if<double>(&value)) {
      // Keep integer and bool entries integer and bool when the value fits.
      const std::optional<Any> previous = exists ? env_.blackboard->GetAny(name) : std::nullopt;
      if (previous && previous->IsType<std::int64_t>() && std::trunc(*d) == *d &&
          std::abs(*d) < kInt64Limit) {
        stored = static_cast<std::int64_t>(*d);
      } else if (previous && previous->IsType<bool>() && (*d == 0.0 || *d == 1.0)) {
        stored = *d == 1.0;
      } else {
        stored = *d;
      }
    } else {
      stored = std::get<std::string>(value);
    }
    try {
      env_.blackboard->Set(name, std::move(stored));
    } catch (const RuntimeError& e) {
      Fail(Cat("cannot assign '", name, "': ", e.what()));
    }
    return value;
  }

  const ScriptEnvironment& env_;
  const std::string& source_;
};

}  // namespace

Script::~Script() = default;

std::shared_ptr<const Script> Script::Parse(std::string_view code) {
  Parser parser(code, Tokenize(code));
  auto script = std::shared_ptr<Script>(new Script());
  script->source_ = std::string(code);
  script->program_ = parser.ParseProgram();
  return script;
}

Any Script::Evaluate(const ScriptEnvironment& environment) const {
  Evaluator evaluator(environment, source_);
  Value result = evaluator.Eval(*program_);
  if (const double* d = std::get_if<double>(&result)) return Any(*d);
  return Any(std::get<std::string>(std::move(result)));
}

bool Script::EvaluateCondition(const ScriptEnvironment& environment) const {
  Evaluator evaluator(environment, source_);
  return evaluator.Truthy(evaluator.Eval(*program_));
}

}  // namespace egress::bt
