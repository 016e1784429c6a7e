// run_fused's strips as a backend's kernels see them: the consumer's view
// of the table its producer fills ends at the last row the strip's buffer
// holds, so that nothing a kernel derives from the view (a prefetch of the
// row after its taps) reaches past the buffer.
#include <gtest/gtest.h>

#include <sh/sh.hpp>

#include <algorithm>
#include <mutex>
#include <vector>

namespace {

using namespace sh;

// What each run of a program reading a table was handed: its domain's
// rows and the rows its first table's view spans.
struct StripRun {
  std::size_t first_row, end_row;
  int table_rows;
};

std::mutex seen_lock;
std::vector<StripRun> seen;

// interp's kernels, in place, recording the runs that read a table.
class RecordingKernel : public Kernel {
 public:
  explicit RecordingKernel(std::unique_ptr<Kernel> inner) : inner_(std::move(inner)) {}
  void run(const RunArgs& args, RunStats& stats) override {
    if (!args.tables.empty() && args.domain.extent[0] > 0) {
      std::size_t row = args.domain.extent[0];
      std::lock_guard<std::mutex> lock(seen_lock);
      seen.push_back({args.domain.first / row, (args.domain.first + args.count) / row, args.tables[0].dims[1]});
    }
    inner_->run(args, stats);
  }

 private:
  std::unique_ptr<Kernel> inner_;
};

class RecordingBackend : public Backend {
 public:
  std::string name() const override { return "strip_views"; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const Options& o) override {
    return std::make_unique<RecordingKernel>(find_backend("interp").compile(p, o));
  }
  bool runs_in_place() const override { return true; }
};

const bool registered = (register_backend("strip_views", [] { return std::make_unique<RecordingBackend>(); }), true);

TEST(FusedStrips, AConsumersTableEndsAtTheLastRowItsStripHolds) {
  ASSERT_TRUE(registered);
  const int w = 16, h = 20, reach = 2, strip = 6;
  Table2D<Attrib1f> rows(w, h);
  Program along = SH_BEGIN_PROGRAM("strip_views_along") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    out = at(1).cast<float>();
  } SH_END;
  Program down = SH_BEGIN_PROGRAM("strip_views_down") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    out = rows[at + ConstAttrib2i(0, -reach)] + rows[at + ConstAttrib2i(0, reach)];
  } SH_END;
  Channel<Attrib1f> out;
  out.shape(w, h);
  seen.clear();
  RunStats stats = run_fused(along, rows, down, {out}, backend("strip_views"), strip);
  ASSERT_EQ(stats.strips, 4u);
  // Row y sums rows y - 2 and y + 2, each clamped to the table.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      ASSERT_EQ(out[static_cast<std::size_t>(y * w + x)],
                static_cast<float>(std::max(y - reach, 0) + std::min(y + reach, h - 1)))
          << x << ", " << y;
  ASSERT_EQ(seen.size(), 4u) << "one consumer run a strip";
  std::sort(seen.begin(), seen.end(), [](const StripRun& a, const StripRun& b) { return a.first_row < b.first_row; });
  for (const StripRun& run : seen) {
    int held = static_cast<int>(std::min<std::size_t>(run.end_row - 1 + reach, h - 1)) + 1;
    EXPECT_EQ(run.table_rows, held) << "the strip of rows " << run.first_row << " to " << run.end_row;
  }
}

}  // namespace
