#include "egress/bt/blackboard.h"

namespace egress::bt {

Blackboard::Ptr Blackboard::Create(Ptr parent) {
  auto blackboard = Ptr(new Blackboard(std::move(parent)));
  if (blackboard->parent_) blackboard->types_ = blackboard->parent_->types_;
  return blackboard;
}

Blackboard& Blackboard::Root() {
  Blackboard* b = this;
  while (b->parent_)
    b = b->parent_.get();
  return *b;
}

const Blackboard& Blackboard::Root() const {
  return const_cast<Blackboard*>(this)->Root();
}

Blackboard::EntryPtr Blackboard::Resolve(std::string_view key, bool create) {
  if (!key.empty() && key.front() == '@') {
    Blackboard& root = Root();
    return root.Resolve(key.substr(1), create);
  }
  std::unique_lock lock(mutex_);
  const std::string name(key);
  if (auto remap = remaps_.find(name); remap != remaps_.end() && parent_) {
    const std::string target = remap->second;
    lock.unlock();
    return parent_->Resolve(target, create);
  }
  if (auto it = entries_.find(name); it != entries_.end()) return it->second;
  if (auto_remap_ && parent_ && !name.empty() && name.front() != '_') {
    lock.unlock();
    return parent_->Resolve(name, create);
  }
  if (!create) return nullptr;
  auto entry = std::make_shared<Entry>();
  entries_.emplace(name, entry);
  return entry;
}

std::optional<Any> Blackboard::GetAny(std::string_view key) const {
  const EntryPtr entry = const_cast<Blackboard*>(this)->Resolve(key, false);
  if (!entry) return std::nullopt;
  std::lock_guard lock(entry->mutex);
  if (entry->value.empty()) return std::nullopt;
  return entry->value;
}

bool Blackboard::Has(std::string_view key) const {
  const EntryPtr entry = const_cast<Blackboard*>(this)->Resolve(key, false);
  if (!entry) return false;
  std::lock_guard lock(entry->mutex);
  return !entry->value.empty();
}

void Blackboard::Set(std::string_view key, Any value) {
  const EntryPtr entry = Resolve(key, true);
  std::lock_guard lock(entry->mutex);
  if (entry->type && !value.empty() && value.type() != *entry->type) {
    // A typed entry: convert strings with the port's parser, numbers between numeric types.
    if (value.IsString() && entry->parse) {
      try {
        value = entry->parse(*value.Peek<std::string>(), types_);
      } catch (const RuntimeError& e) {
        throw RuntimeError(Cat("blackboard entry '", key, "' has type ", entry->type_name,
                               "; cannot store '", value.ToString(), "': ", e.what()));
      }
    } else if (!(value.IsNumber() &&
                 (*entry->type == typeid(std::int64_t) || *entry->type == typeid(double) ||
                  *entry->type == typeid(bool)))) {
      throw RuntimeError(Cat("blackboard entry '", key, "' has type ", entry->type_name,
                             "; cannot store a value of type ", TypeName(value.type())));
    }
  }
  entry->value = std::move(value);
  ++entry->sequence;
}

bool Blackboard::Unset(std::string_view key) {
  if (!key.empty() && key.front() == '@') return Root().Unset(key.substr(1));
  std::unique_lock lock(mutex_);
  const std::string name(key);
  if (auto remap = remaps_.find(name); remap != remaps_.end() && parent_) {
    const std::string target = remap->second;
    lock.unlock();
    return parent_->Unset(target);
  }
  if (entries_.erase(name) > 0) return true;
  if (auto_remap_ && parent_ && !name.empty() && name.front() != '_') {
    lock.unlock();
    return parent_->Unset(name);
  }
  return false;
}

std::uint64_t Blackboard::SequenceId(std::string_view key) const {
  const EntryPtr entry = const_cast<Blackboard*>(this)->Resolve(key, false);
  if (!entry) return 0;
  std::lock_guard lock(entry->mutex);
  return entry->sequence;
}

void Blackboard::AddRemap(std::string internal, std::string parent_key) {
  std::lock_guard lock(mutex_);
  remaps_[std::move(internal)] = std::move(parent_key);
}

std::vector<std::string> Blackboard::LocalKeys() const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> keys;
  for (const auto& [key, entry] : entries_)
    keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  return keys;
}

namespace {
// Numeric port types share the blackboard's normalized storage, so they are compatible.
std::type_index StorageType(std::type_index type) {
  static const std::type_index kInteger = typeid(std::int64_t);
  for (std::type_index t :
       {std::type_index(typeid(int)), std::type_index(typeid(unsigned)),
        std::type_index(typeid(long)), std::type_index(typeid(unsigned long)),
        std::type_index(typeid(short)), std::type_index(typeid(long long)),
        std::type_index(typeid(unsigned long long)), std::type_index(typeid(unsigned short))}) {
    if (type == t) return kInteger;
  }
  if (type == typeid(float)) return typeid(double);
  return type;
}
}  // namespace

void Blackboard::DeclareType(std::string_view key, const PortInfo& port) {
  if (!port.IsStronglyTyped()) return;
  const EntryPtr entry = Resolve(key, true);
  std::lock_guard lock(entry->mutex);
  const std::type_index storage = StorageType(*port.type);
  if (entry->type && *entry->type != storage) {
    throw LogicError(Cat("blackboard entry '", key, "' was first used with type ", entry->type_name,
                         " and now with type ", port.type_name));
  }
  if (!entry->type) {
    entry->type = storage;
    entry->type_name = port.type_name;
    entry->parse = port.parse;
  }
}

std::string Blackboard::DeclaredTypeName(std::string_view key) const {
  const EntryPtr entry = const_cast<Blackboard*>(this)->Resolve(key, false);
  if (!entry) return "";
  std::lock_guard lock(entry->mutex);
  return entry->type_name;
}

}  // namespace egress::bt
