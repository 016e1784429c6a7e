// What the CPU backend adds beyond the conformance suite: its LLVM listing,
// the kernel cache, thread counts, and errors.
#include <gtest/gtest.h>

#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <sh/cpu.hpp>
#include <sh/sh.hpp>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "../common/fresh.hpp"

namespace {

using namespace sh;

Program polynomial(float last = 1.0f) {
  return SH_BEGIN_PROGRAM("poly") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = (x * 3.0f + 2.0f) * x + last;
  } SH_END;
}

// One read of `table` at the index each element brings.
Program read_at_input(const Table1D<Attrib1f>& table, const std::string& name) {
  return SH_BEGIN_PROGRAM(name) {
    InputAttrib1i at;
    OutputAttrib1f out;
    out = table[at];
  } SH_END;
}

TEST(CpuBackend, ListingIsTheOptimisedLlvmIr) {
  std::string ir = kernel_for(polynomial(), backend("cpu"))->listing();
  EXPECT_NE(ir.find("define void @sh_kernel"), std::string::npos) << ir;
  EXPECT_NE(ir.find("fmul"), std::string::npos) << ir;
  // Precise f32: no fused multiply-add, no fast-math flags.
  EXPECT_EQ(ir.find("fmuladd"), std::string::npos) << ir;
  EXPECT_EQ(ir.find("fast"), std::string::npos) << ir;
  Options fast;
  fast.math = MathMode::Fast;
  EXPECT_NE(kernel_for(polynomial(), backend("cpu", fast))->listing().find("fast"), std::string::npos);
  Options f64;
  f64.precision = Precision::F64;
  f64.set(cpu::Options{.width = cpu::Width::Scalar});
  EXPECT_NE(kernel_for(polynomial(), backend("cpu", f64))->listing().find("fmul double"), std::string::npos);
  f64.set(cpu::Options{.width = cpu::Width::Lanes8});
  EXPECT_NE(kernel_for(polynomial(), backend("cpu", f64))->listing().find("fmul <8 x double>"), std::string::npos);
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Tests of truth values, `repeat` times over in a loop of the program's
// own: some hundred repeats make a kernel large enough for the short
// pipeline, one keeps it on O3.
Program truth_tests(int repeat) {
  return SH_BEGIN_PROGRAM("truths") {
    InputAttrib1f x, y, z;
    OutputAttrib1f out;
    Attrib1f sum = 0.0f;
    SH_FOR(Attrib1i i = 0, i < 2, i += 1) {
      for (int k = 0; k < repeat; ++k) {
        Attrib1f xk = x + static_cast<float>(k % 5);
        Attrib1f inside = xk > 0.0f && y >= 0.0f && !(z > 1.0f);
        Attrib1f beyond = xk < -1.0f || y < -1.0f;
        Attrib1f chosen = cond(z > 0.5f, xk > 1.0f, y > 1.0f);  // a truth value chosen by another
        sum += cond(inside || beyond, xk, y) + cond(chosen && y < 1.5f, z, 0.0f);
      }
    } SH_ENDFOR;
    out = sum;
  } SH_END;
}

float truth_tests_cpp(int repeat, float x, float y, float z) {
  float sum = 0.0f;
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < repeat; ++k) {
      float xk = x + static_cast<float>(k % 5);
      bool inside = xk > 0.0f && y >= 0.0f && !(z > 1.0f), beyond = xk < -1.0f || y < -1.0f;
      bool chosen = z > 0.5f ? xk > 1.0f : y > 1.0f;
      sum += (inside || beyond ? xk : y) + (chosen && y < 1.5f ? z : 0.0f);
    }
  return sum;
}

// && and || that share their operands, forty deep: 80 minima and maxima
// but 2^40 paths through them, each value rewritten once.
TEST(CpuBackend, TruthValuesThatShareOperandsCompileAndAgree) {
  Program p = SH_BEGIN_PROGRAM("shared_truths") {
    InputAttrib1f x, y;
    OutputAttrib1f out;
    Attrib1f a = x > 0.0f, b = y > 0.0f;
    for (int k = 0; k < 40; ++k) {
      Attrib1f both = a && b;
      b = a || b;
      a = both;
    }
    out = cond(a, x, y);
  } SH_END;
  std::vector<float> xs{-1, -1, 2, 2}, ys{-3, 3, -3, 3};
  for (const char* width : {"scalar", "16"}) {
    Options o;
    o.set("cpu.width", width);
    Channel<Attrib1f> x(xs), y(ys), out;
    run(p, {x, y}, {out}, backend("cpu", o));
    for (std::size_t i = 0; i < xs.size(); ++i)
      EXPECT_EQ(out.values()[i], xs[i] > 0 && ys[i] > 0 ? xs[i] : ys[i]) << width << ", element " << i;
  }
}

// A truth value set by a uniform branch to 1 or -1 (a 0 the lowering
// hides from the optimiser) is a select of two vectors by one bit: its
// test with a varying one is the bit, splat, and the lanes' masks.
TEST(CpuBackend, ATruthValueOfAUniformBranchMeetsVaryingOnes) {
  Attrib1f on = 1.0f;
  Program p = SH_BEGIN_PROGRAM("uniform_truth") {
    InputAttrib1f x;
    OutputAttrib1f out;
    Attrib1f t = x > 5.0f;  // varying: its lanes' own values until the branch
    SH_IF(on > 0.5f) { t = 1.0f; } SH_ELSE { t = -1.0f; } SH_ENDIF;
    out = cond(t && x > 0.0f, x, -x);
  } SH_END;
  std::vector<float> xs{-2, -1, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14};
  for (const char* width : {"scalar", "8", "16"})
    for (float setting : {1.0f, 0.0f}) {
      on = setting;
      Options o;
      o.set("cpu.width", width);
      Channel<Attrib1f> x(xs), out;
      run(p, {x}, {out}, backend("cpu", o));
      for (std::size_t i = 0; i < xs.size(); ++i)
        EXPECT_EQ(out.values()[i], setting > 0.5f && xs[i] > 0 ? xs[i] : -xs[i]) << width << ", on " << setting;
    }
}

// A program's && and || of comparisons are the comparisons' masks and-ed
// and or-ed: not the minimum and maximum of their 1s and 0s, tested again
// (truth_values.hpp), on both of the optimiser's pipelines and at every
// width, with the program's results.
TEST(CpuBackend, AndsAndOrsOfComparisonsAreOfTheirMasks) {
  std::vector<float> xs, ys, zs;
  for (float x : {-3.0f, -1.5f, -0.5f, 0.0f, 0.5f})
    for (float y : {-2.0f, -0.5f, 0.0f, 2.0f})
      for (float z : {0.0f, 1.0f, 1.5f}) xs.push_back(x), ys.push_back(y), zs.push_back(z);
  for (int repeat : {1, 300})
    for (const char* width : {"scalar", "8", "16"}) {
      Options o;
      o.set("cpu.width", width);
      Program p = truth_tests(repeat);
      std::string ir = kernel_for(p, backend("cpu", o))->listing();
      EXPECT_FALSE(std::regex_search(ir, std::regex("call .*@llvm\\.(minnum|maxnum)")))
          << repeat << " repeats, width " << width;
      EXPECT_NE(ir.find(std::string(width) == "scalar" ? "and i1" : "and <"), std::string::npos) << ir;
      Channel<Attrib1f> x(xs), y(ys), z(zs), out;
      run(p, {x, y, z}, {out}, backend("cpu", o));
      for (std::size_t i = 0; i < xs.size(); ++i)
        EXPECT_EQ(out.values()[i], truth_tests_cpp(repeat, xs[i], ys[i], zs[i]))
            << repeat << " repeats, width " << width << ", x " << xs[i] << ", y " << ys[i] << ", z " << zs[i];
    }
}

// The listing's basic blocks whose labels start with `prefix`, joined.
std::string blocks(const std::string& ir, const std::string& prefix) {
  std::istringstream lines(ir);
  std::string out;
  bool in = false;
  for (std::string line; std::getline(lines, line);) {
    bool label = !line.empty() && line[0] != ' ' && line.find(':') != std::string::npos && line.find("define") != 0;
    if (label) in = line.rfind(prefix, 0) == 0;
    if (in) out += line + "\n";
  }
  return out;
}

// The instructions a value of a listing of one function is computed from,
// its own first: each definition's line, following its operands (`%name`
// defined by `%name = ...`) back to the phis, whose own operands (a loop's
// values from the iteration before) are not followed.
std::vector<std::string> computed_from(const std::string& ir, const std::string& value) {
  const std::regex definition(R"(^\s*(%[\w.]+) = )"), operand(R"(%[\w.]+)");
  std::map<std::string, std::string> defined;
  std::istringstream lines(ir);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, definition)) defined[m[1]] = line;
  }
  std::vector<std::string> chain;
  std::set<std::string> seen;
  std::vector<std::string> todo{value};
  while (!todo.empty()) {
    std::string name = todo.back();
    todo.pop_back();
    auto found = defined.find(name);
    if (!seen.insert(name).second || found == defined.end()) continue;
    chain.push_back(found->second);
    if (found->second.find("= phi ") != std::string::npos) continue;
    std::string rhs = found->second.substr(found->second.find('=') + 1);
    for (std::sregex_iterator op(rhs.begin(), rhs.end(), operand), end; op != end; ++op)
      todo.push_back(op->str());
  }
  return chain;
}

// A gather is the hardware's where it has a fast one (AVX-512); elsewhere
// a call of the kernel's function that loads the lanes one by one.
std::size_t gathers(const std::string& ir) {
  return __builtin_cpu_supports("avx512f") ? count(ir, "call <16 x float> @llvm.masked.gather.v16f32")
                                           : count(ir, "call fastcc <16 x float> @\"sh_lane_loads.float.<16 x i32>\"");
}

// Where the host permutes 16 lanes in one instruction (AVX-512's vpermps),
// a clamped read outside the inside batches is a load of the row's nearest
// elements and a permute; elsewhere a tested masked load and, at the edge,
// a second masked load of the lanes in the row.
bool permutes_16_lanes() { return __builtin_cpu_supports("avx512f"); }
std::size_t permutes(const std::string& ir) { return count(ir, "call <16 x float> @llvm.x86.avx512.permvar.sf.512("); }

// With AVX-512, a row of taps is read with two loads, at its first and
// last tap, and a shuffle of the two for each tap between; a row of one
// tap, or whose taps lie further apart than a batch, keeps a load a tap.
// At the AVX2 level, where such a shuffle is two instructions, every tap is
// a load of its own.
TEST(CpuBackend, ARowOfTapsIsTwoLoadsAndShufflesWhereAvx512ShiftsLanes) {
  Table2D<Attrib1f> image(64, 64);
  image.assign(std::vector<float>(64 * 64, 1.0f));
  Program p = SH_BEGIN_PROGRAM("rows_of_taps") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    out = 0.0f;
    for (int dx = -2; dx <= 2; ++dx) out += image[at + ConstAttrib2i(dx, 0)];
    out += image[at + ConstAttrib2i(0, 1)];
    out += image[at + ConstAttrib2i(-9, 2)] + image[at + ConstAttrib2i(9, 2)];
  } SH_END;
  auto inside = [&](cpu::Isa isa) {
    Options o;
    o.set(cpu::Options{.width = cpu::Width::Lanes8, .isa = isa});
    return blocks(kernel_for(p, backend("cpu", o))->listing(), "batches.inside:");
  };
  std::string avx2 = inside(cpu::Isa::Avx2);
  EXPECT_EQ(count(avx2, "load <8 x float>"), 5u + 1u + 2u) << avx2;
  EXPECT_EQ(count(avx2, "shufflevector <8 x float>"), 0u) << avx2;
  if (!__builtin_cpu_supports("avx512f")) return;
  std::string avx512 = inside(cpu::Isa::Avx512);
  EXPECT_EQ(count(avx512, "load <8 x float>"), 2u + 1u + 2u) << avx512;
  EXPECT_EQ(count(avx512, "shufflevector <8 x float>"), 3u) << avx512;
}

// A one-row stencil: the sum of the taps from low to high along the row.
Program row_of_taps(const Table2D<Attrib1f>& image, int low, int high) {
  return SH_BEGIN_PROGRAM("row_of_taps") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    out = 0.0f;
    for (int dx = low; dx <= high; ++dx) out += image[at + ConstAttrib2i(dx, 0)];
  } SH_END;
}

// At 8 lanes without AVX-512 a batch is one AVX2 register, and the loop
// along the row takes two batches a trip, as 16 lanes' two registers a
// value do: its one block (stores cached, so that it has one) reads the
// row's five taps twice; at 16 lanes, once.
TEST(CpuBackend, TheRowLoopTakesTwoBatchesATripWhereABatchIsOneAvx2Register) {
  Table2D<Attrib1f> image(64, 64);
  image.assign(std::vector<float>(64 * 64, 1.0f));
  Program p = row_of_taps(image, -2, 2);
  auto inside = [&](cpu::Width width) {
    Options o;
    o.set(cpu::Options{.width = width, .stores = cpu::Stores::Cached, .isa = cpu::Isa::Avx2});
    return blocks(kernel_for(p, backend("cpu", o))->listing(), "batches.inside:");
  };
  std::string eight = inside(cpu::Width::Lanes8), sixteen = inside(cpu::Width::Lanes16);
  EXPECT_EQ(count(eight, "load <8 x float>"), 2u * 5u) << eight;
  EXPECT_EQ(count(eight, "store <8 x float>"), 2u) << eight;
  EXPECT_EQ(count(sixteen, "load <16 x float>"), 5u) << sixteen;
}

// A prefetch is one prefetch instruction where the lanes agree on the
// coordinates (a walk's node) and one a lane where they may differ; scalar
// code asks once an element; a table the kernel fetches (mpi's tables
// split across ranks) is not in this process's memory, so nothing is asked.
// LLVM may unroll the scalar loop, by a factor that depends on the host
// CPU (eight on a Zen 4, none on a Zen 1), so scalar code is counted
// against its copies of the element's one read of the table.
TEST(CpuBackend, PrefetchesOneALaneOrOneForLanesThatAgree) {
  Table1D<Attrib1f> t(64);
  t.assign(std::vector<float>(64, 1.0f));
  Attrib1i shared = 3;
  Program asks = SH_BEGIN_PROGRAM("asks") {
    InputAttrib1i i;
    OutputAttrib1f out;
    t.prefetch(i + 1);
    t.prefetch(shared * 2);
    out = t[i];
  } SH_END;
  auto listing = [&](cpu::Width width, cpu::Tables tables) {
    Options o;
    o.set(cpu::Options{.width = width, .tables = tables});
    return kernel_for(asks, backend("cpu", o))->listing();
  };
  auto asked = [&](cpu::Width width, cpu::Tables tables) {
    return count(listing(width, tables), "call void @llvm.prefetch");
  };
  EXPECT_EQ(asked(cpu::Width::Lanes8, cpu::Tables::Memory), 8u + 1u);
  EXPECT_EQ(asked(cpu::Width::Lanes16, cpu::Tables::Memory), 16u + 1u);
  std::string scalar = listing(cpu::Width::Scalar, cpu::Tables::Memory);
  std::size_t elements = count(scalar, "load float, ptr");
  ASSERT_GE(elements, 1u) << scalar;
  EXPECT_EQ(count(scalar, "call void @llvm.prefetch"), 2u * elements) << scalar;
  EXPECT_EQ(asked(cpu::Width::Lanes16, cpu::Tables::Fetched), 0u);
}

// A stencil's reads at x + c along a row are one vector load each: in a
// full batch whose taps all lie inside the table, with no test and no mask,
// such batches one after another in a loop of their own, each fetching the
// row that the next row of batches will first read; in a full batch past
// the table's edges, where it clamps, each row of taps read once, clamped
// (a masked load and a permute, or selects of the row's ends); elsewhere a
// masked load and, where it clamps, a permute (or a second masked load, as
// above); of a table that repeats, a tested masked load and at the edges a
// gather.  Reads at an input's index are gathers only.  (Stores are
// cached here, so that the loop along the row is the one block.)
TEST(CpuBackend, StencilReadsAreVectorLoads) {
  Table2D<Attrib1f> image(64, 64), wrapped(64, 64);
  image.assign(std::vector<float>(64 * 64, 1.0f));
  wrapped.edge(Edge::Repeat);
  wrapped.assign(std::vector<float>(64 * 64, 1.0f));
  auto stencil_of = [](const Table2D<Attrib1f>& table) {
    return SH_BEGIN_PROGRAM("stencil") {
      OutputAttrib1f out;
      Attrib2i at = position<2>();
      out = table[at + ConstAttrib2i(-1, 0)] + table[at + ConstAttrib2i(1, 1)];
    } SH_END;
  };
  Program stencil = stencil_of(image), repeating = stencil_of(wrapped);
  Program scattered = SH_BEGIN_PROGRAM("scattered") {
    InputAttrib2i at;
    OutputAttrib1f out;
    out = image[at + ConstAttrib2i(-1, 0)];
  } SH_END;
  Options o;
  o.set(cpu::Options{.width = cpu::Width::Lanes16, .stores = cpu::Stores::Cached});
  std::string ir = kernel_for(stencil, backend("cpu", o))->listing();
  std::string inside = blocks(ir, "batches.inside:");
  EXPECT_EQ(count(inside, "load <16 x float>"), 2u) << ir;
  std::string label = inside.substr(0, inside.find('\n'));
  EXPECT_TRUE(label.find("%batches.inside,") != std::string::npos || label.ends_with("%batches.inside"))
      << "the block is a loop (one of its predecessors): " << ir;
  EXPECT_EQ(count(inside, "@llvm.masked"), 0u) << ir;
  EXPECT_EQ(count(inside, "call void @llvm.prefetch"), 1u) << "the row the next row of batches reads first: " << ir;
  // That row, or where it lies past the table the table's last row: the
  // smaller of the two, found before the loop.
  std::smatch asked;
  ASSERT_TRUE(std::regex_search(inside, asked, std::regex(R"(@llvm\.prefetch\.p0\(ptr (%[\w.]+))"))) << inside;
  std::vector<std::string> row = computed_from(ir, asked[1]);
  auto smaller = [](const std::string& d) { return d.find("@llvm.smin.i64") != std::string::npos; };
  EXPECT_TRUE(std::any_of(row.begin(), row.end(), smaller)) << "the prefetched row is always the next one: " << ir;
  std::string clamped = blocks(ir, "batch.clamped");
  EXPECT_EQ(count(clamped, "call <16 x float> @llvm.masked.load.v16f32"), 2u) << ir;
  EXPECT_EQ(permutes(clamped), permutes_16_lanes() ? 2u : 0u) << ir;
  EXPECT_EQ(gathers(clamped), 0u) << ir;
  EXPECT_EQ(count(ir, "call <16 x float> @llvm.masked.load.v16f32"), permutes_16_lanes() ? 2u + 2u : 4u + 2u) << ir;
  EXPECT_EQ(permutes(ir), permutes_16_lanes() ? 2u + 2u : 0u) << ir;
  // Beside each of the tested path's permutes, a gather for a run whose x
  // wraps past INT_MAX.
  std::string past_int_max = blocks(ir, "read.wrapped");
  EXPECT_EQ(gathers(past_int_max), permutes(ir) - permutes(clamped)) << ir;
  EXPECT_EQ(gathers(ir), gathers(past_int_max)) << ir;
  std::string wraps = kernel_for(repeating, backend("cpu", o))->listing();
  EXPECT_EQ(blocks(wraps, "batch.clamped"), "") << wraps;
  EXPECT_EQ(count(wraps, "call <16 x float> @llvm.masked.load.v16f32"), 2u) << wraps;
  EXPECT_EQ(gathers(wraps), 2u) << wraps;
  EXPECT_EQ(permutes(wraps), 0u) << wraps;
  std::string other = kernel_for(scattered, backend("cpu", o))->listing();
  EXPECT_EQ(count(other, "@llvm.masked.load.v16f32"), 0u) << other;
  EXPECT_EQ(gathers(other), 1u) << other;
  EXPECT_EQ(count(other, "@llvm.prefetch"), 0u) << other;
}

// A kernel without loops of its own keeps LLVM's full pipeline however
// large it lowers: a 5 x 5 blur's body is lowered three times (inside, a
// full batch past the edges, the tested path), more instructions than the
// tracer's short pipeline starts at, and the loop along the row computes
// nothing that its batches share, such as the row it asks the cache for
// (the smaller of the next row and the table's last).
TEST(CpuBackend, ALargeKernelWithoutLoopsHoistsWhatARowsBatchesShare) {
  Table2D<Attrib1f> image(64, 64);
  image.assign(std::vector<float>(64 * 64, 1.0f));
  Program blur = SH_BEGIN_PROGRAM("blur") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib1f sum = 0.0f;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) sum += image[at + ConstAttrib2i(dx, dy)];
    out = sum * 0.04f;
  } SH_END;
  Options o;
  o.set(cpu::Options{.width = cpu::Width::Lanes16, .stores = cpu::Stores::Cached});
  std::string ir = kernel_for(blur, backend("cpu", o))->listing();
  std::string inside = blocks(ir, "batches.inside:");
  ASSERT_EQ(count(inside, "call void @llvm.prefetch"), 1u) << ir;
  EXPECT_EQ(count(inside, "@llvm.smin"), 0u) << ir;
}

// With AVX-512, two rows of a stencil's batches at a time share what both
// read: a 3 x 3 box's batch reads three rows, two loads each (the row's
// first and last tap), and the batches at (x, y) and (x, y + 1) read four
// rows, eight loads, not twelve.  Each trip asks for the two rows the next
// two rows of batches read first.  A stencil along one row has nothing to
// share and no such loop, and neither has the scalar kernel, nor the AVX2
// level's, whose 16 registers do not hold two rows' taps.
TEST(CpuBackend, StencilRowsRunTwoAtATimeAndShareTheirLoads) {
  Table2D<Attrib1f> image(64, 64);
  image.assign(std::vector<float>(64 * 64, 1.0f));
  auto box_of = [&](int rows) {
    return SH_BEGIN_PROGRAM("box") {
      OutputAttrib1f out;
      Attrib2i at = position<2>();
      out = 0.0f;
      for (int dy = -(rows / 2); dy <= rows / 2; ++dy)
        for (int dx = -1; dx <= 1; ++dx) out += image[at + ConstAttrib2i(dx, dy)];
    } SH_END;
  };
  auto pairs_of = [&](int rows, cpu::Options options) {
    Options o;
    o.set(options);
    return blocks(kernel_for(box_of(rows), backend("cpu", o))->listing(), "pairs.");
  };
  if (__builtin_cpu_supports("avx2")) {
    EXPECT_TRUE(pairs_of(3, {.width = cpu::Width::Lanes8, .isa = cpu::Isa::Avx2}).empty());
  }
  EXPECT_TRUE(pairs_of(3, {.width = cpu::Width::Scalar}).empty());
  cpu::Options sixteen{.width = cpu::Width::Lanes16, .stores = cpu::Stores::Cached};
  if (!permutes_16_lanes()) {
    EXPECT_TRUE(pairs_of(3, sixteen).empty());
    return;
  }
  EXPECT_TRUE(pairs_of(1, sixteen).empty());
  Options o;
  o.set(sixteen);
  std::string ir = kernel_for(box_of(3), backend("cpu", o))->listing();
  std::string pairs = blocks(ir, "pairs.inside:");
  ASSERT_FALSE(pairs.empty()) << ir;
  EXPECT_EQ(count(blocks(ir, "batches.inside:"), "load <16 x float>"), 6u) << ir;
  EXPECT_EQ(count(pairs, "load <16 x float>"), 8u) << ir;
  EXPECT_EQ(count(pairs, "store <16 x float>"), 2u) << ir;
  EXPECT_EQ(count(pairs, "call void @llvm.prefetch"), 2u) << ir;
}

// A local array that every lane writes alike is one array for all lanes:
// a table of squares filled by a uniform loop and read at a uniform index
// is scalar code.  One whose lanes hold their own values is a vector per
// element: at a uniform index one vector store, at indices that differ a
// gather of each lane's own column.  Scalar code has neither.
TEST(CpuBackend, LocalArraysAreScalarWhereLanesAgreeAndGatherWhereTheyDoNot) {
  Table1D<Attrib1i> at(64);
  Program p = SH_BEGIN_PROGRAM("arrays") {
    InputAttrib1i i;
    OutputAttrib1i out;
    LocalArray<Attrib1i> shared(16), own(16);
    SH_FOR(Attrib1i k = 0, k < 16, k += 1) {
      shared.store(k, at[k]);
      own.store(k, i + k);
    } SH_ENDFOR;
    out = at[shared[at[0]]] + own[i % 16];
  } SH_END;
  Options o;
  o.set(cpu::Options{.width = cpu::Width::Lanes16});
  std::string ir = kernel_for(p, backend("cpu", o))->listing();
  EXPECT_EQ(count(ir, "call <16 x i32> @llvm.masked.gather"), 1u) << "own[i % 16] only: " << ir;
  EXPECT_EQ(count(ir, "call void @llvm.masked.scatter"), 0u) << ir;
  EXPECT_GE(count(ir, "store <16 x i32>"), 1u) << "own's column at k: " << ir;
  o.set(cpu::Options{.width = cpu::Width::Scalar});
  std::string scalar = kernel_for(p, backend("cpu", o))->listing();
  EXPECT_EQ(count(scalar, "@llvm.masked"), 0u) << scalar;
}

// A stack declared in a branch some lanes take, inside a loop, is still
// one for all lanes where they store into it alike: its declaration fills
// it, so nothing stored on an earlier trip is read, and the lanes that
// skip the branch need none of it (the BVH's walk for a shadow ray, in the
// loop over lights).  The table read at the index it gives is one load,
// not a gather.
TEST(CpuBackend, AStackDeclaredInADivergentBranchStaysOneForAllLanes) {
  Table1D<Attrib1f> tab(8);
  Attrib1i u = 2;
  Program p = SH_BEGIN_PROGRAM("stack_in_loop") {
    InputAttrib1i n;
    OutputAttrib1f out;
    out = 0.0f;
    SH_FOR(Attrib1i j = 0, j < 3, j += 1) {
      SH_IF(n > j) {
        LocalArray<Attrib1i> stack(4);
        stack.store(u, u + 1);
        out += tab[stack[u]];
      } SH_ENDIF;
    } SH_ENDFOR;
  } SH_END;
  Options o;
  o.set(cpu::Options{.width = cpu::Width::Lanes16});
  std::string ir = kernel_for(p, backend("cpu", o))->listing();
  EXPECT_EQ(count(ir, "call <16 x float> @llvm.masked.gather"), 0u) << ir;
  EXPECT_EQ(count(ir, "call <16 x i32> @llvm.masked.gather"), 0u) << ir;
}

// Every edge mode keeps a stencil's vector load: inside the table the
// coordinates need no wrapping or zeroing, so only the edge path pays.
TEST(CpuBackend, EveryEdgeModeKeepsTheVectorLoad) {
  for (Edge edge : {Edge::Clamp, Edge::Repeat, Edge::Zero}) {
    Table2D<Attrib1f> image(64, 64);
    image.edge(edge);
    image.assign(std::vector<float>(64 * 64, 1.0f));
    Program stencil = SH_BEGIN_PROGRAM("stencil") {
      OutputAttrib1f out;
      out = image[position<2>() + ConstAttrib2i(-1, 0)];
    } SH_END;
    Options o;
    o.set(cpu::Options{.width = cpu::Width::Lanes16});
    std::string ir = kernel_for(stencil, backend("cpu", o))->listing();
    EXPECT_EQ(count(blocks(ir, "batches.inside:"), "load <16 x float>"), 1u) << ir::edge_name(edge) << ir;
    // Where reads clamp, a masked load and a permute, or the tested path's
    // masked load and at the edge a second, and in a full batch past the
    // edge the same again; where they repeat, the tested one.
    bool clamps = edge != Edge::Repeat;
    EXPECT_EQ(count(ir, "call <16 x float> @llvm.masked.load.v16f32"),
              clamps ? (permutes_16_lanes() ? 1u + 1u : 2u + 1u) : 1u)
        << ir::edge_name(edge) << ir;
    EXPECT_EQ(permutes(ir), clamps && permutes_16_lanes() ? 2u : 0u) << ir::edge_name(edge) << ir;
    EXPECT_EQ(blocks(ir, "batch.clamped").empty(), !clamps) << ir::edge_name(edge) << ir;
    // Wrapping divides: only a batch that reaches the edge may.
    EXPECT_EQ(count(blocks(ir, "read.edge"), "srem"), edge == Edge::Repeat ? count(ir, "srem") : 0u) << ir;
    EXPECT_EQ(count(ir, "srem") > 0, edge == Edge::Repeat) << ir;
  }
}

// A full batch past the edges reads a row of taps as two clamped runs, at
// its first and last tap, and the taps between as shuffles of the two: so
// only where a row's taps span at most a batch.  Seven taps along a row
// span six elements, more than four lanes, and such batches keep the
// tested read a tap.
TEST(CpuBackend, ClampedBatchesOnlyWhereARowOfTapsSpansABatch) {
  Table2D<Attrib1f> image(64, 64);
  image.assign(std::vector<float>(64 * 64, 1.0f));
  Program seven = row_of_taps(image, -3, 3);
  auto ir_at = [&](cpu::Width width) {
    Options o;
    o.set(cpu::Options{.width = width});
    return kernel_for(seven, backend("cpu", o))->listing();
  };
  std::string four = ir_at(cpu::Width::Lanes4), eight = ir_at(cpu::Width::Lanes8);
  EXPECT_EQ(blocks(four, "batch.clamped"), "") << four;
  std::string clamped = blocks(eight, "batch.clamped");
  EXPECT_EQ(count(clamped, "call <8 x float> @llvm.masked.load.v8f32"), 2u) << eight;
  EXPECT_EQ(gathers(clamped), 0u) << eight;
}

// A run that compiles says where the time went: the passes, then the
// backend's phases, adding up to no more than the whole.
TEST(CpuBackend, CompilePhasesAddUpToTheCompile) {
  std::string empty = testing::TempDir() + "/sh_compile_phases_test";
  std::filesystem::remove_all(empty);
  setenv("SH_CACHE_DIR", empty.c_str(), 1);  // a compile, not a load
  Options o;
  o.set(cpu::Options{.width = cpu::Width::Lanes8});
  o.optimize = true;
  Attrib1f k = 3.0f;
  const float c = fresh_constant();  // a compile in this process too
  Program p = SH_BEGIN_PROGRAM("phases") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * k + c;
  } SH_END;
  Channel<Attrib1f> x(std::vector<float>{1, 2}), y;
  RunStats s = run(p, {x}, {y}, backend("cpu", o));
  ASSERT_TRUE(s.compiled);
  ASSERT_GE(s.compile_phases.size(), 6u);
  EXPECT_EQ(s.compile_phases.front().name, "passes");
  double sum = 0;
  for (const CompilePhase& phase : s.compile_phases) sum += phase.ms;
  EXPECT_LE(sum, s.compile_ms + 1e-6);
  EXPECT_GT(sum, 0.0);
  EXPECT_GT(s.compile_cpu_ms, 0.0);
  unsetenv("SH_CACHE_DIR");
  std::filesystem::remove_all(empty);
}

TEST(CpuBackend, WidthSettingPicksTheLanesAndRejectsOthers) {
  for (const char* width : {"4", "16"}) {
    Options o;
    o.set("width", width);  // the string form: the cpu backend owns "width"
    std::string ir = kernel_for(polynomial(), backend("cpu", o))->listing();
    EXPECT_NE(ir.find(std::string("<") + width + " x float>"), std::string::npos) << width;
  }
  Options bad;
  try {
    bad.set("width", "7");
    FAIL() << "width 7 was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("\"width\" is \"7\""), std::string::npos) << e.what();
  }
  Options typed;
  typed.set(cpu::Options{.width = static_cast<cpu::Width>(7)});
  EXPECT_THROW(kernel_for(polynomial(), backend("cpu", typed)), Error);
  try {
    bad.set("cpu.lanes", "8");
    FAIL() << "an unknown setting was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the cpu backend has no setting 'lanes'"), std::string::npos) << e.what();
  }
}

TEST(CpuBackend, OptionsHaveAStringFormAndVariantsCoverEveryWidth) {
  Options o;
  o.set("width", "scalar").set("tables", "fetched").set("stores", "streamed");
  cpu::Options mine = o.get<cpu::Options>();
  EXPECT_EQ(mine.width, cpu::Width::Scalar);
  EXPECT_EQ(mine.tables, cpu::Tables::Fetched);
  EXPECT_EQ(mine.stores, cpu::Stores::Streamed);
  EXPECT_EQ(mine.settings(), (Settings{{"stores", "streamed"}, {"tables", "fetched"}, {"width", "scalar"}}));
  EXPECT_EQ(cpu::Options{}.settings(), Settings{}) << "defaults are not spelt out";
  try {
    o.set("stores", "uncached");
    FAIL() << "an unknown kind of stores was accepted";
  } catch (const Error& e) {
    std::string said = e.what();
    EXPECT_NE(said.find("\"stores\" is \"uncached\"; expected auto, cached or streamed"), std::string::npos) << said;
  }
  std::vector<std::string> widths, stores, isas;
  for (const BackendInfo& b : backends())
    if (b.name == "cpu")
      for (const Backend::Variant& v : b.variants) {
        widths.push_back(v.options.settings()["width"]);
        stores.push_back(v.options.settings()["stores"]);
        isas.push_back(v.options.settings()["isa"]);
      }
  std::vector<std::string> expected_widths{"scalar", "4", "8", "16", "16", "scalar", "16"};
  std::vector<std::string> expected_stores(7), expected_isas(7);
  expected_stores[4] = "streamed";
  // The levels' variants where the backend compiles for them.
  auto compiles_for = [](const char* level) {
    try {
      Options at_level;
      return find_backend("cpu").lanes(at_level.set("isa", level)) > 0;
    } catch (const Error&) {
      return false;
    }
  };
  for (auto [level, width] : {std::pair{"sse4.2", "4"}, std::pair{"avx2", "8"}})
    if (compiles_for(level)) {
      expected_widths.push_back(width);
      expected_stores.emplace_back();
      expected_isas.push_back(level);
    }
  EXPECT_EQ(widths, expected_widths);
  EXPECT_EQ(stores, expected_stores);
  EXPECT_EQ(isas, expected_isas);
}

// A level outside the enumeration (a typed option set by a cast) is refused
// by name; it read past the table of levels and crashed.
TEST(CpuBackend, AnIsaThatIsNoLevelIsRefused) {
  Options o;
  o.set(sh::cpu::Options{.isa = static_cast<sh::cpu::Isa>(9)});
  Program p = SH_BEGIN_PROGRAM("levelled") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x + 1.0f;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1}), out;
  try {
    run(p, {in}, {out}, backend("cpu", o));
    ADD_FAILURE() << "isa 9 was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("isa 9 is none of host, sse4.2, avx2, avx512"), std::string::npos) << e.what();
  }
}

// A kernel for an x86-64 level runs that level's lowering, whatever the
// host has beyond it: the level's widest vectors by default, and, below
// AVX-512, a gather a lane at a time.  A level the host lacks is refused
// by name.
TEST(CpuBackend, IsaLevelsSetTheWidthAndTheLoweringAndTheHostMustHaveThem) {
  Options o;
  o.set("isa", "avx2");
  EXPECT_EQ(o.get<cpu::Options>().isa, cpu::Isa::Avx2);
  EXPECT_EQ(o.get<cpu::Options>().settings(), (Settings{{"isa", "avx2"}}));
  try {
    o.set("isa", "avx3");
    FAIL() << "an unknown level was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("\"isa\" is \"avx3\"; expected host, sse4.2, avx2 or avx512"),
              std::string::npos)
        << e.what();
  }
  Table1D<Attrib1f> table(64);
  Program scattered = read_at_input(table, "scattered");
  // Whether the host has a level, as far as the compiler's CPU tests tell
  // (they do not name every feature of a level: where they see all they
  // name, and the backend refuses, the test says so).
  struct Level {
    const char* name;
    const char* feature;  // one the level needs
    bool lacks, has;
    int lanes;
  };
  bool sse42 = __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("ssse3") && __builtin_cpu_supports("popcnt");
  bool avx2 = sse42 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
              __builtin_cpu_supports("bmi2");
  bool avx512 = avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
                __builtin_cpu_supports("avx512cd");
  for (Level level : {Level{"sse4.2", "sse4.2", !__builtin_cpu_supports("sse4.2"), sse42, 4},
                      Level{"avx2", "avx2", !__builtin_cpu_supports("avx2"), avx2, 8},
                      Level{"avx512", "avx512f", !__builtin_cpu_supports("avx512f"), avx512, 16}}) {
    Options at_level;
    at_level.set("isa", level.name);
    if (!level.has && !level.lacks) continue;
    if (level.lacks) {
      try {
        kernel_for(polynomial(), backend("cpu", at_level));
        ADD_FAILURE() << level.name << " was compiled on a host without it";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("this host lacks"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(level.feature), std::string::npos) << e.what();
      }
      continue;
    }
    EXPECT_EQ(find_backend("cpu").lanes(at_level), level.lanes) << level.name;
    at_level.set("width", "16");
    std::string ir = kernel_for(scattered, backend("cpu", at_level))->listing();
    // (LLVM may copy the loop, and the gather with it.)
    bool hardware = level.lanes == 16;
    EXPECT_EQ(count(ir, "call <16 x float> @llvm.masked.gather") > 0, hardware) << level.name << ir;
    EXPECT_EQ(count(ir, "call fastcc <16 x float> @\"sh_lane_loads") > 0, !hardware) << level.name << ir;
  }
}

// A full batch of an output is stored past the cache where the run asks
// (an output too large for the cache, or stores=streamed) and the batch
// starts on a multiple of its size, up to a line: at 16 lanes a float's
// batch (64 bytes) and a float4's (256), at 4 lanes a float4's (64) but
// not a float's (16 bytes, a quarter of a line).  One test of the run's
// ask and the batches' places serves every output.  A fence before the
// kernel returns orders them.  Scalar kernels, kernels with loops (whose
// time goes to the loops) and stores=cached have none.  Where the host is
// not x86 there are none either.
TEST(CpuBackend, FullBatchesOfOutputsStorePastTheCacheWhereAsked) {
  Program p = SH_BEGIN_PROGRAM("two_outputs") {
    InputAttrib1f x;
    OutputAttrib1f one;
    OutputAttrib4f four;
    one = x * 2.0f;
    four = join(join(x, x + 1.0f), join(x + 2.0f, x + 3.0f));
  } SH_END;
  auto listing = [&](cpu::Width width, cpu::Stores stores) {
    Options o;
    o.set(cpu::Options{.width = width, .stores = stores});
    return kernel_for(p, backend("cpu", o))->listing();
  };
  auto streamed = [](const std::string& ir) { return count(ir, "!nontemporal"); };
  auto fences = [](const std::string& ir) { return count(ir, "call void @llvm.x86.sse.sfence()"); };
#if defined(__x86_64__)
  std::string w16 = listing(cpu::Width::Lanes16, cpu::Stores::Auto);
  EXPECT_EQ(streamed(w16), 2u) << w16;
  EXPECT_EQ(count(w16, "align 64, !nontemporal"), 2u) << "each on a line: " << w16;
  EXPECT_EQ(fences(w16), 1u) << w16;
  EXPECT_EQ(count(w16, "label %store.streamed, label %store.cached"), 1u) << w16;
  std::string w4 = listing(cpu::Width::Lanes4, cpu::Stores::Streamed);
  EXPECT_EQ(streamed(w4), 1u) << w4;
  EXPECT_EQ(fences(w4), 1u) << w4;
#endif
  Program looping = SH_BEGIN_PROGRAM("looping") {
    InputAttrib1f x;
    OutputAttrib1f one;
    one = x;
    SH_FOR(Attrib1f i = 0.0f, i < x, i += 1.0f) { one += i; } SH_ENDFOR;
  } SH_END;
  Options always;
  always.set(cpu::Options{.width = cpu::Width::Lanes16, .stores = cpu::Stores::Streamed});
  std::string cached = listing(cpu::Width::Lanes16, cpu::Stores::Cached);
  std::string scalar = listing(cpu::Width::Scalar, cpu::Stores::Streamed);
  std::string loops = kernel_for(looping, backend("cpu", always))->listing();
  for (const std::string& ir : {cached, scalar, loops}) {
    EXPECT_EQ(streamed(ir), 0u) << ir;
    EXPECT_EQ(fences(ir), 0u) << ir;
  }
}

// Each run says whether it wrote its outputs past the cache
// (cpu::RunDetails): where stores=streamed asks and the kernel can (no
// loops, lanes side by side), unless the caller reads an output back at
// once; a report line only where a run did.
TEST(CpuBackend, RunsSayWhetherTheyWroteTheirOutputsPastTheCache) {
  Program doubled = SH_BEGIN_PROGRAM("doubled") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f;
  } SH_END;
  Program looping = SH_BEGIN_PROGRAM("looping") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x;
    SH_FOR(Attrib1f i = 0.0f, i < x, i += 1.0f) { y += i; } SH_ENDFOR;
  } SH_END;
  const std::size_t n = 1000;
  std::vector<float> in(n, 3.0f), out(n);
  auto streamed = [&](const Program& p, cpu::Width width, cpu::Stores stores, bool read_back) {
    Options o;
    o.set(cpu::Options{.width = width, .stores = stores});
    RunArgs args;
    args.count = n;
    args.inputs.push_back({ir::Type{ir::Scalar::F32, 1}, n, in.data()});
    args.outputs.push_back({ir::Type{ir::Scalar::F32, 1}, n, out.data()});
    args.outputs[0].read_back = read_back;
    RunStats stats;
    kernel_for(p, backend("cpu", o))->run(args, stats);
    EXPECT_EQ(out[n - 1], 6.0f);  // 3 doubled; 3 + 0 + 1 + 2
    const auto* details = stats.details_as<cpu::RunDetails>();
    EXPECT_TRUE(details && details->runs == 1);
    return details ? details->streamed : 99u;
  };
#if defined(__x86_64__)
  EXPECT_EQ(streamed(doubled, cpu::Width::Lanes8, cpu::Stores::Streamed, false), 1u);
#endif
  EXPECT_EQ(streamed(doubled, cpu::Width::Lanes8, cpu::Stores::Streamed, true), 0u) << "read back at once";
  EXPECT_EQ(streamed(doubled, cpu::Width::Lanes8, cpu::Stores::Cached, false), 0u);
  EXPECT_EQ(streamed(doubled, cpu::Width::Lanes8, cpu::Stores::Auto, false), 0u) << "4000 bytes stay in the cache";
  EXPECT_EQ(streamed(doubled, cpu::Width::Scalar, cpu::Stores::Streamed, false), 0u);
  EXPECT_EQ(streamed(looping, cpu::Width::Lanes8, cpu::Stores::Streamed, false), 0u);
  cpu::RunDetails total;
  EXPECT_TRUE(total.describe().empty());
  total.runs = 3;
  total.streamed = 2;
  EXPECT_EQ(total.describe(), std::vector<std::string>{"2 of 3 runs wrote their outputs past the cache"});
}

// run_fused's producer writes each strip into a buffer its consumer reads
// at once: under stores=streamed only the consumer's runs, which write the
// outputs, stream.
TEST(CpuBackend, FusedStripsKeepTheProducersRowsInTheCache) {
  const int w = 64, h = 40;
  Table2D<Attrib1f> image(w, h), rows(w, h);
  image.assign(std::vector<float>(static_cast<std::size_t>(w) * h, 1.0f));
  Program along = SH_BEGIN_PROGRAM("along") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    out = image[at + ConstAttrib2i(-1, 0)] + image[at + ConstAttrib2i(1, 0)];
  } SH_END;
  Program down = SH_BEGIN_PROGRAM("down") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    out = rows[at + ConstAttrib2i(0, -1)] + rows[at + ConstAttrib2i(0, 1)];
  } SH_END;
  Options o;
  o.set(cpu::Options{.width = cpu::Width::Lanes8, .stores = cpu::Stores::Streamed});
  Channel<Attrib1f> out;
  out.shape(w, h);
  RunStats stats = run_fused(along, rows, down, {out}, backend("cpu", o), 8);
  ASSERT_EQ(stats.strips, 5u);
  EXPECT_EQ(out.values(), std::vector<float>(static_cast<std::size_t>(w) * h, 4.0f));
  const auto* details = stats.details_as<cpu::RunDetails>();
  ASSERT_NE(details, nullptr);
  EXPECT_EQ(details->runs, 10u);
#if defined(__x86_64__)
  EXPECT_EQ(details->streamed, 5u);
#endif
}

// Streamed or not, the outputs are the same: rows of 20 elements, whose
// float batches start 0, 16, 32 or 48 bytes past a line (those of four
// floats always on one: a row that does not start on a line stores both
// as any store), and end in batches of four.
TEST(CpuBackend, StreamedStoresWriteWhatCachedOnesDo) {
  Program p = SH_BEGIN_PROGRAM("placed") {
    OutputAttrib1f one;
    OutputAttrib4f four;
    Attrib2i at = position<2>();
    Attrib1f x = at(0).cast<float>() * 0.5f + at(1).cast<float>();
    one = x * x;
    four = join(join(x, x + 1.0f), join(at(0).cast<float>(), at(1).cast<float>()));
  } SH_END;
  auto outputs = [&](cpu::Stores stores) {
    Options o;
    o.threads = 2;
    o.set(cpu::Options{.width = cpu::Width::Lanes16, .stores = stores});
    Channel<Attrib1f> one;
    Channel<Attrib4f> four;
    one.shape(20, 301);
    four.shape(20, 301);
    run(p, {}, {one, four}, backend("cpu", o));
    return std::pair(one.values(), four.values());
  };
  auto cached = outputs(cpu::Stores::Cached);
  EXPECT_EQ(cached.first.size(), 20u * 301u);
  EXPECT_EQ(cached.first[20 * 300 + 19], (9.5f + 300.0f) * (9.5f + 300.0f));
  EXPECT_EQ(outputs(cpu::Stores::Streamed), cached);
}

TEST(CpuBackend, ReadsThroughSourcesWithFetchedTablesOnOneThread) {
  Options o;
  o.threads = 8;
  o.set(cpu::Options{.width = cpu::Width::Lanes4});
  ASSERT_TRUE(find_backend("cpu").read_through_sources(o));
  EXPECT_EQ(o.get<cpu::Options>().tables, cpu::Tables::Fetched);
  EXPECT_EQ(o.get<cpu::Options>().width, cpu::Width::Lanes4) << "the other options stay";
  EXPECT_EQ(o.threads, 1);
}

TEST(CpuBackend, CompilesOncePerProgramAndOptions) {
  const float last = fresh_constant();  // a program no earlier run compiled
  Program p = polynomial(last);
  Channel<Attrib1f> x(std::vector<float>{1, 2}), y;
  Options o;
  o.threads = 1;
  run(p, {x}, {y}, backend("cpu", o));
  RunStats again = run(polynomial(last), {x}, {y}, backend("cpu", o));  // same IR, recorded again
  EXPECT_FALSE(again.compiled);
  o.threads = 2;
  RunStats other = run(p, {x}, {y}, backend("cpu", o));
  EXPECT_TRUE(other.compiled) << "options are part of the key";
  EXPECT_EQ(y[1], 16 + last);
}

TEST(CpuBackend, EveryThreadCountGivesTheSameResult) {
  Program p = SH_BEGIN_PROGRAM("divergent") {
    InputAttrib1f n;
    OutputAttrib1f r;
    r = 0.0f;
    SH_FOR(Attrib1f i = 0.0f, i < n, i += 1.0f) { r += sin(i); } SH_ENDFOR;
  } SH_END;
  std::vector<float> ns;
  for (int i = 0; i < 20000; ++i) ns.push_back(static_cast<float>(i % 97));
  Channel<Attrib1f> in(ns), one, two, all;
  Options o;
  o.threads = 1;
  run(p, {in}, {one}, backend("cpu", o));
  o.threads = 2;
  run(p, {in}, {two}, backend("cpu", o));
  run(p, {in}, {all}, backend("cpu"));
  EXPECT_EQ(one.values(), two.values());
  EXPECT_EQ(one.values(), all.values());
}

TEST(CpuBackend, RunawayLoopNamesTheElementAndLoop) {
  Program p = SH_BEGIN_PROGRAM("runaway") {
    InputAttrib1f x;
    OutputAttrib1f r;
    r = x;
    SH_WHILE(r > 0.0f) { r = r + 1.0f; } SH_ENDWHILE;
  } SH_END;
  std::vector<float> xs(1000, -1.0f);
  xs[737] = 1.0f;
  Channel<Attrib1f> in(xs), out;
  Options o;
  o.max_loop_iterations = 5000;
  try {
    run(p, {in}, {out}, backend("cpu", o));
    FAIL();
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("runaway"), std::string::npos) << m;
    EXPECT_NE(m.find("element 737"), std::string::npos) << m;
    EXPECT_NE(m.find("loop test-first"), std::string::npos) << m;
  }
}

TEST(CpuBackend, TableReadsStayInsideTheBufferForAnyIndex) {
  Table1D<Attrib1i> t(3);
  t.assign({10, 20, 30});
  Program p = SH_BEGIN_PROGRAM("reads") {
    InputAttrib1f u;
    OutputAttrib1i a;
    OutputAttrib1i b;
    a = t[u];
    b = t(u);
  } SH_END;
  std::vector<float> us = {-1e30f, -1.f, 0.f, 0.5f, 1.f, 2.f, 3.f, 1e30f, std::numeric_limits<float>::quiet_NaN()};
  Channel<Attrib1f> in(us);
  Channel<Attrib1i> a, b, ra, rb;
  run(p, {in}, {a, b}, backend("cpu"));
  run(p, {in}, {ra, rb}, backend("interp"));
  EXPECT_EQ(a.values(), ra.values());
  EXPECT_EQ(b.values(), rb.values());
}

// n floats that end exactly where an inaccessible page begins: a kernel
// that reads or writes one lane past the stream's end faults.
class GuardedFloats {
 public:
  explicit GuardedFloats(std::size_t n) : page_(static_cast<std::size_t>(sysconf(_SC_PAGESIZE))) {
    std::size_t pages = (n * sizeof(float) + page_ - 1) / page_ + 1;
    bytes_ = pages * page_;
    base_ = static_cast<char*>(mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    mprotect(base_ + bytes_ - page_, page_, PROT_NONE);
    data_ = reinterpret_cast<float*>(base_ + bytes_ - page_) - n;
  }
  ~GuardedFloats() { munmap(base_, bytes_); }
  float* data() { return data_; }

 private:
  std::size_t page_, bytes_ = 0;
  char* base_ = nullptr;
  float* data_ = nullptr;
};

TEST(CpuBackend, StreamTailTouchesNothingPastTheEnd) {
  Program p = SH_BEGIN_PROGRAM("tail") {
    InputAttrib3f v;
    OutputAttrib3f r;
    r = v * 2.0f;
  } SH_END;
  ir::Type vec3{ir::Scalar::F32, 3};
  for (const char* width : {"scalar", "4", "8", "16"}) {
    Options o;
    o.set("cpu.width", width);
    std::shared_ptr<Kernel> kernel = kernel_for(p, backend("cpu", o));
    for (std::size_t n : {1, 5, 15, 16, 17, 35}) {
      GuardedFloats in(3 * n), out(3 * n);
      for (std::size_t i = 0; i < 3 * n; ++i) in.data()[i] = static_cast<float>(i);
      RunArgs args;
      args.count = n;
      args.inputs.push_back({vec3, n, in.data()});
      args.outputs.push_back({vec3, n, out.data()});
      RunStats stats;
      kernel->run(args, stats);
      for (std::size_t i = 0; i < 3 * n; ++i) ASSERT_EQ(out.data()[i], 2.0f * i) << "width " << width << ", n " << n;
    }
  }
}

TEST(CpuBackend, SpmdKernelRefusesATablePastThirtyTwoBitIndices) {
  Table2D<Attrib1f> t(1, 1);
  Program p = SH_BEGIN_PROGRAM("big_table") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = t[join(i, i)];
  } SH_END;
  Options o;
  o.set(cpu::Options{.width = cpu::Width::Lanes8});
  std::shared_ptr<Kernel> kernel = kernel_for(p, backend("cpu", o));
  float one = 1.0f;
  std::int32_t index = 0;
  RunArgs args;
  args.count = 1;
  args.inputs.push_back({ir::Type{ir::Scalar::I32, 1}, 1, &index});
  args.outputs.push_back({ir::Type{ir::Scalar::F32, 1}, 1, &one});
  // Described as 2^32 values; refused before any is read.
  args.tables.push_back(TableView{ir::Type{ir::Scalar::F32, 1}, 2, {1 << 16, 1 << 16, 1}, &one, nullptr, 1, 1});
  RunStats stats;
  try {
    kernel->run(args, stats);
    FAIL() << "a table of 2^32 values was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("4294967296 values"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("width=scalar"), std::string::npos) << e.what();
  }
}

// A table held elsewhere, in spans of 3 elements: every read the kernel
// makes is either a span asked for or counted as served from the last one.
class SpansOfThree : public TableSource {
 public:
  explicit SpansOfThree(std::vector<float> values) : values_(std::move(values)) {}
  Span span_of(std::size_t flat) override {
    ++spans;
    std::size_t first = flat / 3 * 3;
    return {values_.data() + first, first, std::min(first + 3, values_.size())};
  }
  void count_reads(std::size_t reads) override { inline_reads += reads; }
  std::size_t spans = 0, inline_reads = 0;

 private:
  std::vector<float> values_;
};

// Two tables of one element type, whose reads share code in SPMD modes:
// each read goes to its own table's source.
TEST(CpuBackend, FetchedTablesReadThroughASourceAtEveryWidth) {
  std::vector<float> values(100), others(100);
  for (std::size_t k = 0; k < values.size(); ++k) {
    values[k] = 0.5f * static_cast<float>(k);
    others[k] = 1000.0f - static_cast<float>(k);
  }
  Table1D<Attrib1f> table(100), other(100);
  table.assign(values);
  other.assign(others);
  Program p = SH_BEGIN_PROGRAM("through_source") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = table[i];
    SH_IF(i % 3 == 0) { y += table[i + 1]; } SH_ENDIF;  // a read only some lanes make
    y += other[i + 40];
  } SH_END;
  std::vector<std::int32_t> is;
  // Neighbours reading neighbours, then scattered reads; clamped at both ends too.
  for (int k = 0; k < 1000; ++k) is.push_back(k < 300 ? k / 2 - 10 : (k * 37) % 120 - 10);
  std::size_t reads = 0;
  std::vector<float> expected;
  for (std::int32_t i : is) {
    auto at = [](const std::vector<float>& v, std::int32_t k) {
      return v[static_cast<std::size_t>(std::clamp(k, 0, 99))];
    };
    expected.push_back((i % 3 == 0 ? at(values, i) + at(values, i + 1) : at(values, i)) + at(others, i + 40));
    reads += i % 3 == 0 ? 2 : 1;
  }
  for (const char* width : {"scalar", "4", "16"}) {
    Options o;
    o.set("width", width).set("tables", "fetched");
    o.threads = 1;
    std::shared_ptr<Kernel> kernel = kernel_for(p, backend("cpu", o));
    std::vector<float> out(is.size());
    SpansOfThree source(values), other_source(others);
    RunArgs args;
    args.count = is.size();
    args.inputs.push_back({ir::Type{ir::Scalar::I32, 1}, is.size(), is.data()});
    args.outputs.push_back({ir::Type{ir::Scalar::F32, 1}, out.size(), out.data()});
    ir::Type f32{ir::Scalar::F32, 1};
    args.tables.push_back(TableView{f32, 1, {100, 1, 1}, nullptr, nullptr, 7, 1, &source});
    args.tables.push_back(TableView{f32, 1, {100, 1, 1}, nullptr, nullptr, 8, 1, &other_source});
    RunStats stats;
    kernel->run(args, stats);
    EXPECT_EQ(out, expected) << width;
    EXPECT_EQ(source.spans + source.inline_reads, reads) << width;
    if (std::string(width) != "scalar") {
      std::istringstream ir(kernel->listing());
      std::size_t rounds = 0;
      for (std::string line; std::getline(ir, line);)
        rounds += line.starts_with("define") && line.find("@sh_fetch_lanes.") != std::string::npos;
      EXPECT_EQ(rounds, 1u) << width << ": one rounds function for both tables\n" << kernel->listing();
    }
    EXPECT_EQ(other_source.spans + other_source.inline_reads, is.size()) << width;
    EXPECT_GT(source.inline_reads, 0u) << width << ": no read was served from a span";
    Options memory = o;
    memory.set("tables", "memory");
    try {
      kernel_for(p, backend("cpu", memory))->run(args, stats);
      ADD_FAILURE() << "a kernel that loads read a table it does not hold";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("tables=fetched"), std::string::npos) << e.what();
    }
  }
}

TEST(CpuObjectCache, SecondCompileLoadsMachineCodeAndABadFileIsRecompiled) {
  namespace fs = std::filesystem;
  fs::path dir = fs::path(testing::TempDir()) / "sh_object_cache_test";
  fs::remove_all(dir);
  setenv("SH_CACHE_DIR", dir.c_str(), 1);
  sh::Program p = polynomial();
  sh::ir::Program ir = sh::optimize(p.ir());
  sh::Backend& cpu = sh::find_backend("cpu");
  auto first = cpu.compile(ir, sh::Options{});
  EXPECT_EQ(first->listing().find("loaded from the object cache"), std::string::npos);
  std::size_t objects = 0;
  for (const auto& f : fs::directory_iterator(dir)) objects += f.path().extension() == ".o";
  EXPECT_EQ(objects, 1u);
  auto second = cpu.compile(ir, sh::Options{});
  EXPECT_NE(second->listing().find("loaded from the object cache"), std::string::npos);
  EXPECT_FALSE(first->loaded_from_disk());
  EXPECT_TRUE(second->loaded_from_disk());
  auto names = [](const sh::Kernel& k) {
    std::vector<std::string> out;
    for (const sh::CompilePhase& phase : k.compile_phases()) out.push_back(phase.name);
    return out;
  };
  EXPECT_EQ(names(*first), (std::vector<std::string>{"cache key", "lowering", "LLVM optimisation", "JIT setup",
                                                     "machine code", "stored", "linked"}));
  EXPECT_EQ(names(*second), (std::vector<std::string>{"cache key", "JIT setup", "object from the cache, linked"}))
      << "a hit neither lowers nor runs LLVM";
  EXPECT_NE(second->listing().find("define void @sh_kernel"), std::string::npos) << "the stored listing comes back";

  sh::Channel<sh::Attrib1f> x(std::vector<float>{1, 2}), y1, y2;
  auto run_with = [&](sh::Kernel& k, sh::Channel<sh::Attrib1f>& out) {
    out.resize(2);
    std::shared_ptr<sh::detail::Buffer> in = x, o = out;
    sh::RunArgs a;
    a.count = 2;
    a.inputs.push_back({in->type(), 2, in->data()});
    a.outputs.push_back({o->type(), 2, o->data()});
    sh::RunStats s;
    k.run(a, s);
  };
  run_with(*second, y2);
  EXPECT_EQ(y2[1], 17.f);

  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().extension() == ".o") std::ofstream(f.path(), std::ios::binary) << "not an object file";
  auto third = cpu.compile(ir, sh::Options{});
  run_with(*third, y1);
  EXPECT_EQ(y1[1], 17.f) << "a corrupt cache entry is compiled afresh";
  // Bytes changed inside a whole object file (its code, say) are found by
  // the entry's checksum: compiled afresh, not loaded and run.
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().extension() == ".o") {
      std::fstream o(f.path(), std::ios::in | std::ios::out | std::ios::binary);
      o.seekp(static_cast<std::streamoff>(fs::file_size(f.path()) / 2));
      o.write("\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff", 16);
    }
  auto flipped = cpu.compile(ir, sh::Options{});
  EXPECT_EQ(flipped->listing().find("loaded from the object cache"), std::string::npos);
  y1[1] = 0;
  run_with(*flipped, y1);
  EXPECT_EQ(y1[1], 17.f);
  // An entry that exists but does not open (here a socket in its place;
  // elsewhere another user's file) is compiled afresh too.
  auto after = cpu.compile(ir, sh::Options{});
  EXPECT_NE(after->listing().find("loaded from the object cache"), std::string::npos)
      << "the fresh compile took the damaged entry's place";
  int in_the_way = socket(AF_UNIX, SOCK_STREAM, 0);
  std::size_t replaced = 0;
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().extension() == ".o") {
      ++replaced;
      fs::remove(f.path());
      sockaddr_un at{};
      at.sun_family = AF_UNIX;
      std::strncpy(at.sun_path, f.path().c_str(), sizeof at.sun_path - 1);
      ASSERT_EQ(bind(in_the_way, reinterpret_cast<const sockaddr*>(&at), sizeof at), 0) << f.path();
    }
  ASSERT_EQ(replaced, 1u);
  auto fourth = cpu.compile(ir, sh::Options{});
  EXPECT_EQ(fourth->listing().find("loaded from the object cache"), std::string::npos);
  y1[1] = 0;
  run_with(*fourth, y1);
  EXPECT_EQ(y1[1], 17.f) << "an unreadable cache entry is compiled afresh";
  close(in_the_way);
  unsetenv("SH_CACHE_DIR");
  fs::remove_all(dir);
}

// A run that made its kernel says whether it compiled it or loaded its
// machine code from the disk cache: a program of another name, the same
// computation, misses this process's kernels but finds the first's object.
TEST(CpuObjectCache, ARunSaysItsKernelCameFromTheDisk) {
  namespace fs = std::filesystem;
  fs::path dir = fs::path(testing::TempDir()) / fresh_name("sh_from_disk_test");
  fs::remove_all(dir);
  setenv("SH_CACHE_DIR", dir.c_str(), 1);
  float constant = fresh_constant();
  auto program = [&](const std::string& name) {
    return SH_BEGIN_PROGRAM(name) {
      sh::InputAttrib1f x;
      sh::OutputAttrib1f y;
      y = x * constant;
    } SH_END;
  };
  sh::Channel<sh::Attrib1f> x(std::vector<float>{1, 2}), y1, y2;
  sh::RunStats made = sh::run(program("made"), {x}, {y1}, sh::backend("cpu"));
  sh::RunStats loaded = sh::run(program("loaded"), {x}, {y2}, sh::backend("cpu"));
  EXPECT_TRUE(made.compiled);
  EXPECT_FALSE(made.from_disk);
  EXPECT_TRUE(loaded.compiled) << "another name: not this process's kernel";
  EXPECT_TRUE(loaded.from_disk);
  EXPECT_EQ(y2[1], 2 * constant);
  unsetenv("SH_CACHE_DIR");
  fs::remove_all(dir);
}

// With SH_PERF_JITDUMP=1 a compiled kernel is described to perf: LLVM's
// jitdump file for this process, under $JITDUMPDIR, grows by a record that
// names the kernel's entry; the kernel still runs.  The listener is one for
// the process and keeps the directory it first saw, so the directory is
// this process's own and stays: a repeated run appends to the same file.
TEST(CpuBackend, WithPerfJitdumpTheKernelIsDescribedToPerf) {
  namespace fs = std::filesystem;
  struct Unset {
    ~Unset() {
      for (const char* name : {"SH_PERF_JITDUMP", "SH_CACHE_DIR", "JITDUMPDIR"}) unsetenv(name);
    }
  } unset;
  fs::path dir = fs::path(testing::TempDir()) / ("sh_jitdump_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  setenv("JITDUMPDIR", dir.c_str(), 1);
  setenv("SH_PERF_JITDUMP", "1", 1);
  setenv("SH_CACHE_DIR", "off", 1);
  std::string dump_name = "jit-" + std::to_string(getpid()) + ".dump";
  auto dump = [&] {
    std::string contents;
    for (const auto& entry : fs::recursive_directory_iterator(dir))
      if (entry.path().filename() == dump_name) {
        std::ifstream in(entry.path(), std::ios::binary);
        contents.assign(std::istreambuf_iterator<char>(in), {});
      }
    return contents;
  };
  std::size_t before = dump().size();
  float constant = fresh_constant();
  sh::Program p = SH_BEGIN_PROGRAM("described") {
    sh::InputAttrib1f x;
    sh::OutputAttrib1f y;
    y = x * constant;
  } SH_END;
  sh::Channel<sh::Attrib1f> x(std::vector<float>{1, 2}), y;
  sh::run(p, {x}, {y}, sh::backend("cpu"));
  EXPECT_EQ(y[1], 2 * constant);
  std::string after = dump();
  ASSERT_GT(after.size(), before) << "no record added to " << dump_name << " under " << dir;
  EXPECT_NE(after.find("sh_kernel", before), std::string::npos) << "the new records do not name the kernel";
}

// Loops long enough that the optimised kernel is cut into parts: four data
// dependent loops of 600 arithmetic operations each, reading a table at
// lanes' own places.
sh::Program large_kernel(const sh::Table1D<sh::Attrib1f>& table) {
  return SH_BEGIN_PROGRAM("large") {
    sh::InputAttrib1f x;
    sh::OutputAttrib1f y;
    sh::Attrib1f sum = 0.0f;
    for (int loop = 0; loop < 4; ++loop) {
      sh::Attrib1f v = x + static_cast<float>(loop);
      SH_FOR(sh::Attrib1i i = 0, i < x.cast<std::int32_t>() % (3 + loop) + 1, i += 1) {
        v += table[(i * 7 + x.cast<std::int32_t>()) % 64];
        for (int k = 0; k < 200; ++k) v = v * (0.5f + 1.0f / (k + 3)) + static_cast<float>(k % 7) - v * v * 0.001f;
      } SH_ENDFOR;
      sum += v;
    }
    y = sum;
  } SH_END;
}

std::vector<float> run_large(sh::Kernel& k, const sh::Table1D<sh::Attrib1f>& table, const std::vector<float>& xs) {
  std::vector<float> in = xs, out(xs.size());
  sh::RunArgs a;
  a.count = xs.size();
  a.inputs.push_back({sh::ir::Type{sh::ir::Scalar::F32, 1}, xs.size(), in.data()});
  a.outputs.push_back({sh::ir::Type{sh::ir::Scalar::F32, 1}, xs.size(), out.data()});
  a.tables.push_back(sh::TableView{sh::ir::Type{sh::ir::Scalar::F32, 1}, 1, {64, 1, 1}, table.storage()->buffer.data(), nullptr,
                                   table.storage()->id, 1, nullptr});
  sh::RunStats s;
  k.run(a, s);
  return out;
}

// The loops outlined from the kernel, by the functions the listing defines.
std::size_t outlined(const std::string& listing) {
  std::size_t n = 0;
  std::istringstream lines(listing);
  for (std::string line; std::getline(lines, line);)
    n += line.rfind("define ", 0) == 0 && line.find("@sh_kernel.part") != std::string::npos;
  return n;
}

TEST(CpuObjectCache, LargeKernelCompiledInPartsOnThreadsRunsAsOneWholeAndComesBackFromTheCache) {
  namespace fs = std::filesystem;
  fs::path dir = fs::path(testing::TempDir()) / "sh_object_parts_test";
  fs::remove_all(dir);
  sh::Table1D<sh::Attrib1f> table(64);
  std::vector<float> entries;
  for (int i = 0; i < 64; ++i) entries.push_back(static_cast<float>(i) * 0.125f);
  table.assign(entries);
  sh::ir::Program ir = sh::passes::legalize(sh::optimize(large_kernel(table).ir()));
  sh::Backend& cpu = sh::find_backend("cpu");
  std::vector<float> xs;
  for (int i = 0; i < 100; ++i) xs.push_back(static_cast<float>(i % 13) * 0.25f);
  // The parts' threads side by side on any machine (the parts are as many
  // as the arena's threads).
  tbb::global_control allow(tbb::global_control::max_allowed_parallelism, 4);
  for (auto [width, threads] : {std::pair{"scalar", 2}, std::pair{"8", 4}, std::pair{"16", 2}}) {
    sh::Options whole, parts;
    whole.set("width", width);
    whole.threads = 1;
    parts.set("width", width);
    setenv("SH_CACHE_DIR", "off", 1);
    auto one = cpu.compile(ir, whole);
    EXPECT_EQ(one->listing().find("sh_kernel.part"), std::string::npos) << width << ": one thread, one part";
    std::vector<float> want = run_large(*one, table, xs);
    setenv("SH_CACHE_DIR", dir.c_str(), 1);
    auto split = tbb::task_arena(threads).execute([&] { return cpu.compile(ir, parts); });
    EXPECT_GE(outlined(split->listing()), static_cast<std::size_t>(threads - 1))
        << width << ": loops outlined, a function or more per part";
    EXPECT_EQ(run_large(*split, table, xs), want) << width;
    auto loaded = cpu.compile(ir, parts);
    EXPECT_NE(loaded->listing().find("loaded from the object cache"), std::string::npos) << width;
    EXPECT_NE(loaded->listing().find("@sh_kernel.part("), std::string::npos) << width;
    EXPECT_EQ(run_large(*loaded, table, xs), want) << width;
    fs::remove_all(dir);
  }
  unsetenv("SH_CACHE_DIR");
}

// Without loops there is nothing to outline: on four threads the kernel
// is still one function, compiled whole, and runs as it does on one.
TEST(CpuObjectCache, LargeKernelWithoutLoopsStaysWhole) {
  sh::Program p = SH_BEGIN_PROGRAM("straight") {
    sh::InputAttrib1f x;
    sh::OutputAttrib1f y;
    sh::Attrib1f v = x;
    for (int k = 0; k < 700; ++k) v = v * (0.5f + 1.0f / (k + 3)) + static_cast<float>(k % 7) - v * v * 0.001f;
    y = v;
  } SH_END;
  sh::ir::Program ir = sh::passes::legalize(sh::optimize(p.ir()));
  sh::Backend& cpu = sh::find_backend("cpu");
  setenv("SH_CACHE_DIR", "off", 1);
  sh::Options one;
  one.threads = 1;
  auto whole = cpu.compile(ir, one);
  tbb::global_control allow(tbb::global_control::max_allowed_parallelism, 4);
  auto four = tbb::task_arena(4).execute([&] { return cpu.compile(ir, sh::Options{}); });
  unsetenv("SH_CACHE_DIR");
  EXPECT_GT(count(four->listing(), "\n  %"), 1200u) << "large enough to be split";
  EXPECT_EQ(outlined(four->listing()), 0u);
  std::vector<float> xs{0.5f, 1.0f, 2.0f, 3.0f};
  auto run_straight = [&](sh::Kernel& k) {
    std::vector<float> in = xs, out(xs.size());
    sh::RunArgs a;
    a.count = xs.size();
    a.inputs.push_back({sh::ir::Type{sh::ir::Scalar::F32, 1}, xs.size(), in.data()});
    a.outputs.push_back({sh::ir::Type{sh::ir::Scalar::F32, 1}, xs.size(), out.data()});
    sh::RunStats s;
    k.run(a, s);
    return out;
  };
  EXPECT_EQ(run_straight(*four), run_straight(*whole));
}

}  // namespace
