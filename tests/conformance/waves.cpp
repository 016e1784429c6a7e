// Running in waves: elements stop at table entries not built yet, a
// refiner builds what they asked for, and they resume from their carried
// state.  Every backend (and every rank of mpi) must give the same sums
// while each element takes exactly its own steps.
#include <algorithm>
#include <set>

#include "harness.hpp"

namespace conformance {
namespace {

constexpr int kEntries = 997;
constexpr int kChain = 5;  // entries each element adds up
constexpr const char* kKind = "conformance.squares";

std::int32_t square_plus_one(std::int32_t k) { return k * k + 1; }

// Builds entries of a table on request (k*k + 1; -1 marks "not built").
class LazySquares : public sh::Refiner {
 public:
  explicit LazySquares(std::uint64_t stands_for) : stands_for_(stands_for), values_(kEntries, -1) {}
  std::string kind() const override { return kKind; }
  std::string seed() const override { return std::to_string(stands_for_); }
  void bind(std::vector<sh::TableView>& tables) const override {
    for (sh::TableView& t : tables)
      if (t.id == stands_for_ || t.id == own_id_) {
        t.data = values_.data();
        t.id = own_id_;
        t.version = version_;
      }
  }
  std::size_t refine(const std::vector<std::int32_t>& requests, int width) override {
    std::size_t built = 0;
    for (std::size_t i = 0; i < requests.size(); i += width)
      if (std::int32_t r = requests[i]; r >= 0 && r < kEntries && values_[r] < 0) {
        values_[r] = square_plus_one(r);
        ++built;
      }
    version_ += built > 0;
    return built;
  }
  std::string summary() const override { return std::to_string(std::count_if(values_.begin(), values_.end(), [](int v) { return v >= 0; })); }

 private:
  std::uint64_t stands_for_;
  std::uint64_t own_id_ = sh::refined_table_id();
  std::uint64_t version_ = 1;
  std::vector<std::int32_t> values_;
};

// A refiner whose bind hands the kernel what the program does not read:
// one of four faults, by its seed.
class BrokenBind : public sh::Refiner {
 public:
  static constexpr const char* kKind = "conformance.broken_bind";
  explicit BrokenBind(int fault) : fault_(fault) {}
  std::string kind() const override { return kKind; }
  std::string seed() const override { return std::to_string(fault_); }
  void bind(std::vector<sh::TableView>& tables) const override {
    if (fault_ == 0) tables.pop_back();
    if (fault_ == 1) tables[0].data = nullptr, tables[0].source = nullptr;
    if (fault_ == 2) tables[0].dims[0] = 0;
    if (fault_ == 3) tables[0].element = {sh::ir::Scalar::F32, 4};
  }
  std::size_t refine(const std::vector<std::int32_t>&, int) override { return 0; }
  std::string summary() const override { return ""; }

 private:
  int fault_;
};

// Every process of an mpi job registers them before serving.
const bool registered = [] {
  sh::register_refiner(kKind, [](const std::string& seed) { return std::make_unique<LazySquares>(std::stoull(seed)); });
  sh::register_refiner(BrokenBind::kKind, [](const std::string& seed) { return std::make_unique<BrokenBind>(std::stoi(seed)); });
  return true;
}();

TEST_P(Conformance, WavesResumeStoppedElementsUntilTheTableHasWhatTheyNeed) {
  ASSERT_TRUE(registered);
  sh::Table1D<sh::Attrib1i> values(kEntries);
  values.name("squares").assign(std::vector<std::int32_t>(kEntries, -1));
  sh::Program p = SH_BEGIN_PROGRAM("lazy squares") {
    sh::InputAttrib1i first;
    sh::InputAttrib3i resume;  // next step, sum so far, steps taken
    sh::OutputAttrib1i request;
    sh::OutputAttrib3i state;
    sh::Attrib1i step = resume(0), sum = resume(1), taken = resume(2);
    request = -1;
    SH_WHILE(step < kChain) {
      sh::Attrib1i at = (first * 3 + step * 7) % kEntries;
      sh::Attrib1i v = values[at];
      request = sh::cond(v < 0, at, request);
      SH_BREAK(v < 0);
      sum += v;
      step += 1;
      taken += 1;
    } SH_ENDWHILE;
    state = sh::join(sh::join(step, sum), taken);
  } SH_END;

  const std::size_t n = 1500;
  std::vector<std::int32_t> firsts(n), zeros(3 * n, 0);
  for (std::size_t i = 0; i < n; ++i) firsts[i] = static_cast<std::int32_t>((i * 37) % kEntries);
  sh::Channel<sh::Attrib1i> first(firsts), request;
  sh::Channel<sh::Attrib3i> resume(zeros), state;
  LazySquares refiner(values.storage()->id);
  sh::Waves waves{&refiner, 0, {{1, 1}}};
  sh::RunStats stats = sh::run(p, {first, resume}, {request, state}, waves, choice());

  std::set<int> needed;
  for (std::size_t i = 0; i < n; ++i) {
    std::int32_t want = 0;
    for (int s = 0; s < kChain; ++s) {
      int at = (firsts[i] * 3 + s * 7) % kEntries;
      want += square_plus_one(at);
      needed.insert(at);
    }
    ASSERT_EQ(request[i], -1) << "element " << i;
    ASSERT_EQ(state[3 * i], kChain) << "element " << i;
    EXPECT_EQ(state[3 * i + 1], want) << "element " << i;
    EXPECT_EQ(state[3 * i + 2], kChain) << "element " << i << " repeated steps instead of resuming";
  }
  EXPECT_GE(stats.waves, 1u);
  EXPECT_GT(stats.resumed, 0u);
  // Each process built only entries some element needed; together all of them.
  ASSERT_FALSE(stats.refined.empty());
  std::size_t built = 0;
  for (const std::string& s : stats.refined) built += std::stoul(s);
  EXPECT_GE(built, needed.size());
  EXPECT_LE(built, needed.size() * stats.refined.size());
  if (stats.refined.size() == 1) {
    EXPECT_EQ(std::stoul(stats.refined[0]), needed.size());
  }

  // A second run finds everything built on this process: no wave at all
  // where one process did all the work.
  sh::Channel<sh::Attrib1i> request2;
  sh::Channel<sh::Attrib3i> state2;
  sh::RunStats again = sh::run(p, {first, resume}, {request2, state2}, waves, choice());
  if (stats.refined.size() == 1) {
    EXPECT_EQ(again.waves, 0u);
  }
  for (std::size_t i = 0; i < 3 * n; ++i) ASSERT_EQ(state2[i], state[i]);
}

// Without a refiner, waves are a wavefront: each element takes one step a
// wave and asks for another while it has steps to go; each wave runs only
// those, gathered side by side, from their carried state.
TEST_P(Conformance, WavesWithoutARefinerRunTheElementsStillGoingOneStepAWave) {
  constexpr int kLongest = 6;
  sh::Program p = SH_BEGIN_PROGRAM("steps") {
    sh::InputAttrib1i steps;  // this element's: 1..kLongest
    sh::InputAttrib2i resume;  // steps taken, sum of the step numbers so far
    sh::OutputAttrib1i request;
    sh::OutputAttrib2i state;
    sh::Attrib1i taken = resume(0) + 1;
    state = sh::join(taken, resume(1) + taken * steps);
    request = (taken < steps) - 1;  // 0: another wave, -1: done
  } SH_END;

  const std::size_t n = 1000;
  std::vector<std::int32_t> counts(n), zeros(2 * n, 0);
  std::size_t more = 0;  // runs after an element's first
  for (std::size_t i = 0; i < n; ++i) {
    counts[i] = 1 + static_cast<std::int32_t>((i * 7 + i / 13) % kLongest);
    more += counts[i] - 1;
  }
  sh::Channel<sh::Attrib1i> steps(counts), request;
  sh::Channel<sh::Attrib2i> resume(zeros), state;
  sh::RunStats stats = sh::run(p, {steps, resume}, {request, state}, sh::Waves{nullptr, 0, {{1, 1}}}, choice());
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(request[i], -1) << "element " << i;
    ASSERT_EQ(state[2 * i], counts[i]) << "element " << i << " took another number of steps";
    EXPECT_EQ(state[2 * i + 1], counts[i] * counts[i] * (counts[i] + 1) / 2) << "element " << i;
  }
  EXPECT_EQ(stats.resumed, more) << "each wave runs only the elements still going";
  // mpi too, whose ranks run the waves of their chunks: the deepest.
  EXPECT_EQ(stats.waves, static_cast<std::size_t>(kLongest - 1));
  EXPECT_TRUE(stats.refined.empty());
}

// A negative cap on the waves is refused (it once let a run that always
// asks for more go on for ever); a cap of 0 stops at the first request.
TEST_P(Conformance, WavesRefuseANegativeCapAndStopAtTheCap) {
  sh::Program p = SH_BEGIN_PROGRAM("always more") {
    sh::InputAttrib1i x;
    sh::OutputAttrib1i request;
    request = x * 0;  // 0: another wave, always
  } SH_END;
  sh::Channel<sh::Attrib1i> x(std::vector<std::int32_t>{1, 2, 3}), request;
  try {
    sh::run(p, {x}, {request}, sh::Waves{nullptr, 0, {}, -1}, choice());
    FAIL() << "a negative cap was accepted";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("max_waves must be 0 or more, not -1"), std::string::npos) << e.what();
  }
  try {
    sh::run(p, {x}, {request}, sh::Waves{nullptr, 0, {}, 2}, choice());
    FAIL() << "waves went on past the cap";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("after 2 waves"), std::string::npos) << e.what();
  }
}

// An error in a later wave names the element by its place in the stream,
// not in the gathered stopped elements: element 10 alone takes a third
// wave, and runs a loop past the cap there.
TEST_P(Conformance, AnErrorInALaterWaveNamesTheElementsOwnPlace) {
  sh::Program p = SH_BEGIN_PROGRAM("late runaway") {
    sh::InputAttrib1i id;
    sh::InputAttrib1i waves_so_far;
    sh::OutputAttrib1i request;
    sh::OutputAttrib1i waves_now;
    sh::Attrib1i w = waves_so_far + 1;
    sh::Attrib1f x = 1.0f;
    SH_IF(id == 10 && w == 3) {
      SH_WHILE(x > 0.0f) { x += 1.0f; } SH_ENDWHILE;
    } SH_ENDIF;
    waves_now = w + (x < 0.0f).cast<int>();  // reads the loop's result, so it is not left out
    request = cond(id == 10 && w < 3, sh::Attrib1i(0), sh::Attrib1i(-1));
  } SH_END;
  std::vector<std::int32_t> ids(40), zeros(40, 0);
  for (int i = 0; i < 40; ++i) ids[i] = i;
  sh::Channel<sh::Attrib1i> id(ids), so_far(zeros), request, now;
  sh::Options o;
  o.max_loop_iterations = 1000;
  try {
    sh::run(p, {id, so_far}, {request, now}, sh::Waves{nullptr, 0, {{1, 1}}}, choice(o));
    FAIL() << "an endless loop must be an error";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("element 10 "), std::string::npos) << e.what();
  }
}

// What a refiner's bind leaves is checked before a kernel reads it, the
// same on every backend (a table left out crashed the cpu backend's code,
// one without data crashed interp, a zero extent read zeros on cpu and
// opencl and was refused on interp).
TEST_P(Conformance, WavesRefuseTablesTheRefinerBoundWrongly) {
  ASSERT_TRUE(registered);
  sh::Table1D<sh::Attrib1i> values(8);
  values.assign(std::vector<std::int32_t>(8, 3));
  sh::Program p = SH_BEGIN_PROGRAM("bound wrongly") {
    sh::InputAttrib1i at;
    sh::OutputAttrib1i request;
    request = values[at] * 0 - 1;
  } SH_END;
  sh::Channel<sh::Attrib1i> at(std::vector<std::int32_t>{1, 2, 3}), request;
  const char* says[] = {"left 0 tables where the program reads 1", "made table 0 that has no elements",
                        "made table 0 that has 0 elements along dimension 0",
                        "made table 0 that is f32x4 of rank 1 where the program reads i32"};
  for (int fault = 0; fault < 4; ++fault) {
    BrokenBind refiner(fault);
    try {
      sh::run(p, {at}, {request}, sh::Waves{&refiner, 0, {}}, choice());
      ADD_FAILURE() << "fault " << fault << " was not found";
    } catch (const sh::Error& e) {
      EXPECT_NE(std::string(e.what()).find(says[fault]), std::string::npos) << e.what();
    }
  }
}

TEST_P(Conformance, WavesRefuseARequestOutputThatIsNotAnInt) {
  sh::Program p = SH_BEGIN_PROGRAM("bad waves") {
    sh::InputAttrib1f x;
    sh::OutputAttrib1f y;
    y = x;
  } SH_END;
  sh::Channel<sh::Attrib1f> x(std::vector<float>{1, 2}), y;
  LazySquares refiner(0);
  try {
    sh::run(p, {x}, {y}, sh::Waves{&refiner, 0, {}}, choice());
    FAIL() << "a float request output was accepted";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("output 0 holds the requests of waves, so it must be int1..int4"), std::string::npos)
        << e.what();
  }
  // An output or input that does not exist is named as given (a negative
  // one was named as slot 0, which exists).
  sh::Program ints = SH_BEGIN_PROGRAM("int waves") {
    sh::InputAttrib1i i;
    sh::OutputAttrib1i request;
    request = i * 0 - 1;
  } SH_END;
  sh::Channel<sh::Attrib1i> i(std::vector<std::int32_t>{1, 2}), request;
  for (auto [waves, says] : {std::pair{sh::Waves{nullptr, -1, {}}, "output -1 named for waves does not exist (1 outputs)"},
                             std::pair{sh::Waves{nullptr, 0, {{0, -3}}}, "input -3 named as carried does not exist (1 inputs)"}})
    try {
      sh::run(ints, {i}, {request}, waves, choice());
      FAIL() << "waves naming a slot that does not exist were accepted";
    } catch (const sh::Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace conformance
