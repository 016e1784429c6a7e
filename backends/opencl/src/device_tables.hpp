#pragma once
// Tables kept on a device between runs, for every kernel there.  A kernel
// names, for each table its program reads, the table its last run read
// there (a slot); a copy is kept while a slot names it, at the version
// last read, but not past its table: a copy whose table is gone goes at
// the next table a run asks for on the device.  (Each kernel kept its last
// tables' copies for as long as it lived, which is as long as the
// process: programs made and dropped one after another each left theirs.)
//
// A table is known by its id and its owner (TableView::owner, the storage
// of a table of the process's own): kernels share such a table's copy.  A
// view without an owner (the Kernel API's, whose ids its caller chose) is
// its slot's alone, as one kernel's copies were before.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "runtime.hpp"
#include "sh/backend.hpp"

namespace sh::opencl {

// A table's id, and its owner's storage or, with none, the slot it is in.
using TableKey = std::pair<std::uint64_t, const void*>;
inline constexpr TableKey kNoTable{~std::uint64_t{0}, nullptr};
using TableSlots = std::vector<TableKey>;

class DeviceTables {
 public:
  struct Copy {
    std::shared_ptr<const Buffer> buffer;  // held by the run that uses it
    bool made = false;                     // made now, from the host's memory
  };
  // Slot `slot` now names table `t`: its copy, made by `make` where none is
  // kept at its version and size.
  Copy hold(TableSlots& slots, std::size_t slot, const TableView& t, const std::function<Buffer()>& make);
  // The slots name nothing (their kernel is going).
  void release(TableSlots& slots);
  std::size_t bytes() const;  // of the copies kept now

 private:
  struct Kept {
    std::uint64_t version = 0;
    std::size_t bytes = 0;
    std::shared_ptr<const Buffer> buffer;
    std::weak_ptr<const void> owner;
    bool owned = false;  // by a table of the process's own, which may go
    int holders = 0;
  };
  void let_go(const TableKey& key);
  void drop_orphans();

  mutable std::mutex mutex_;
  std::map<TableKey, Kept> kept_;
};

// The device's tables, one set for each device opened.
DeviceTables& tables_on(const Device& device);

}  // namespace sh::opencl
