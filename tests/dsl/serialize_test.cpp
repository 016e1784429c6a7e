// Programs as bytes (what the mpi backend sends): a round trip keeps the
// program exactly, and no truncated or garbled input crashes the reader.
#include <gtest/gtest.h>

#include <random>

#include <sh/sh.hpp>

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
    energy.add(n, c);
  } SH_END;
}

TEST(Serialize, RoundTripKeepsTheProgram) {
  ir::Program p = sample().ir();
  ir::Program back = ir::deserialize(ir::serialize(p));
  EXPECT_EQ(ir::print(back), ir::print(p));
  EXPECT_EQ(ir::structural_hash(back), ir::structural_hash(p));
  ir::Program optimised = optimize(p);
  EXPECT_EQ(ir::print(ir::deserialize(ir::serialize(optimised))), ir::print(optimised));
}

TEST(Serialize, BadBytesAreErrorsNotCrashes) {
  std::string bytes = ir::serialize(sample().ir());
  for (std::size_t cut = 0; cut < bytes.size(); cut += 7)
    EXPECT_THROW(ir::deserialize(bytes.substr(0, cut)), Error) << "truncated at " << cut;
  std::mt19937 rng(42);
  int rejected = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::string garbled = bytes;
    for (int k = 0; k < 3; ++k) garbled[rng() % garbled.size()] = static_cast<char>(rng());
    try {
      ir::deserialize(garbled);  // a flip may land in a name or a constant: still a program
    } catch (const Error&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 100);
  EXPECT_THROW(ir::deserialize("not a program"), Error);
}

}  // namespace
