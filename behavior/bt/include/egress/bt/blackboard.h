#pragma once
/// @file
/// Blackboard: the key-value store nodes share through their ports.
///
/// Each SubTree instance gets its own blackboard whose parent is the including tree's. A key
/// resolves in this order: `@key` goes to the root blackboard; a key remapped with AddRemap
/// goes to the parent's key; a key held locally is used; with auto-remapping on, any other key
/// not starting with `_` is looked up (and created) in the parent.
///
/// Entries are typed: once a strongly typed port uses a key (checked at load time) or a typed
/// value is written, later writes must convert to that type, else RuntimeError.

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "egress/bt/any.h"
#include "egress/bt/ports.h"

namespace egress::bt {

class Blackboard : public std::enable_shared_from_this<Blackboard> {
 public:
  using Ptr = std::shared_ptr<Blackboard>;

  /// A new blackboard; `parent` is the scope remapped and auto-remapped keys resolve in.
  static Ptr Create(Ptr parent = nullptr);

  /// Copy of the value under `key`, or nullopt when there is none.
  std::optional<Any> GetAny(std::string_view key) const;
  /// The value converted to T; nullopt when the key has no value.
  /// @throws RuntimeError if the value does not convert.
  template <typename T>
  std::optional<T> Get(std::string_view key) const {
    auto value = GetAny(key);
    if (!value || value->empty()) return std::nullopt;
    return value->Cast<T>(types_);
  }
  bool Has(std::string_view key) const;

  /// Writes `value`, converting it to the entry's type if the entry is typed.
  /// @throws RuntimeError if it does not convert.
  void Set(std::string_view key, Any value);
  /// Removes the entry (where the key resolves). Returns false if there was none.
  bool Unset(std::string_view key);
  /// Incremented on every write of the entry; 0 when the key has no entry.
  std::uint64_t SequenceId(std::string_view key) const;

  /// Makes the local key `internal` an alias of the parent's key `parent_key`.
  void AddRemap(std::string internal, std::string parent_key);
  void SetAutoRemap(bool enabled) { auto_remap_ = enabled; }
  bool auto_remap() const { return auto_remap_; }
  const Ptr& parent() const { return parent_; }
  /// Keys held locally (not those reached through remapping).
  std::vector<std::string> LocalKeys() const;

  /// Declares the type a port expects of `key` (load time).
  /// @throws LogicError naming both types if the entry already has another strong type.
  void DeclareType(std::string_view key, const PortInfo& port);
  /// The declared type name of the key's entry, or empty.
  std::string DeclaredTypeName(std::string_view key) const;

  /// Used to convert string values into user types on typed entries.
  void SetTypeRegistry(const TypeRegistry* types) { types_ = types; }

 private:
  struct Entry {
    mutable std::mutex mutex;
    Any value;
    std::optional<std::type_index> type;
    std::string type_name;
    std::function<Any(std::string_view, const TypeRegistry*)> parse;
    std::uint64_t sequence{0};
  };
  using EntryPtr = std::shared_ptr<Entry>;

  explicit Blackboard(Ptr parent) : parent_(std::move(parent)) {}
  Blackboard& Root();
  const Blackboard& Root() const;
  /// Where `key` lives and under which name there; `create` makes a missing entry.
  EntryPtr Resolve(std::string_view key, bool create);

  Ptr parent_;
  bool auto_remap_{false};
  const TypeRegistry* types_{nullptr};
  mutable std::mutex mutex_;
  std::unordered_map<std::string, EntryPtr> entries_;
  std::unordered_map<std::string, std::string> remaps_;
};

}  // namespace egress::bt
