#include "device_tables.hpp"

namespace sh::opencl {

DeviceTables::Copy DeviceTables::hold(TableSlots& slots, std::size_t slot, const TableView& t,
                                      const std::function<Buffer()>& make) {
  std::lock_guard lock(mutex_);
  drop_orphans();
  if (slots[slot] != t.id) {
    let_go(slots[slot]);
    slots[slot] = t.id;
    ++kept_[t.id].holders;
  }
  Kept& k = kept_[t.id];
  Copy copy{k.buffer, false};
  if (!k.buffer || k.version != t.version) {
    k.buffer = std::make_shared<const Buffer>(make());
    k.version = t.version;
    k.bytes = t.bytes();
    k.owner = t.owner;
    k.owned = !t.owner.expired();  // a table a run reads is alive, if it has an owner at all
    copy = {k.buffer, true};
  }
  return copy;
}

void DeviceTables::release(TableSlots& slots) {
  std::lock_guard lock(mutex_);
  for (std::uint64_t& id : slots) {
    let_go(id);
    id = kNoTable;
  }
}

std::size_t DeviceTables::bytes() const {
  std::lock_guard lock(mutex_);
  std::size_t total = 0;
  for (const auto& [id, k] : kept_) total += k.bytes;
  return total;
}

void DeviceTables::let_go(std::uint64_t id) {
  auto it = kept_.find(id);
  if (it != kept_.end() && --it->second.holders == 0) kept_.erase(it);
}

// A table that is gone is read by no run again (its id is never reused),
// however many slots still name it.
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
