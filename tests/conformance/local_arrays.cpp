// Local arrays: an element's own memory.  Each element reads back what it
// stored and nothing of its neighbours' (SIMD lanes side by side keep
// their own), starts with zeros, clamps an index outside to the nearest
// end, and keeps what a divergent branch or loop stored only for the
// elements that ran it.  Arrays every lane writes alike (one for all lanes)
// and arrays read at indices that differ between lanes are both here.
#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib1i;
using sh::Attrib4f;

constexpr std::int32_t kSlots = 12;

std::int32_t count_of(std::size_t e) { return static_cast<std::int32_t>((e * 7 + 3) % 11); }

// A stack: element e pushes the binary digits of e + 1, lowest first, then
// pops them into a number read backwards (the digits reversed).  The loops
// run a different number of times in neighbouring elements.
TEST_P(Conformance, LocalArrayIsAStackOfItsElementsOwn) {
  sh::Program p = SH_BEGIN_PROGRAM("array_stack") {
    sh::Input<Attrib1i> n;
    sh::Output<Attrib1i> reversed, depth_out;
    sh::LocalArray<Attrib1i> stack(32, "stack");
    Attrib1i left = n + 1, depth = 0;
    SH_WHILE(left > 0) {
      stack.store(depth, left % 2);
      depth += 1;
      left = left / 2;
    } SH_ENDWHILE;
    depth_out = depth;
    reversed = 0;
    SH_WHILE(depth > 0) {
      depth -= 1;
      reversed = reversed * 2 + stack[depth];
    } SH_ENDWHILE;
  } SH_END;
  for (std::size_t length : {1, 5, 16, 17, 300}) {
    std::vector<std::int32_t> ns(length);
    for (std::size_t e = 0; e < length; ++e) ns[e] = static_cast<std::int32_t>(e * 37 % 1000);
    sh::Channel<Attrib1i> in(ns), reversed, depth;
    run(p, {in}, {reversed, depth});
    for (std::size_t e = 0; e < length; ++e) {
      std::int32_t v = ns[e] + 1, bits = 0;
      for (std::int32_t x = v; x > 0; x /= 2) ++bits;
      // Digits pushed lowest first pop highest first: the number itself.
      EXPECT_EQ(reversed[e], v) << "length " << length << ", element " << e;
      EXPECT_EQ(depth[e], bits) << "element " << e;
    }
  }
}

// Element e stores at indices that differ between neighbours, under a
// branch some of them take, and reads every slot back: slots it never
// stored are zero, an index below 0 or past the end lands on slot 0 or
// the last, and four components stay together.
TEST_P(Conformance, LocalArrayStartsAtZeroClampsAndKeepsBranchesApart) {
  sh::Program p = SH_BEGIN_PROGRAM("array_slots") {
    sh::Input<Attrib1i> count;
    sh::Input<Attrib1f> x;
    sh::Output<Attrib4f> sum;
    sh::Output<Attrib1f> first, last;
    sh::LocalArray<Attrib4f> slots(kSlots, "slots");
    SH_FOR(Attrib1i k = 0, k < count, k += 1) {
      SH_IF(k % 3 != 1) {
        slots.store(k, join(join(x, k.cast<float>()), join(-x, x * 2.0f)));
      } SH_ENDIF;
    } SH_ENDFOR;
    slots.store(-5, join(x + 1.0f, sh::ConstAttrib3f(0.0f, 0.0f, 0.0f)));
    slots.store(kSlots + 40, join(x + 2.0f, sh::ConstAttrib3f(0.0f, 0.0f, 0.0f)));
    sum = sh::ConstAttrib4f(0.0f, 0.0f, 0.0f, 0.0f);
    SH_FOR(Attrib1i k = 1, k < kSlots - 1, k += 1) { sum += slots[k] * (k + 1).cast<float>(); } SH_ENDFOR;
    first = slots[-1](0);
    last = slots[1000](0);
  } SH_END;
  constexpr std::size_t kElements = 300;
  std::vector<std::int32_t> counts(kElements);
  std::vector<float> xs(kElements);
  for (std::size_t e = 0; e < kElements; ++e) {
    counts[e] = count_of(e);
    xs[e] = static_cast<float>(e) * 0.5f - 20.0f;
  }
  sh::Channel<Attrib1i> c(counts);
  sh::Channel<Attrib1f> x(xs);
  sh::Channel<Attrib4f> sum;
  sh::Channel<Attrib1f> first, last;
  run(p, {c, x}, {sum, first, last});
  for (std::size_t e = 0; e < kElements; ++e) {
    float want[4] = {0, 0, 0, 0};
    for (std::int32_t k = 1; k < kSlots - 1; ++k) {
      if (k >= counts[e] || k % 3 == 1) continue;
      float w = static_cast<float>(k + 1), v[4] = {xs[e], static_cast<float>(k), -xs[e], xs[e] * 2.0f};
      for (int i = 0; i < 4; ++i) want[i] += v[i] * w;
    }
    for (int i = 0; i < 4; ++i) EXPECT_EQ(sum[e * 4 + i], want[i]) << "element " << e << " component " << i;
    EXPECT_EQ(first[e], xs[e] + 1.0f) << "element " << e << ": index -5 stores into slot 0";
    EXPECT_EQ(last[e], xs[e] + 2.0f) << "element " << e << ": index 52 stores into the last slot";
  }
}

// A table of squares every lane fills alike, read where each lane asks;
// and an array of each lane's own values written at indices all lanes
// share, read at indices each lane picks.
TEST_P(Conformance, LocalArraysWrittenAlikeOrApartAndReadAnywhere) {
  sh::Program p = SH_BEGIN_PROGRAM("array_shared_and_own") {
    sh::Input<Attrib1i> i;
    sh::Output<Attrib1i> square, own;
    sh::LocalArray<Attrib1i> squares(16), mine(16);
    SH_FOR(Attrib1i k = 0, k < 16, k += 1) {
      squares.store(k, k * k);
      mine.store(k, i * 100 + k);
    } SH_ENDFOR;
    square = squares[i % 16];
    own = mine[(i * 5) % 16];
  } SH_END;
  constexpr std::size_t kElements = 100;
  std::vector<std::int32_t> is(kElements);
  for (std::size_t e = 0; e < kElements; ++e) is[e] = static_cast<std::int32_t>(e * 13 % 97);
  sh::Channel<Attrib1i> in(is), square, own;
  run(p, {in}, {square, own});
  for (std::size_t e = 0; e < kElements; ++e) {
    EXPECT_EQ(square[e], (is[e] % 16) * (is[e] % 16)) << "element " << e;
    EXPECT_EQ(own[e], is[e] * 100 + (is[e] * 5) % 16) << "element " << e;
  }
}

// A store under a branch some neighbours take, then one every element runs
// at another index: the second leaves the first element as each element
// had it.  A declaration inside a loop gives zeros every time it runs.
TEST_P(Conformance, LocalArrayStoresLeaveTheOtherElementsAndDeclarationsFillWithZero) {
  sh::Program p = SH_BEGIN_PROGRAM("array_partial") {
    sh::Input<Attrib1i> i;
    sh::Output<Attrib1i> kept, refilled;
    sh::LocalArray<Attrib1i> a(2);
    SH_IF(i % 2 == 0) { a.store(0, 7); } SH_ENDIF;
    a.store(1, 3);
    kept = a[0] + a[1] * 10;
    refilled = 0;
    SH_FOR(Attrib1i k = 0, k < 3 + i % 3, k += 1) {
      sh::LocalArray<Attrib1i> fresh(4);
      refilled += fresh[k - 1];
      fresh.store(k, 5);
    } SH_ENDFOR;
  } SH_END;
  constexpr std::size_t kElements = 70;
  std::vector<std::int32_t> is(kElements);
  for (std::size_t e = 0; e < kElements; ++e) is[e] = static_cast<std::int32_t>(e * 3 + e / 5);
  sh::Channel<Attrib1i> in(is), kept, refilled;
  run(p, {in}, {kept, refilled});
  for (std::size_t e = 0; e < kElements; ++e) {
    EXPECT_EQ(kept[e], is[e] % 2 == 0 ? 37 : 30) << "element " << e;
    EXPECT_EQ(refilled[e], 0) << "element " << e << ": what the last trip stored is gone";
  }
}

}  // namespace
}  // namespace conformance
