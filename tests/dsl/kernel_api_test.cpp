// The Kernel API (kernel_for, Kernel::run): arguments a caller built by
// hand are checked against the program on every backend but mpi (which
// would start MPI in this process; its kernels are wrapped alike), where
// a missing input, a short view or a domain of no rows crashed a backend
// and a view of another type gave wrong results without a word.  And what
// the process's kernels are keyed by.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include <sh/sh.hpp>
#include <sh/waves.hpp>

#include "../common/expect_error.hpp"
#include "../common/fresh.hpp"

namespace {

using namespace sh;

struct Case {
  const char* what;
  std::function<void(RunArgs&)> spoil;
  const char* says;
};

TEST(KernelApi, ArgumentsThatDoNotMatchTheProgramAreErrorsOnEveryBackend) {
  Table1D<Attrib1f> table(4);
  table.name("lookup").assign(std::vector<float>{1, 2, 3, 4});
  Attrib1f scale = 2.0f;
  Program p = SH_BEGIN_PROGRAM("by_hand") {
    InputAttrib1i i;
    InputAttrib1f x;
    OutputAttrib1f y;
    y = table[i] * scale + x;
  } SH_END;
  const ir::Program& ir = p.ir();
  std::vector<std::int32_t> is{0, 1, 2, 3};
  std::vector<float> xs{10, 20, 30, 40}, out(4), other(4);
  auto good = [&] {
    RunArgs a;
    a.count = 4;
    a.inputs = {{ir.type_of(ir.inputs[0]), 4, is.data()}, {ir.type_of(ir.inputs[1]), 4, xs.data()}};
    a.outputs = {{ir.type_of(ir.outputs[0]), 4, out.data()}};
    a.uniforms = {{2, 0, 0, 0}};
    TableView t;
    t.element = ir.tables[0].element;
    t.dims = {4, 1, 1};
    t.data = other.data();
    t.id = std::uint64_t{1} << 62;
    a.tables = {t};
    return a;
  };
  other = {1, 2, 3, 4};
  const std::vector<Case> cases = {
      {"an input left out", [](RunArgs& a) { a.inputs.pop_back(); },
       "1 inputs given where the program has 2"},
      {"an output too many", [&](RunArgs& a) { a.outputs.push_back(a.outputs[0]); }, "2 outputs given"},
      {"no uniforms", [](RunArgs& a) { a.uniforms.clear(); }, "0 uniforms given where the program has 1"},
      {"no tables", [](RunArgs& a) { a.tables.clear(); }, "0 tables given"},
      {"an input of another type", [](RunArgs& a) { a.inputs[1].type = ir::Type{ir::Scalar::F64, 1}; },
       "input 1 is f64 where the program's is f32"},
      {"a short output", [](RunArgs& a) { a.outputs[0].count = 2; },
       "output 0 holds 2 elements, fewer than the run's 4"},
      {"an input without memory", [](RunArgs& a) { a.inputs[0].data = nullptr; }, "input 0 has no memory"},
      {"a table of no elements", [](RunArgs& a) { a.tables[0].dims[0] = 0; },
       "table 0 has 0 elements along dimension 0"},
      {"a table of rank 2", [](RunArgs& a) { a.tables[0].rank = 2; },
       "table 0 is f32 of rank 2 where the program reads f32 of rank 1"},
      {"a table read given sums", [&](RunArgs& a) { a.tables[0].sums = other.data(); }, "it has no sums"},
      {"a table beyond its rank", [](RunArgs& a) { a.tables[0].dims[1] = 0; }, "beyond its rank"},
      {"a table without elements", [](RunArgs& a) { a.tables[0].data = nullptr; }, "table 0 has no elements"},
      {"a domain of no rows", [](RunArgs& a) { a.domain.extent = {4, 0, 1}; }, "must be 1 or more"},
      {"a domain too small", [](RunArgs& a) { a.domain.extent = {2, 1, 1}; },
       "run past the launch domain's 2 elements"},
  };
  for (const std::string& name : backend_names()) {
    if (name == "mpi") continue;
    std::shared_ptr<Kernel> kernel = kernel_for(p, backend(name));
    RunStats stats;
    RunArgs fine = good();
    kernel->run(fine, stats);
    EXPECT_EQ(out, (std::vector<float>{12, 24, 36, 48})) << name;
    for (const Case& c : cases) {
      RunArgs spoiled = good();
      c.spoil(spoiled);
      SCOPED_TRACE(name + ": " + c.what);
      expect_error([&] { kernel->run(spoiled, stats); }, {"program 'by_hand': Kernel::run: ", c.says});
    }
    Waves waves{nullptr, 5, {}};
    expect_error([&] { kernel->run_waves(fine, waves, stats); }, {"output 5 named for waves does not exist"});
  }
}

// A kernel's errors name its program, tables and variables, so programs of
// one structure under other names (the same program name, another table's)
// are kernels of their own: the second's errors named the first's table.
TEST(KernelApi, ProgramsOfOneStructureUnderOtherNamesAreKernelsOfTheirOwn) {
  const float added = fresh_constant();
  auto reader = [&](const Table1D<Attrib1f>& t) {
    return SH_BEGIN_PROGRAM("lookup") {
      InputAttrib1i i;
      OutputAttrib1f y;
      y = t[i] + added;
    } SH_END;
  };
  Table1D<Attrib1f> alpha(2), beta(2), gamma(2);
  alpha.name("alpha").assign(std::vector<float>{1, 2});
  beta.name("beta").assign(std::vector<float>{3, 4});
  gamma.name("alpha").assign(std::vector<float>{5, 6});
  Channel<Attrib1i> at(std::vector<std::int32_t>{1});
  Channel<Attrib1f> out;
  EXPECT_TRUE(run(reader(alpha), {at}, {out}, backend("interp")).compiled);
  EXPECT_TRUE(run(reader(beta), {at}, {out}, backend("interp")).compiled) << "another table's name";
  EXPECT_FALSE(run(reader(gamma), {at}, {out}, backend("interp")).compiled) << "the same names, another table";
  EXPECT_EQ(out[0], 6 + added);
}

}  // namespace
