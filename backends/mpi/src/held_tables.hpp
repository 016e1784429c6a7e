#pragma once
// Whole tables the serving ranks keep between runs, held by the kernels
// that read them.  Each kernel names, for each table of its program, the
// table its last run read there (a slot); a table is kept while a slot
// names it.  A kernel given another table in a slot (the same kernel over
// another scene), or destroyed, lets go of the old one, so the ranks do
// not keep every table they were ever sent.  Rank 0 and every serving rank
// follow the same runs and so agree on what is kept: rank 0 sends a table
// again exactly where the ranks let it go.
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

namespace sh::mpi {

constexpr std::uint64_t kNoTable = std::numeric_limits<std::uint64_t>::max();

// A kernel's slots, one per table of its program, naming none at first.
using TableSlots = std::vector<std::uint64_t>;
inline TableSlots no_tables(std::size_t n) { return TableSlots(n, kNoTable); }

template <class Kept>
class HeldTables {
 public:
  // Slot i now names table `id`: what is kept for it (default-made when new).
  Kept& hold(TableSlots& slots, std::size_t i, std::uint64_t id) {
    if (slots[i] != id) {
      let_go(slots[i]);
      ++held_[id].holders;
      slots[i] = id;
    }
    return held_[id].kept;
  }
  // Slot i names no table kept here (a split table's, say).
  void clear(TableSlots& slots, std::size_t i) {
    let_go(slots[i]);
    slots[i] = kNoTable;
  }
  void clear_all(TableSlots& slots) {
    for (std::size_t i = 0; i < slots.size(); ++i) clear(slots, i);
  }
  template <class F>
  void for_each(F f) const {
    for (const auto& [id, h] : held_) f(h.kept);
  }

 private:
  void let_go(std::uint64_t id) {
    auto it = held_.find(id);
    if (it != held_.end() && --it->second.holders == 0) held_.erase(it);
  }

  struct Held {
    Kept kept;
    int holders = 0;
  };
  std::map<std::uint64_t, Held> held_;
};

}  // namespace sh::mpi
