#include "device_tables.hpp"

namespace sh::opencl {

DeviceTables::Copy DeviceTables::hold(TableSlots& slots, std::size_t slot, const TableView& t,
                                      const std::function<Buffer()>& make) {
  // A table a run reads is alive, if it has an owner at all.
  std::shared_ptr<const void> owner = t.owner.lock();
  TableKey key{t.id, owner ? owner.get() : static_cast<const void*>(&slots.at(slot))};
  auto current = [&](const Kept& k) { return k.buffer && k.version == t.version && k.bytes == t.bytes(); };
  {
    std::lock_guard lock(mutex_);
    drop_orphans();
    if (slots[slot] != key) {
      let_go(slots[slot]);
      slots[slot] = key;
      ++kept_[key].holders;
    }
    if (const Kept& k = kept_[key]; current(k)) return {k.buffer, false};
  }
  // Copied outside the lock: a large table's copy holds up no other
  // kernel's run.  The slot's hold keeps the entry meanwhile.
  auto made = std::make_shared<const Buffer>(make());
  std::lock_guard lock(mutex_);
  Kept& k = kept_[key];
  if (current(k)) return {k.buffer, false};  // another run made it meanwhile
  k = {t.version, t.bytes(), made, t.owner, owner != nullptr, k.holders};
  return {made, true};
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

DeviceTables& tables_on(const Device& device) { return one_per_device<DeviceTables>(device); }

}  // namespace sh::opencl
