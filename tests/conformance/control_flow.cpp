// Recorded control flow with data-dependent conditions and trip counts, on
// every backend (Sh's own suite never tested this).
#include <algorithm>

#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib1i;

std::vector<float> counts() { return {0, 1, 2, 3, 7, 10, 31, -4, 0.5f, 16}; }

TEST_P(Conformance, NestedIfElse) {
  sh::Program p = SH_BEGIN_PROGRAM("nested_if") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> r;
    r = 0.0f;
    SH_IF(x > 2.0f) {
      SH_IF(x > 8.0f) { r = 3.0f; } SH_ELSE { r = 2.0f; } SH_ENDIF;
    } SH_ELSE {
      SH_IF(x < 0.0f) { r = -1.0f; } SH_ENDIF;
      r += x;
    } SH_ENDIF;
  } SH_END;
  std::vector<float> xs = counts();
  sh::Channel<Attrib1f> in(xs), out;
  run(p, {in}, {out});
  for (std::size_t k = 0; k < xs.size(); ++k) {
    float x = xs[k];
    float want = x > 2 ? (x > 8 ? 3.f : 2.f) : (x < 0 ? -1.f : 0.f) + x;
    EXPECT_EQ(out[k], want) << "x = " << x;
  }
}

TEST_P(Conformance, WhileDoForWithDataDependentTripCounts) {
  sh::Program p = SH_BEGIN_PROGRAM("loops") {
    sh::Input<Attrib1f> n;
    sh::Output<Attrib1f> w, d, f;
    Attrib1f i = 0.0f;
    w = 0.0f;
    SH_WHILE(i < n) {
      w += i;
      i += 1.0f;
    } SH_ENDWHILE;
    Attrib1f j = 0.0f;
    d = 0.0f;
    SH_DO {
      d += 2.0f;
      j += 1.0f;
    } SH_UNTIL(j >= n);
    f = 1.0f;
    SH_FOR(Attrib1f k = 0.0f, k < n, k += 1.0f) {
      f *= 2.0f;
    } SH_ENDFOR;
  } SH_END;
  std::vector<float> ns = counts();
  sh::Channel<Attrib1f> in(ns), w, d, f;
  run(p, {in}, {w, d, f});
  for (std::size_t k = 0; k < ns.size(); ++k) {
    float n = ns[k], ws = 0, ds = 0, fs = 1;
    for (float i = 0; i < n; i += 1) ws += i;
    float j = 0;
    do {
      ds += 2;
      j += 1;
    } while (!(j >= n));
    for (float i = 0; i < n; i += 1) fs *= 2;
    EXPECT_EQ(w[k], ws) << "while, n = " << n;
    EXPECT_EQ(d[k], ds) << "do/until, n = " << n;
    EXPECT_EQ(f[k], fs) << "for, n = " << n;
  }
}

TEST_P(Conformance, BreakAndContinueInEveryLoopForm) {
  sh::Program p = SH_BEGIN_PROGRAM("jumps") {
    sh::Input<Attrib1f> n;
    sh::Output<Attrib1f> w, d, f, nested;
    // while: sum odd i below n, stop once the sum passes 20.
    Attrib1f i = 0.0f;
    w = 0.0f;
    SH_WHILE(i < n) {
      i += 1.0f;
      SH_CONTINUE(i % 2.0f == 0.0f);
      w += i;
      SH_BREAK(w > 20.0f);
    } SH_ENDWHILE;
    // do/until: continue goes to the test.
    Attrib1f j = 0.0f;
    d = 0.0f;
    SH_DO {
      j += 1.0f;
      SH_CONTINUE(j < 3.0f);
      d += j;
    } SH_UNTIL(j >= n);
    // for: continue runs the update.
    f = 0.0f;
    SH_FOR(Attrib1f k = 0.0f, k < n, k += 1.0f) {
      SH_IF(k == 2.0f) { SH_CONTINUE(); } SH_ENDIF;
      SH_BREAK(k > 12.0f);
      f += k;
    } SH_ENDFOR;
    // A break leaves only the inner loop.
    nested = 0.0f;
    SH_FOR(Attrib1f a = 0.0f, a < n, a += 1.0f) {
      SH_FOR(Attrib1f b = 0.0f, b < 100.0f, b += 1.0f) {
        SH_BREAK(b >= a);
        nested += 1.0f;
      } SH_ENDFOR;
    } SH_ENDFOR;
  } SH_END;
  std::vector<float> ns = counts();
  sh::Channel<Attrib1f> in(ns), w, d, f, nested;
  run(p, {in}, {w, d, f, nested});
  for (std::size_t k = 0; k < ns.size(); ++k) {
    float n = ns[k];
    float ws = 0, ds = 0, fs = 0, ns_ = 0;
    for (float i = 0; i < n;) {
      i += 1;
      if (std::fmod(i, 2.f) == 0) continue;
      ws += i;
      if (ws > 20) break;
    }
    float j = 0;
    do {
      j += 1;
      if (j < 3) continue;
      ds += j;
    } while (!(j >= n));
    for (float c = 0; c < n; c += 1) {
      if (c == 2) continue;
      if (c > 12) break;
      fs += c;
    }
    for (float a = 0; a < n; a += 1)
      for (float b = 0; b < 100; b += 1) {
        if (b >= a) break;
        ns_ += 1;
      }
    EXPECT_EQ(w[k], ws) << "while, n = " << n;
    EXPECT_EQ(d[k], ds) << "do/until, n = " << n;
    EXPECT_EQ(f[k], fs) << "for, n = " << n;
    EXPECT_EQ(nested[k], ns_) << "nested, n = " << n;
  }
}

TEST_P(Conformance, IntegerLoopCounters) {
  sh::Program p = SH_BEGIN_PROGRAM("collatz") {
    sh::Input<Attrib1i> start;
    sh::Output<Attrib1i> steps;
    Attrib1i x = start;
    steps = 0;
    SH_WHILE(x > 1) {
      SH_IF(x % 2 == 0) { x = x / 2; } SH_ELSE { x = 3 * x + 1; } SH_ENDIF;
      steps += 1;
    } SH_ENDWHILE;
  } SH_END;
  std::vector<std::int32_t> starts = {1, 2, 3, 6, 7, 27, 97, 871, 0, -5};
  sh::Channel<Attrib1i> in(starts), out;
  run(p, {in}, {out});
  for (std::size_t k = 0; k < starts.size(); ++k) {
    std::int64_t x = starts[k];
    int steps = 0;
    while (x > 1) {
      x = x % 2 == 0 ? x / 2 : 3 * x + 1;
      ++steps;
    }
    EXPECT_EQ(out[k], steps) << "start " << starts[k];
  }
}

TEST_P(Conformance, LoopIterationCapTurnsEndlessLoopIntoError) {
  sh::Program p = SH_BEGIN_PROGRAM("endless") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> r;
    r = x;
    SH_WHILE(r > 0.0f) { r += 1.0f; } SH_ENDWHILE;  // never ends for x > 0
  } SH_END;
  sh::Channel<Attrib1f> in(std::vector<float>{-1, 1}), out;
  sh::Options o;
  o.max_loop_iterations = 1000;
  sh::BackendChoice c = choice(o);
  try {
    sh::run(p, {in}, {out}, c);
    FAIL() << "an endless loop must be an error";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("endless"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("element 1 "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1000"), std::string::npos) << e.what();
  }
}

// The loop that ran away is the one named, when the loop around it tests
// last and its test holds a loop too (opencl named the test's loop: it
// numbered a do/until's parts in another order than it wrote them).
TEST_P(Conformance, TheRunawayLoopIsNamedInsideADoUntilWhoseTestLoops) {
  sh::Program p = SH_BEGIN_PROGRAM("runaway_in_do") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> r;
    Attrib1f k = 0.0f, n = 0.0f;
    SH_DO {
      SH_WHILE(x > 0.0f) { k += 1.0f; } SH_ENDWHILE;  // never ends for x > 0
      n += 1.0f;
    } SH_UNTIL(([&] {
      Attrib1f j = 0.0f;
      SH_WHILE(j < 2.0f) { j += 1.0f; } SH_ENDWHILE;
      return j + n;
    })() > 3.0f);
    r = k + n;
  } SH_END;
  sh::Options o;
  o.max_loop_iterations = 100;
  auto named_loop = [&](const sh::BackendChoice& c) -> std::string {
    sh::Channel<Attrib1f> in(std::vector<float>{1.0f}), out;
    try {
      sh::run(p, {in}, {out}, c);
    } catch (const sh::Error& e) {
      std::string what = e.what();
      auto from = what.find("(`"), to = what.find("`)");
      return from == std::string::npos || to == std::string::npos ? what : what.substr(from, to - from);
    }
    return "no error";
  };
  std::string reference = named_loop(sh::backend("interp", o));
  EXPECT_NE(reference.find("while"), std::string::npos) << reference;
  EXPECT_EQ(named_loop(choice(o)), reference);
}

// Two programs of one structure under two names: each one's error names
// it (they shared a kernel, and the second's error named the first).
TEST_P(Conformance, ARunawayLoopsErrorNamesItsOwnProgram) {
  auto endless = [](const std::string& name) {
    return SH_BEGIN_PROGRAM(name) {
      sh::Input<Attrib1f> x;
      sh::Output<Attrib1f> r;
      r = x;
      SH_WHILE(r > 0.0f) { r += 1.0f; } SH_ENDWHILE;
    } SH_END;
  };
  sh::Options o;
  o.max_loop_iterations = 50;
  for (const char* name : {"first_of_a_shape", "second_of_a_shape"}) {
    sh::Channel<Attrib1f> in(std::vector<float>{1.0f}), out;
    try {
      sh::run(endless(name), {in}, {out}, choice(o));
      ADD_FAILURE() << name << ": an endless loop must be an error";
    } catch (const sh::Error& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + name + "'"), std::string::npos) << e.what();
    }
  }
}

// A loop whose every element leaves by a break in its last allowed pass
// ran no more than the cap: no error, however many elements share a
// batch (a masked loop once counted one more pass with no lane left).
TEST_P(Conformance, LoopLeftByABreakInItsLastAllowedPassIsNoRunaway) {
  sh::Program p = SH_BEGIN_PROGRAM("break_at_cap") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> r;
    Attrib1f i = 0.0f;
    SH_WHILE(i < 100.0f) {
      i += 1.0f;
      SH_BREAK(i >= x);
    } SH_ENDWHILE;
    r = i;
  } SH_END;
  sh::Options o;
  o.max_loop_iterations = 4;
  for (std::size_t n : {1u, 5u, 17u}) {
    sh::Channel<Attrib1f> in(std::vector<float>(n, 4.0f)), out;
    sh::run(p, {in}, {out}, choice(o));
    for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(out[k], 4.0f) << n << " elements, element " << k;
  }
}

// The cap is the passes a loop may run: a while, a for and a do/until of
// exactly the cap's passes run (a while of 3 passes under a cap of 3 was
// refused, its fourth test counted as a pass, and under a cap of 0 a
// while that ran no pass); one pass more is refused, naming the element.
TEST_P(Conformance, ALoopOfExactlyTheCapsPassesRuns) {
  sh::Program p = SH_BEGIN_PROGRAM("exact_cap") {
    sh::Input<Attrib1f> n;
    sh::Output<sh::Attrib3f> r;
    Attrib1f w = 0.0f, f = 0.0f, d = 0.0f;
    SH_WHILE(w < n) { w += 1.0f; } SH_ENDWHILE;
    SH_FOR(Attrib1f i = 0.0f, i < n, i += 1.0f) { f += 1.0f; } SH_ENDFOR;
    SH_DO { d += 1.0f; } SH_UNTIL(d >= n);
    r = join(join(w, f), d);
  } SH_END;
  sh::Options o;
  o.max_loop_iterations = 3;
  for (std::size_t count : {1u, 5u, 17u}) {
    std::vector<float> ns(count);
    for (std::size_t k = 0; k < count; ++k) ns[k] = static_cast<float>(1 + k % 3);  // 1, 2 or 3 passes
    sh::Channel<Attrib1f> in(ns);
    sh::Channel<sh::Attrib3f> out;
    sh::run(p, {in}, {out}, choice(o));
    for (std::size_t k = 0; k < count; ++k)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(out[3 * k + c], ns[k]) << count << " elements, element " << k << ", loop " << c;
    ns[count / 2] = 4.0f;
    sh::Channel<Attrib1f> over(ns);
    try {
      sh::run(p, {over}, {out}, choice(o));
      ADD_FAILURE() << "a loop of 4 passes ran under a cap of 3";
    } catch (const sh::Error& e) {
      EXPECT_NE(std::string(e.what()).find("element " + std::to_string(count / 2) + " "), std::string::npos) << e.what();
    }
  }
  sh::Program none = SH_BEGIN_PROGRAM("no_pass") {
    sh::Input<Attrib1f> n;
    sh::Output<Attrib1f> r;
    Attrib1f w = 0.0f;
    SH_WHILE(w < n) { w += 1.0f; } SH_ENDWHILE;
    r = w;
  } SH_END;
  o.max_loop_iterations = 0;
  sh::Channel<Attrib1f> zero(std::vector<float>{0.0f, -1.0f}), out;
  sh::run(none, {zero}, {out}, choice(o));
  EXPECT_EQ(out[0], 0.0f);
}

// A variable read before anything is written to it reads zero, in every
// element: on a loop's first trip, after a loop that did not run, after an
// if whose other side wrote it, in a do/until body before its test, and in
// a component never written; however many elements ran before (batches of
// SIMD lanes reuse their registers).
TEST_P(Conformance, AVariableReadBeforeItsWriteReadsZeroInEveryElement) {
  sh::Program p = SH_BEGIN_PROGRAM("read_unwritten") {
    sh::Input<Attrib1i> trips;
    sh::Input<Attrib1f> x;
    sh::Output<sh::Attrib4f> out;
    Attrib1f carried, after_loop, one_side;
    sh::Attrib2f half;
    Attrib1f seen = 0.0f;
    SH_FOR(Attrib1i j = 0, j < trips, j += 1) {
      seen += carried;
      carried = x;
      after_loop = x + 1.0f;
    } SH_ENDFOR;
    SH_IF(x > 4.0f) { one_side = x; } SH_ENDIF;
    // A do/until loop's body runs before its test writes `tested`: its
    // first trip reads zero, the others x.
    Attrib1f tested, before_test = 0.0f;
    Attrib1i k = 0;
    SH_DO {
      before_test += tested;
      k += 1;
    } SH_UNTIL((tested = x) * 0.0f + (k >= trips).cast<float>() > 0.5f);
    half(0) = x;
    out = join(join(seen, after_loop), join(one_side, half(1) + half(0) + before_test));
  } SH_END;
  for (std::size_t length : {1, 17, 300}) {
    std::vector<std::int32_t> ns(length);
    std::vector<float> xs(length);
    for (std::size_t e = 0; e < length; ++e) {
      ns[e] = static_cast<std::int32_t>((e * 5 + 3) % 4);
      xs[e] = static_cast<float>(e % 19) * 0.5f;
    }
    sh::Channel<Attrib1i> in_trips(ns);
    sh::Channel<Attrib1f> in_x(xs);
    sh::Channel<sh::Attrib4f> out;
    run(p, {in_trips, in_x}, {out});
    for (std::size_t e = 0; e < length; ++e) {
      float x = xs[e];
      int n = ns[e];
      float want[] = {n > 0 ? static_cast<float>(n - 1) * x : 0.0f, n > 0 ? x + 1.0f : 0.0f, x > 4.0f ? x : 0.0f,
                      x + static_cast<float>(std::max(n, 1) - 1) * x};
      for (int c = 0; c < 4; ++c)
        EXPECT_EQ(out[e * 4 + static_cast<std::size_t>(c)], want[c]) << "length " << length << ", element " << e << ", component " << c;
    }
  }
}

// Names are the user's to choose: a program, a variable and a local array
// named with a backslash, a line break or a directive change nothing (the
// opencl backend wrote them into its source's comments, where a trailing
// backslash swallowed the next line and a line break began a new one).
TEST_P(Conformance, NamesWithBackslashesAndLineBreaksChangeNothing) {
  sh::Program p = SH_BEGIN_PROGRAM("named\\\n#define e 0\r\\") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> r;
    Attrib1f t = x * 2.0f;
    t.name("dir\\");
    Attrib1f u = t + 1.0f;
    u.name("line\n#define e 0");
    sh::LocalArray<Attrib1f> kept(2, "kept\\");
    kept.store(1, u);
    r = kept[1] * x;
  } SH_END;
  sh::Channel<Attrib1f> in(std::vector<float>{1.0f, 2.0f, 3.0f}), out;
  run(p, {in}, {out});
  EXPECT_EQ(out.values(), (std::vector<float>{3.0f, 10.0f, 21.0f}));
}

}  // namespace
}  // namespace conformance
