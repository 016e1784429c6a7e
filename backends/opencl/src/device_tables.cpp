#include "device_tables.hpp"

namespace sh::opencl {

DeviceTables::Copy DeviceTables::hold(TableSlots& slots, std::size_t slot, const TableView& t,
                                      const std::function<Buffer()>& make) {
  std::lock_guard lock(mutex_);
  drop_orphans();
  // A table a run reads is alive, if it has an owner at all.
  std::shared_ptr<const void> owner = t.owner.lock();
  TableKey key{t.id, owner ? owner.get() : static_cast<const void*>(&slots.at(slot))};
  if (slots[slot] != key) {
    let_go(slots[slot]);
    slots[slot] = key;
    ++kept_[key].holders;
  }
  Kept& k = kept_[key];
  Copy copy{k.buffer, false};
  if (!k.buffer || k.version != t.version || k.bytes != t.bytes()) {
    k.buffer = std::make_shared<const Buffer>(make());
    k.version = t.version;
    k.bytes = t.bytes();
    k.owner = t.owner;
    k.owned = owner != nullptr;
    copy = {k.buffer, true};
  }
  return copy;
}

void DeviceTables::release(TableSlots& slots) {
  std::lock_guard lock(mutex_);
  for (TableKey& key : slots) {
    let_go(key);
    key = kNoTable;
  }
}

std::size_t DeviceTables::bytes() const {
  std::lock_guard lock(mutex_);
  std::size_t total = 0;
  for (const auto& [id, k] : kept_) total += k.bytes;
  return total;
}

void DeviceTables::let_go(const TableKey& key) {
  auto it = kept_.find(key);
  if (it != kept_.end() && --it->second.holders <= 0) kept_.erase(it);
}

// A table that is gone is read by no run again (its id is never reused),
// however many slots still name it: a slot that names it names a key no
// view will have again.
void DeviceTables::drop_orphans() {
  std::erase_if(kept_, [](const auto& entry) { return entry.second.owned && entry.second.owner.expired(); });
}

DeviceTables& tables_on(const Device& device) {
  // Never destroyed: devices stay open, and kernels let go of their tables
  // in static destructors too.
  struct Sets {
    std::mutex mutex;
    std::map<cl_device_id, DeviceTables> of;
  };
  static Sets* sets = new Sets;
  std::lock_guard lock(sets->mutex);
  return sets->of[device.id];
}

}  // namespace sh::opencl
