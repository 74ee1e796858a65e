#pragma once
/// @file
/// The engine's two exception kinds, as in BehaviorTree.CPP: LogicError when a tree or a node
/// registration is wrong (the XML or the code must change), RuntimeError when a value met at
/// tick time is unusable. Load errors name the file, line, element and what is wrong.

#include <sstream>
#include <stdexcept>
#include <string>

namespace egress::bt {

class LogicError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Concatenates streamable values.
template <typename... Args>
std::string Cat(const Args&... args) {
  std::ostringstream out;
  (out << ... << args);
  return out.str();
}

}  // namespace egress::bt
