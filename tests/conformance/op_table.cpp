// Every row of the op table (dsl/include/sh/ir/ops.def) on every scalar
// its domain takes, over the extreme values, against the interpreter's
// evaluator (ir::eval in double, rounded to the result type) within the
// row's ULP bound.  A new operation is held here to the interpreter on
// every other backend without a line of this file changing (any_lane,
// whose answer depends on other elements, by its bounds in
// lane_group.cpp).  On interp this checks only that the program runs: the
// evaluator's meanings are tested against <cmath> and values derived by
// hand in float_ops.cpp, integer_ops.cpp, mod_round.cpp and extremes.cpp,
// where a new operation needs its own case.
#include <map>

#include <sh/ir/eval.hpp>

#include "harness.hpp"

namespace conformance {
namespace {

using sh::ir::Op;
using sh::ir::Scalar;

constexpr int kWidth = 4;

std::vector<double> values_of(Scalar s) {
  switch (s) {
    case Scalar::F32: {
      std::vector<float> v = extreme_values<float>();
      return {v.begin(), v.end()};
    }
    case Scalar::F64: return extreme_values<double>();
    case Scalar::I32:
      return {0, 1, -1, 2, -2, 3, 7, -7, 100, -100, 46341, 65536, INT32_MAX, INT32_MIN, INT32_MIN + 1.0, INT32_MAX - 1.0};
    case Scalar::Bool: return {0, 1};
  }
  return {};
}

// Operand k of element e, component c: every pair of values meets in some
// element, and every component position sees every value.
double operand_value(const std::vector<double>& v, std::size_t e, int k, int c) {
  std::size_t n = v.size(), i = e / n, j = e % n;
  std::size_t at[3] = {i + c, j + 2 * c, i + j + c};
  return v[at[k] % n];
}

bool ordinary(double v) {
  double a = std::fabs(v);
  return std::isfinite(v) && (a == 0 || (a > 1e-30 && a < 1e30));
}

struct Row {
  Op op;
  sh::ir::VarId out;
};

// One program per operand scalar: every operation its domain allows, each
// into its own output.
struct TableProgram {
  sh::Program program;
  std::vector<Row> rows;
};

TableProgram program_for(Scalar s) {
  sh::ir::Program p;
  p.name = std::string("op_table_") + sh::ir::scalar_name(s);
  sh::ir::Type t{s, kWidth};
  std::vector<sh::ir::VarId> args;
  for (const char* name : {"x", "y", "z"}) {
    args.push_back(p.add_var({sh::ir::VarKind::Input, t, name, {}}));
    p.inputs.push_back(args.back());
  }
  TableProgram out;
  for (int i = 0; i < sh::ir::kOpCount; ++i) {
    Op op = sh::ir::op_at(i);
    const sh::ir::OpInfo& info = sh::ir::op_info(op);
    if (info.result != sh::ir::ResultRule::SameAsOperands || !sh::ir::accepts(op, s) || sh::ir::is_lane_group(op))
      continue;
    sh::ir::VarId r = p.add_var({sh::ir::VarKind::Output, t, info.name, {}});
    p.outputs.push_back(r);
    std::vector<sh::ir::Operand> operands;
    for (int k = 0; k < info.arity; ++k) operands.push_back(sh::ir::whole(p, args[k]));
    p.body.push_back(sh::ir::Stmt{sh::ir::Assign{r, sh::ir::Swizzle::identity(kWidth), op, operands, -1}});
    out.rows.push_back({op, r});
  }
  out.program = sh::Program(std::move(p), {}, {});
  return out;
}

void check_scalar(const Conformance& t, Scalar s) {
  TableProgram tp = program_for(s);
  std::vector<double> values = values_of(s);
  std::size_t count = values.size() * values.size();
  sh::ir::Type type{s, kWidth};
  std::vector<std::shared_ptr<sh::detail::Buffer>> in, out;
  for (int k = 0; k < 3; ++k) {
    in.push_back(std::make_shared<sh::detail::Buffer>(type, count));
    for (std::size_t e = 0; e < count; ++e)
      for (int c = 0; c < kWidth; ++c) in[k]->set(e, c, operand_value(values, e, k, c));
  }
  for (std::size_t r = 0; r < tp.rows.size(); ++r) out.push_back(std::make_shared<sh::detail::Buffer>(type, 0));
  t.run(tp.program, in, out);

  for (std::size_t r = 0; r < tp.rows.size(); ++r) {
    const sh::ir::OpInfo& info = sh::ir::op_info(tp.rows[r].op);
    int wrong = 0;
    for (std::size_t e = 0; e < count && wrong < 5; ++e)
      for (int c = 0; c < kWidth; ++c) {
        double x[3];
        for (int k = 0; k < 3; ++k) x[k] = in[k]->get(e, c);
        double want = sh::ir::eval(tp.rows[r].op, s, s, sh::Precision::F64, x[0], x[1], x[2]);
        double got = out[r]->get(e, c);
        std::string where = std::string(info.name) + "(" + std::to_string(x[0]) + ", " + std::to_string(x[1]) + ", " +
                            std::to_string(x[2]) + ") " + sh::ir::scalar_name(s) + " component " + std::to_string(c);
        if (!sh::ir::is_float(s)) {
          if (got != want) ++wrong;
          EXPECT_EQ(got, want) << where;
          continue;
        }
        bool fast = t.fast();
        if (fast) {
          bool skip = !ordinary(want);
          for (int k = 0; k < info.arity; ++k) skip = skip || !ordinary(x[k]);
          if (info.cls == sh::ir::OpClass::Transcendental && std::fabs(x[0]) > 1e4) skip = true;
          if (skip) continue;
        }
        std::uint64_t d = s == Scalar::F32 ? ulp_distance<float>(static_cast<float>(want), static_cast<float>(got))
                                           : ulp_distance<double>(want, got);
        bool ok = fast ? d <= info.ulp_fast || std::fabs(got - want) <= 1e-4 * std::max(1.0, std::fabs(want))
                       : d <= info.ulp_precise;
        if (!ok) ++wrong;
        EXPECT_TRUE(ok) << where << ": got " << got << ", want " << want << " (" << d << " ulp)";
      }
  }
}

TEST_P(Conformance, EveryOperationOfTheTableOnEveryScalarItTakes) {
  for (Scalar s : {Scalar::F32, Scalar::F64, Scalar::I32, Scalar::Bool}) check_scalar(*this, s);
}

// Cast is the table's one Converted row: every scalar to every scalar.
TEST_P(Conformance, CastBetweenEveryPairOfScalars) {
  const Scalar all[] = {Scalar::F32, Scalar::F64, Scalar::I32, Scalar::Bool};
  sh::ir::Program p;
  p.name = "op_table_casts";
  std::map<Scalar, sh::ir::VarId> input;
  for (Scalar s : all) {
    input[s] = p.add_var({sh::ir::VarKind::Input, {s, kWidth}, sh::ir::scalar_name(s), {}});
    p.inputs.push_back(input[s]);
  }
  std::vector<std::pair<Scalar, Scalar>> pairs;
  for (Scalar from : all)
    for (Scalar to : all) {
      sh::ir::VarId r = p.add_var({sh::ir::VarKind::Output, {to, kWidth}, "cast", {}});
      p.outputs.push_back(r);
      p.body.push_back(sh::ir::Stmt{sh::ir::Assign{r, sh::ir::Swizzle::identity(kWidth), Op::Cast,
                                                   {sh::ir::whole(p, input[from])}, -1}});
      pairs.push_back({from, to});
    }
  sh::Program program(std::move(p), {}, {});
  std::size_t count = values_of(Scalar::F32).size();
  std::vector<std::shared_ptr<sh::detail::Buffer>> in, out;
  for (Scalar s : all) {
    std::vector<double> v = values_of(s);
    in.push_back(std::make_shared<sh::detail::Buffer>(sh::ir::Type{s, kWidth}, count));
    for (std::size_t e = 0; e < count; ++e)
      for (int c = 0; c < kWidth; ++c) in.back()->set(e, c, v[(e + 5 * c) % v.size()]);
  }
  for (auto [from, to] : pairs) out.push_back(std::make_shared<sh::detail::Buffer>(sh::ir::Type{to, kWidth}, 0));
  run(program, in, out);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    auto [from, to] = pairs[k];
    const auto& src = in[static_cast<std::size_t>(from)];
    for (std::size_t e = 0; e < count; ++e)
      for (int c = 0; c < kWidth; ++c) {
        double x = src->get(e, c);
        if (fast() && sh::ir::is_float(from) && !ordinary(x)) continue;
        double want = sh::ir::eval(Op::Cast, from, to, sh::Precision::F64, x);
        if (to == Scalar::F32) want = static_cast<float>(want);
        double got = out[k]->get(e, c);
        if (std::isnan(want) && std::isnan(got)) continue;
        EXPECT_EQ(got, want) << "cast " << sh::ir::scalar_name(from) << " " << x << " to " << sh::ir::scalar_name(to);
      }
  }
}

}  // namespace
}  // namespace conformance
