#pragma once
/// @file
/// Error types and message helpers shared by every egress module.
///
/// Two kinds of errors, as in Drake and BehaviorTree.CPP:
///  - InvalidArgument: a caller passed a value that breaks a documented precondition (a NaN
///    pose, a negative resolution). The calling code must change.
///  - LoadError: a file or text the user brought cannot be used (missing file, malformed XML,
///    a required element absent). Its message names the source and, where known, the line,
///    element or field.
/// Messages follow "Invalid <what>: <field> (<value>) must be <rule>."

#include <sstream>
#include <stdexcept>
#include <string>

namespace egress {

/// Concatenates any streamable values into one string.
template <typename... Args>
std::string StrCat(const Args&... args) {
  std::ostringstream out;
  out.precision(10);
  (out << ... << args);
  return out.str();
}

/// A value passed to an egress API breaks its documented precondition.
class InvalidArgument : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A file or document the user brought cannot be loaded. what() names the source.
class LoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A file lies outside the directory the reader is confined to (ScopedReadRoot).
class PathOutsideRoot : public LoadError {
 public:
  using LoadError::LoadError;
};

/// Throws InvalidArgument with the concatenated message unless `condition` holds.
template <typename... Args>
void ThrowUnless(bool condition, const Args&... message) {
  if (!condition) throw InvalidArgument(StrCat(message...));
}

}  // namespace egress
