#pragma once
// Two stencil programs run as one: a producer whose one output the
// consumer reads as a table (a separable blur's rows, then its columns).
// Run one after the other, the producer's whole output goes to memory and
// comes back; run_fused runs them together in strips of rows instead, as
// Halide computes a stage at its consumer's rows.  A strip's producer rows,
// and the rows above and below it that the consumer's taps reach, go to a
// buffer of the strip's thread that stays in its cache, and the consumer
// reads that buffer as the table.
//
// The strips need a backend that runs in place (Backend::runs_in_place:
// cpu, interp) and a consumer that reads the table only at constant
// offsets from its element's position (taps, as docs/stencils.md writes
// them), with the table clamped or zero at its edges.  Otherwise the two
// run one after the other, with the producer's output written into the
// table; so do programs that scatter, checked runs (Options::checked:
// their findings name elements of the whole grid), outputs that lie in a
// table's memory (an in-place blur, whose strips would overwrite rows a
// later strip reads) and a second table on the table's memory (which the
// strips do not fill).  The outputs are the same either way (RunStats::strips says which
// it was); what the table holds afterwards is not part of the result.
#include <memory>
#include <vector>

#include "sh/backend.hpp"
#include "sh/table.hpp"

namespace sh {

namespace detail {
RunStats run_fused(const Program& producer, const std::shared_ptr<TableStorage>& through, const Program& consumer,
                   const std::vector<std::shared_ptr<Buffer>>& outputs, const BackendChoice& choice, int strip_rows);
}  // namespace detail

// Runs `producer` (no input streams, one output of `through`'s element
// type) and `consumer` (no input streams) over the launch domain of the
// consumer's outputs, a grid of `through`'s dimensions; the consumer reads
// the producer's output as `through`.  `strip_rows` sets the rows of a
// strip (0: as many as keep a strip's buffer in a core's cache).  Throws
// sh::Error naming the program where the two do not fit together.
template <class E>
RunStats run_fused(const Program& producer, const Table2D<E>& through, const Program& consumer,
                   const std::vector<std::shared_ptr<detail::Buffer>>& outputs, const BackendChoice& choice = {},
                   int strip_rows = 0) {
  return detail::run_fused(producer, through.storage(), consumer, outputs, choice, strip_rows);
}

}  // namespace sh
