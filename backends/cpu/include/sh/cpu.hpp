#pragma once
// The CPU backend, "cpu": the optimised IR is lowered to LLVM IR, compiled
// by LLVM 15's ORC LLJIT for the host CPU (or an x86-64 level it has: Isa),
// and run over the stream in oneTBB parallel loops.  Its library registers
// it when linked (sh::sh).
//
// Kernels are SPMD: each SIMD lane runs one stream element (16 lanes with
// AVX-512, 8 with AVX, else 4), values that cannot differ between lanes
// stay scalar, divergent ifs and loops run under lane masks, and table
// reads are gathers.  Every width gives the same results.
//
// sh::Options it honours: precision (f32 without FMA contraction, IEEE
// divide and sqrt; f64 computes every float as double), math (fast: LLVM
// fast-math flags), threads (a oneTBB arena; 0 = every core),
// max_loop_iterations, and its own options below.
// kernel_for(p, backend("cpu"))->listing() gives the optimised LLVM IR.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sh/backend.hpp"
#include "sh/options.hpp"

namespace sh::cpu {

// Lanes per kernel: the host's widest vectors (Auto), one (Scalar), or 4,
// 8 or 16.
enum class Width : std::uint8_t { Auto = 0, Scalar = 1, Lanes4 = 4, Lanes8 = 8, Lanes16 = 16 };

// Where table elements are read: from the run's memory, or through a call
// out of the kernel (Fetched), so that a table may be a TableSource (such
// as an mpi rank's cache of a table split across ranks).
enum class Tables : std::uint8_t { Memory, Fetched };

// How full batches of outputs are written: through the cache (Cached), or
// past it, with non-temporal stores, where a run's output channels are
// too large to stay there (Auto: together half the last-level cache or
// more) or always (Streamed).  A stream written past the cache costs no read of its lines
// first and evicts nothing a run still reads; the next run that reads it
// finds it in memory.  Only x86 hosts, SPMD widths and kernels without
// loops (whose time goes to their loops, not their stores) stream, and of
// a batch only outputs whose batch is 32 bytes or more; a batch streams
// where each such output's batch starts on a multiple of the largest
// power of two dividing its size, up to a line (64 bytes), else it is
// stored as any other.  Results never change.
enum class Stores : std::uint8_t { Auto, Cached, Streamed };

// Which instructions kernels use: the host's (Host), or those of an
// x86-64 level the host also has: SSE 4.2 (x86-64-v2), AVX2 (x86-64-v3)
// or AVX-512 (x86-64-v4).  A level's widest vectors set the Auto width
// (4, 8 and 16 lanes).  A level the host lacks, or any level on a host
// that is not x86-64, is an error naming what is missing.  Machine code
// for a level runs on every host that has it, and lets one host try the
// code another would run.
enum class Isa : std::uint8_t { Host, Sse42, Avx2, Avx512 };

// RunStats::details of a cpu run (stats.details_as<cpu::RunDetails>()):
// how many runs wrote their outputs past the cache (Stores).
class RunDetails : public sh::RunDetails {
 public:
  std::size_t runs = 0;
  std::size_t streamed = 0;

  std::unique_ptr<sh::RunDetails> clone() const override;
  void add(const sh::RunDetails& more) override;
  // A line where a run streamed; none where every run kept its outputs in
  // the cache, as most do.
  std::vector<std::string> describe() const override;
};

struct Options {
  static constexpr const char* backend_name = "cpu";
  Width width = Width::Auto;
  Tables tables = Tables::Memory;
  Stores stores = Stores::Auto;
  Isa isa = Isa::Host;

  // String form: width (scalar, 4, 8, 16, auto), tables (memory, fetched),
  // stores (auto, cached, streamed), isa (host, sse4.2, avx2, avx512).
  Settings settings() const;
  void set(const std::string& name, const std::string& value);
};

}  // namespace sh::cpu
