// Programs as bytes (what the mpi backend sends, --dump-ir-bytes writes and
// the kernel cache hashes): a round trip keeps the program exactly, the hash
// leaves names out, and no truncated or garbled input crashes the reader.
#include <gtest/gtest.h>

#include <random>

#include <sh/sh.hpp>

#include "../common/expect_error.hpp"

namespace {

using namespace sh;

Program sample() {
  Table2D<Attrib3f> t(2, 2);
  t.name("t");
  Attrib1f u = 2.0f;
  Accumulator<Attrib3f> energy(4, "energy");
  return SH_BEGIN_PROGRAM("sample") {
    InputAttrib2f uv;
    InOut<Attrib3f> acc;
    OutputAttrib1i n;
    Attrib3f c = t(uv) * u;
    n = 0;
    SH_FOR(Attrib1i i = 0, i < 4, i += 1) {
      SH_IF(dot(c, c) > 1.0f) { SH_BREAK(); } SH_ENDIF;
      c(0, 1) = c(1, 0) + 0.5f;
      n += 1;
    } SH_ENDFOR;
    acc = acc + c;
    t.prefetch(join(n, n - 1));
    energy.add(n, c);
  } SH_END;
}

TEST(Serialize, RoundTripKeepsTheProgram) {
  ir::Program p = sample().ir();
  std::string bytes = ir::serialize(p);
  ir::Program back = ir::deserialize(bytes);
  EXPECT_EQ(ir::serialize(back), bytes);
  EXPECT_EQ(ir::print(back), ir::print(p));
  EXPECT_EQ(ir::structural_hash(back), ir::structural_hash(p));
  ir::Program optimised = optimize(p);
  EXPECT_EQ(ir::print(ir::deserialize(ir::serialize(optimised))), ir::print(optimised));
}

TEST(Serialize, TheHashIsTheBytesWithoutNames) {
  ir::Program p = sample().ir();
  ir::Program renamed = p;
  renamed.name = "another";
  for (ir::Var& v : renamed.vars) v.name += "_renamed";
  for (ir::TableDecl& t : renamed.tables) t.name = "other";
  EXPECT_NE(ir::serialize(renamed), ir::serialize(p));
  EXPECT_EQ(ir::serialize(renamed, {.names = false}), ir::serialize(p, {.names = false}));
  EXPECT_EQ(ir::structural_hash(renamed), ir::structural_hash(p));
  EXPECT_EQ(sample().hash(), ir::structural_hash(p)) << "Program::hash() is the structural hash of its IR";

  // Without names the bytes still read back, as the same program unnamed.
  ir::Program unnamed = ir::deserialize(ir::serialize(p, {.names = false}));
  EXPECT_EQ(unnamed.name, "");
  EXPECT_EQ(ir::print(unnamed, {.names = false}), ir::print(p, {.names = false}));

  ir::Program other_constant = p;
  for (ir::Var& v : other_constant.vars)
    if (v.kind == ir::VarKind::Const) v.value[0] += 1;
  EXPECT_NE(ir::structural_hash(other_constant), ir::structural_hash(p)) << "constants are structure";
}

// A program built by hand, whose last statement's operation byte lies at a
// known distance from the end: the operand (var 4, swizzle 1 + 1), the
// operand count 1 and the table 4 follow it.
ir::Program negation() {
  ir::Program p;
  p.name = "negation";
  p.inputs.push_back(p.add_var({ir::VarKind::Input, {ir::Scalar::F32, 1}, "x", {}}));
  p.outputs.push_back(p.add_var({ir::VarKind::Output, {ir::Scalar::F32, 1}, "r", {}}));
  p.body.push_back(ir::Stmt{ir::Assign{1, ir::Swizzle::identity(1), ir::Op::Neg, {whole(p, 0)}, -1}});
  return p;
}
constexpr std::size_t kOpFromEnd = 6 + 1 + 4 + 1;

TEST(Serialize, EveryValueIsRangeChecked) {
  std::string bytes = ir::serialize(negation());
  ASSERT_EQ(bytes[bytes.size() - kOpFromEnd], static_cast<char>(ir::Op::Neg));
  for (int op : {ir::kOpCount, 255}) {
    std::string bad = bytes;
    bad[bad.size() - kOpFromEnd] = static_cast<char>(op);
    expect_error([&] { ir::deserialize(bad); }, {"malformed program bytes at offset", "unknown operation"});
  }
  std::string wrong_arity = bytes;
  wrong_arity[bytes.size() - kOpFromEnd] = static_cast<char>(ir::Op::Add);
  expect_error([&] { ir::deserialize(wrong_arity); }, {"add takes 2 operands, not 1"});
  std::string wide_swizzle = bytes;
  wide_swizzle[bytes.size() - 1] = 7;  // the operand's component
  expect_error([&] { ir::deserialize(wide_swizzle); }, {"operand swizzle is 7, outside [0, 4)"});
  std::string stray_var = bytes;
  stray_var[bytes.size() - 6] = 9;  // the operand's variable
  expect_error([&] { ir::deserialize(stray_var); }, {"operand is 9, outside [0, 2)"});
  std::string old_version = bytes;
  old_version[4] = 1;
  expect_error([&] { ir::deserialize(old_version); }, {"format version 1; this build reads version"});
  expect_error([&] { ir::deserialize(bytes + "x"); }, {"1 bytes after the program"});
  expect_error([&] { ir::deserialize("{\"scene\": 1}"); }, {"at offset 0: not a serialized program"});
}

// A table's edge mode is one byte, refused outside the three modes.
TEST(Serialize, ATablesEdgeModeIsRangeChecked) {
  auto with_edge = [](ir::Edge e) {
    ir::Program p = negation();
    p.tables.push_back(ir::TableDecl{{ir::Scalar::F32, 1}, 2, "image", false, e});
    return ir::serialize(p);
  };
  std::string repeat = with_edge(ir::Edge::Repeat), zero = with_edge(ir::Edge::Zero);
  ASSERT_EQ(repeat.size(), zero.size());
  std::size_t at = 0;
  while (at < repeat.size() && repeat[at] == zero[at]) ++at;
  ASSERT_LT(at, repeat.size());
  EXPECT_EQ(ir::deserialize(zero).tables[0].edge, ir::Edge::Zero);
  std::string unknown = zero;
  unknown[at] = 3;
  expect_error([&] { ir::deserialize(unknown); }, {"table edge mode is 3, outside [0, 3)"});
}

// Ifs nested `depth` deep around one negation.
ir::Program nested(int depth) {
  ir::Program p = negation();
  for (int d = 0; d < depth; ++d) {
    ir::If i{whole(p, 0), std::move(p.body), {}};
    p.body = {ir::Stmt{std::move(i)}};
  }
  return p;
}

// The reader recurses once per level: nesting far deeper than a recorded
// program's is refused before it can exhaust the stack.
TEST(Serialize, NestingIsBounded) {
  ir::Program deep = nested(200);
  EXPECT_EQ(ir::print(ir::deserialize(ir::serialize(deep))), ir::print(deep));
  expect_error([] { ir::deserialize(ir::serialize(nested(1001))); }, {"statements nested deeper than"});
}

// Every prefix, every single-bit flip and thousands of random garblings of a
// program's bytes: each either reads back as a program the verifier accepts
// or throws sh::Error; none crashes (run under the ASan build too).
TEST(Serialize, BadBytesAreErrorsNotCrashes) {
  std::string bytes = ir::serialize(sample().ir());
  for (std::size_t cut = 0; cut < bytes.size(); ++cut)
    EXPECT_THROW(ir::deserialize(bytes.substr(0, cut)), Error) << "truncated at " << cut;
  auto survives = [](const std::string& b) {
    try {
      ir::deserialize(b);  // a flip may land in a name or a constant: still a program
      return true;
    } catch (const Error&) {
      return false;
    }
  };
  int rejected = 0;
  for (std::size_t bit = 0; bit < 8 * bytes.size(); ++bit) {
    std::string flipped = bytes;
    flipped[bit / 8] = static_cast<char>(flipped[bit / 8] ^ (1 << (bit % 8)));
    rejected += !survives(flipped);
  }
  EXPECT_GT(rejected, static_cast<int>(bytes.size()));
  std::mt19937 rng(42);
  rejected = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    std::string garbled = bytes;
    for (int k = 0; k < 3; ++k) garbled[rng() % garbled.size()] = static_cast<char>(rng());
    rejected += !survives(garbled);
  }
  EXPECT_GT(rejected, 1000);
  EXPECT_THROW(ir::deserialize(""), Error);
}

}  // namespace
