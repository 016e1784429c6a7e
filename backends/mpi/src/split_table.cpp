#include "split_table.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "options.hpp"
#include "sh/error.hpp"

namespace sh::mpi {

SplitSettings split_settings(const Options& o) {
  check(o);
  SplitSettings s;
  s.enabled = o.split_tables.has_value();
  s.min_bytes = o.split_tables.value_or(0);
  s.block_bytes = o.block_bytes;
  s.cache_blocks = o.cache_blocks;
  return s;
}

BlockLayout::BlockLayout(const TableView& view, std::size_t block_bytes, int ranks)
    : element_bytes(static_cast<std::size_t>(view.element.width) * ir::storage_bytes(view.element.scalar)),
      elements(view.bytes() / element_bytes),
      block_elements(std::max<std::size_t>(1, block_bytes / element_bytes)),
      ranks(ranks) {}

std::size_t BlockLayout::bytes_of(std::size_t block) const {
  return std::min(block_elements, elements - block * block_elements) * element_bytes;
}

std::string BlockLayout::share(const void* table, int rank) const {
  std::string packed;
  for (std::size_t b = static_cast<std::size_t>(rank); b < blocks(); b += static_cast<std::size_t>(ranks))
    packed.append(static_cast<const char*>(table) + b * block_elements * element_bytes, bytes_of(b));
  return packed;
}

SplitTable::SplitTable(const BlockLayout& layout, const std::string& own_share, std::size_t cache_blocks)
    : layout_(layout), slot_bytes_(layout.block_elements * layout.element_bytes),
      capacity_(std::min(cache_blocks, layout.blocks())) {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  slots_.resize(slot_bytes_ * capacity_);
  slot_of_.assign(layout.blocks(), -1);
  block_in_.resize(capacity_);
  used_at_.resize(capacity_);
  // Memory MPI allocates: within a node it is shared memory that the
  // other ranks read directly; across nodes, memory registered for RDMA.
  MPI_Win_allocate(static_cast<MPI_Aint>(own_share.size()), 1, MPI_INFO_NULL, MPI_COMM_WORLD, &own_, &window_);
  // One shared epoch for the table's life: each miss only flushes.
  MPI_Win_lock_all(MPI_MODE_NOCHECK, window_);
  if (!own_share.empty()) std::memcpy(own_, own_share.data(), own_share.size());
  // No rank reads a share before its owner has written it: a rank that
  // went on at once read zeros from one still copying (a loaded machine's
  // failure of the split-table tests).
  MPI_Win_sync(window_);
  MPI_Barrier(MPI_COMM_WORLD);
}

SplitTable::~SplitTable() {
  MPI_Win_unlock_all(window_);
  MPI_Win_free(&window_);
}

TableSource::Span SplitTable::span_of(std::size_t flat) {
  ++counts_.reads;
  std::size_t b = flat / layout_.block_elements, first = b * layout_.block_elements;
  return {block(b), first, std::min(first + layout_.block_elements, layout_.elements)};
}

const char* SplitTable::block(std::size_t b) {
  std::int32_t slot = slot_of_[b];
  if (slot < 0) {
    if (filled_ < capacity_) {
      slot = static_cast<std::int32_t>(filled_++);
    } else {  // evict the least recently used
      slot = static_cast<std::int32_t>(std::min_element(used_at_.begin(), used_at_.end()) - used_at_.begin());
      slot_of_[block_in_[static_cast<std::size_t>(slot)]] = -1;
    }
    fill(b, slots_.data() + static_cast<std::size_t>(slot) * slot_bytes_);
    slot_of_[b] = slot;
    block_in_[static_cast<std::size_t>(slot)] = b;
  }
  used_at_[static_cast<std::size_t>(slot)] = ++clock_;
  return slots_.data() + static_cast<std::size_t>(slot) * slot_bytes_;
}

void SplitTable::fill(std::size_t b, char* slot) {
  auto start = std::chrono::steady_clock::now();
  int owner = layout_.owner(b);
  std::size_t offset = layout_.offset_in_share(b), bytes = layout_.bytes_of(b);
  if (owner == rank_) {
    std::memcpy(slot, own_ + offset, bytes);
    ++counts_.local_misses;
  } else {
    int n = static_cast<int>(bytes);
    MPI_Get(slot, n, MPI_BYTE, owner, static_cast<MPI_Aint>(offset), n, MPI_BYTE, window_);
    MPI_Win_flush(owner, window_);
    ++counts_.remote_misses;
  }
  counts_.fill_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

CacheCounts SplitTable::take_counts() {
  CacheCounts taken = counts_;
  counts_ = {};
  return taken;
}

// Never destroyed by exit: freeing windows is collective, and rank 0 frees
// them in step with the others when it shuts them down.
std::map<std::uint64_t, HeldSplit>& split_tables() {
  static auto* held = new std::map<std::uint64_t, HeldSplit>;
  return *held;
}

bool holds_split(const TableView& view, const SplitSettings& settings) {
  auto it = split_tables().find(view.id);
  return it != split_tables().end() && it->second.version == view.version &&
         it->second.block_bytes == settings.block_bytes && it->second.cache_blocks == settings.cache_blocks;
}

SplitTable& hold_split(const TableView& view, const SplitSettings& settings, const std::string& share) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  HeldSplit& held = split_tables()[view.id];
  held.table.reset();
  held = {view.version, settings.block_bytes, settings.cache_blocks, nullptr};
  held.table = std::make_unique<SplitTable>(BlockLayout(view, settings.block_bytes, ranks), share,
                                            settings.cache_blocks);
  return *held.table;
}

void release_split_tables() { split_tables().clear(); }

}  // namespace sh::mpi
