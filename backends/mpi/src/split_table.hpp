#pragma once
// Tables split across ranks, as the seed's renderer kept its scene: block b
// of a table (a fixed number of whole elements, 2 KB by default) lives on
// rank b mod ranks, and every rank reads the table through a cache of
// blocks with least-recently-used replacement.  A miss copies the block
// from this rank's own share or reads it from its owner with MPI one-sided
// communication (a passive-target window per table), so the owner need not
// take part.  Reads run on one thread (the kernels that read a split table
// run on one per rank).
#include <mpi.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sh/mpi.hpp"

namespace sh::mpi {

// What a run asked for: tables of at least `min_bytes` are split.  Sent
// to the ranks as it is.
struct SplitSettings {
  bool enabled = false;
  std::size_t min_bytes = 0;
  std::size_t block_bytes = 2048;
  std::size_t cache_blocks = 64;
};
// From mpi::Options (split_tables, block_bytes, cache_blocks), checked.
SplitSettings split_settings(const Options& options);

// How a table's elements fall into blocks and onto ranks.
struct BlockLayout {
  std::size_t element_bytes = 0, elements = 0, block_elements = 0;
  int ranks = 1;
  BlockLayout() = default;
  BlockLayout(const TableView& view, std::size_t block_bytes, int ranks);
  std::size_t blocks() const { return (elements + block_elements - 1) / block_elements; }
  int owner(std::size_t block) const { return static_cast<int>(block % static_cast<std::size_t>(ranks)); }
  // Where the block starts in its owner's share, in bytes.
  std::size_t offset_in_share(std::size_t block) const { return block / ranks * block_elements * element_bytes; }
  std::size_t bytes_of(std::size_t block) const;
  // The blocks `rank` owns, packed in order: its share.
  std::string share(const void* table, int rank) const;
};

class SplitTable : public TableSource {
 public:
  // Collective over every rank, in the same order on each.
  SplitTable(const BlockLayout& layout, const std::string& own_share, std::size_t cache_blocks);
  ~SplitTable() override;  // collective too
  SplitTable(const SplitTable&) = delete;
  SplitTable& operator=(const SplitTable&) = delete;

  Span span_of(std::size_t flat) override;
  void count_reads(std::size_t reads) override { counts_.reads += reads; }
  // Reads and misses since the last call.
  CacheCounts take_counts();

 private:
  const char* block(std::size_t b);
  void fill(std::size_t b, char* slot);

  BlockLayout layout_;
  int rank_ = 0;
  char* own_ = nullptr;  // this rank's share, in the window's memory
  MPI_Win window_ = MPI_WIN_NULL;
  std::vector<char> slots_;
  std::size_t slot_bytes_ = 0, capacity_ = 0, filled_ = 0;
  // Least recently used by time stamps: a hit is two stores; a miss, rare,
  // looks at every slot for the oldest.
  std::vector<std::int32_t> slot_of_;  // per block: its slot, or -1
  std::vector<std::size_t> block_in_;  // per slot: its block
  std::vector<std::uint64_t> used_at_;  // per slot: when last read
  std::uint64_t clock_ = 0;
  CacheCounts counts_;
};

// The split tables this rank holds, by table identity, at the version and
// with the blocks and cache they were split with.  A new version or other
// settings replace the old one (collectively).
struct HeldSplit {
  std::uint64_t version = 0;
  std::size_t block_bytes = 0, cache_blocks = 0;
  std::unique_ptr<SplitTable> table;
};
std::map<std::uint64_t, HeldSplit>& split_tables();
// Whether this rank holds `view` split as `settings` ask.
bool holds_split(const TableView& view, const SplitSettings& settings);
// Collective: holds `view` split as `settings` ask, from this rank's share.
SplitTable& hold_split(const TableView& view, const SplitSettings& settings, const std::string& share);
// Collective, before MPI ends: frees every split table's window.
void release_split_tables();

}  // namespace sh::mpi
