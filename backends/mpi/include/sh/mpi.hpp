#pragma once
// The distributed backend, "mpi": under `mpirun -np N`, rank 0 owns the
// streams and every rank (rank 0 too) computes chunks with a local backend
// (mpi::Options::local: by default the preferred backend linked, cpu where
// it is).  The stream is cut into many more chunks than ranks and handed
// out as ranks ask (Schedule::Dynamic), or into one share per rank, rank r
// taking the r-th in every run (Static, the default for runs in waves,
// whose per-rank refiners keep what they built for their share); results
// land in order.  Tables and uniforms go out once per version.
// With Options::split_tables set, tables that large or larger are split
// instead: blocks of block_bytes dealt to the ranks in turn, each rank
// reading through an LRU cache of cache_blocks blocks per table, filled by
// one-sided MPI reads; hit rates come back in RunDetails::caches.  Only
// local backends whose kernels read tables through a TableSource
// (Backend::read_through_sources: cpu, interp) read split tables; with
// others (opencl) tables stay whole, and the backend says so.
// Its library registers it when linked (sh::sh); this header is its API.
//
// Ranks other than 0 serve rank 0 from the first time they compile an mpi
// kernel until rank 0 exits, or ends MPI itself (MPI_Finalize, where it
// started MPI); call sh::mpi::start() at the top of main to make them do
// so at once (they then never run the rest of main).  Nothing runs on the
// backend after MPI_Finalize.  Run without mpirun, it is one rank, and
// says so.
//
// The local backend's own options travel with these in the same
// sh::Options: o.set(sh::mpi::Options{...}).set(sh::cpu::Options{...}).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sh/backend.hpp"

namespace sh::mpi {

// Initialises MPI if needed; on ranks other than 0 serves and exits.
void start();
int rank();
int size();

enum class Schedule : std::uint8_t { Auto, Dynamic, Static };  // Auto: static for runs in waves, else dynamic

struct Options {
  static constexpr const char* backend_name = "mpi";
  // Every member has an initializer: designated initializers may leave any out.
  std::string local{};                 // the backend each rank runs; empty: the preferred one linked
  Schedule schedule = Schedule::Auto;
  std::uint64_t chunk = 0;             // dynamic: elements per chunk; 0: 16 chunks per rank
  std::optional<std::uint64_t> split_tables{};  // tables of at least this many bytes split; none: all whole
  std::uint64_t block_bytes = 2048;    // a split table's blocks (1 to 2^24 bytes)
  std::uint64_t cache_blocks = 64;     // blocks in each rank's cache of each split table (1 to 2^20)

  // String form: local, schedule (dynamic, static), chunk, split_tables
  // (bytes, or "off"), block_bytes, cache_blocks.
  Settings settings() const;
  void set(const std::string& name, const std::string& value);
};

// What one rank did in a run.
struct PartStats {
  int part = 0;  // the rank
  std::size_t elements = 0, chunks = 0;
  double busy_s = 0, idle_s = 0;
  std::size_t bytes_sent = 0, bytes_received = 0;
  std::size_t waves = 0, resumed = 0;  // see RunStats
  // Bytes of tables the rank keeps between runs after this one: a serving
  // rank's copies of the whole tables its kernels' last runs read (one per
  // table a kernel's program names; a kernel given another table there, or
  // destroyed, lets go of the old one).
  std::size_t held_bytes = 0;
};

// Reads of a split table through a cache of blocks: a miss fills a block
// from this rank's share (local) or another rank's.
struct CacheCounts {
  std::size_t reads = 0, local_misses = 0, remote_misses = 0;
  double fill_s = 0;  // time spent filling blocks
  CacheCounts& operator+=(const CacheCounts& o) {
    reads += o.reads;
    local_misses += o.local_misses;
    remote_misses += o.remote_misses;
    fill_s += o.fill_s;
    return *this;
  }
  double hit_rate() const { return reads ? 1.0 - static_cast<double>(local_misses + remote_misses) / reads : 1.0; }
};

struct TableCacheStats {
  std::string table;
  std::size_t blocks = 0, cache_blocks = 0;  // the table's, and each rank's cache's
  CacheCounts counts;                        // summed over ranks
};

// RunStats::details of an mpi run: stats.details_as<mpi::RunDetails>().
class RunDetails : public sh::RunDetails {
 public:
  std::vector<PartStats> parts;         // by rank, rank 0 first
  std::vector<TableCacheStats> caches;  // the split tables

  std::unique_ptr<sh::RunDetails> clone() const override;
  // Parts by rank and caches by table.
  void add(const sh::RunDetails& more) override;
  // Per rank its work, per split table read its cache's figures.
  std::vector<std::string> describe() const override;
};

}  // namespace sh::mpi
