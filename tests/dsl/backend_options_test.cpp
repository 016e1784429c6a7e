// Backends' own options as dsl carries them: typed per backend, a string
// form parsed by the backend that owns the setting, part of the kernel key;
// and the registry's list of what is linked.  Two toy backends registered
// here (running interp's kernels) stand in for real ones, so that dsl is
// tested without any backend library.
#include <gtest/gtest.h>

#include <sh/sh.hpp>

#include <algorithm>

#include "../common/expect_error.hpp"
#include "../common/fresh.hpp"

namespace {

using namespace sh;

// A backend's options as a backend's header declares them.
template <const char* Name>
struct LevelOptions {
  static constexpr const char* backend_name = Name;
  int level = 0;
  Settings settings() const { return level ? Settings{{"level", std::to_string(level)}} : Settings{}; }
  void set(const std::string& name, const std::string& value) {
    if (name != "level") throw Error(std::string("the ") + Name + " backend has no setting '" + name + "'");
    if (value.empty() || value.find_first_not_of("0123456789") != std::string::npos)
      throw Error(std::string(Name) + " backend: setting \"level\" must be a whole number, not '" + value + "'");
    level = std::stoi(value);
  }
};

constexpr char kToy[] = "toy", kTwin[] = "twin";
using ToyOptions = LevelOptions<kToy>;
using TwinOptions = LevelOptions<kTwin>;

template <class O>
class LevelBackend : public Backend {
 public:
  std::string name() const override { return O::backend_name; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const Options& o) override {
    levels_compiled.push_back(o.get<O>().level);
    return find_backend("interp").compile(p, o);
  }
  std::vector<Setting> settings() const override { return {{"level", "a whole number"}}; }
  BackendOptions default_options() const override { return O{}; }
  std::vector<Variant> variants() const override { return {{"low", O{.level = 1}}, {"high", O{.level = 9}}}; }
  static inline std::vector<int> levels_compiled;
};

// Registered as a backend's library registers its own: before main.
const bool registered = (register_backend(kToy, [] { return std::make_unique<LevelBackend<ToyOptions>>(); }),
                         register_backend(kTwin, [] { return std::make_unique<LevelBackend<TwinOptions>>(); }), true);

TEST(BackendOptions, TypedOptionsAreKeptPerBackendWithDefaultsWhereNoneWasSet) {
  Options o;
  EXPECT_EQ(o.get<ToyOptions>().level, 0);
  o.set(ToyOptions{.level = 4}).set(TwinOptions{.level = 2});
  EXPECT_EQ(o.get<ToyOptions>().level, 4);
  EXPECT_EQ(o.get<TwinOptions>().level, 2);
  Options copy = o;
  copy.set(ToyOptions{.level = 5});
  EXPECT_EQ(o.get<ToyOptions>().level, 4) << "a copy's options are its own";
}

TEST(BackendOptions, TheStringFormIsParsedByTheBackendThatOwnsTheSetting) {
  Options o;
  o.set("toy.level", "3");
  EXPECT_EQ(o.get<ToyOptions>().level, 3);
  EXPECT_EQ(o.get<TwinOptions>().level, 0);
  o.set("twin.level", "7");
  EXPECT_EQ(o.get<TwinOptions>().level, 7);
  EXPECT_EQ(o.get<ToyOptions>().level, 3) << "setting one backend's option keeps the others";
}

TEST(BackendOptions, UnknownAmbiguousAndBadSettingsAreErrorsNamingThem) {
  Options o;
  expect_error([&] { o.set("colour", "red"); }, {"no linked backend has a setting 'colour'", "toy: level"});
  expect_error([&] { o.set("level", "1"); }, {"'level' is ambiguous", "toy.level", "twin.level"});
  expect_error([&] { o.set("toy.colour", "red"); }, {"the toy backend has no setting 'colour'", "level"});
  expect_error([&] { o.set("nowhere.level", "1"); }, {"no backend 'nowhere'", "interp"});
  expect_error([&] { o.set("toy.level", "high"); }, {"toy backend", "\"level\"", "'high'"});
  expect_error([&] { o.set("interp.level", "1"); }, {"the interp backend has no setting 'level'", "interp has no settings"});
  EXPECT_TRUE(o.backends.empty()) << "a failed set changes nothing";
}

TEST(BackendOptions, OptionsArePartOfTheKernelKey) {
  Options a, b, c;
  a.set(ToyOptions{.level = 2});
  b.set("toy.level", "2");
  EXPECT_EQ(a.key(), b.key()) << "typed and string forms are the same options";
  c.set(ToyOptions{});
  EXPECT_EQ(c.key(), Options{}.key()) << "defaults set are defaults";
  EXPECT_NE(a.key(), c.key());

  const float added = fresh_constant();  // a program no earlier run compiled
  Program p = SH_BEGIN_PROGRAM("keyed") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x + added;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1, 2}), out;
  auto& compiled = LevelBackend<ToyOptions>::levels_compiled;
  compiled.clear();
  EXPECT_TRUE(run(p, {in}, {out}, backend("toy", a)).compiled);
  EXPECT_FALSE(run(p, {in}, {out}, backend("toy", b)).compiled);
  EXPECT_TRUE(run(p, {in}, {out}, backend("toy", c)).compiled);
  EXPECT_EQ(compiled, (std::vector<int>{2, 0})) << "the kernel is compiled with the options it was asked for";
  EXPECT_EQ(out[1], 2 + added);
}

// A thread count no pool should have (millions crashed the thread library)
// or below zero is refused before anything is compiled, on every backend.
TEST(BackendOptions, ThreadsOutOfRangeAreRefusedByName) {
  Program p = SH_BEGIN_PROGRAM("threaded") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1, 2}), out;
  for (int threads : {-1, kMostThreads + 1, 10000000}) {
    Options o;
    o.threads = threads;
    for (const char* name : {"interp", "toy"})
      expect_error([&] { run(p, {in}, {out}, backend(name, o)); },
                   {"program 'threaded'", "Options::threads = ", "0 (every core) to 1024"});
  }
  Options most;
  most.threads = kMostThreads;
  run(p, {in}, {out}, backend("interp", most));
  EXPECT_EQ(out[1], 4.f);
}

TEST(BackendOptions, AVariantCarriesItsBackendsOptions) {
  std::vector<BackendInfo> all = backends();
  auto toy = std::find_if(all.begin(), all.end(), [](const BackendInfo& b) { return b.name == "toy"; });
  ASSERT_NE(toy, all.end());
  ASSERT_EQ(toy->variants.size(), 2u);
  EXPECT_EQ(toy->variants[1].name, "high");
  Options o;
  o.set(toy->variants[1].options);
  EXPECT_EQ(o.get<ToyOptions>().level, 9);
  EXPECT_EQ(toy->variants[1].options.settings(), (Settings{{"level", "9"}}));
  ASSERT_EQ(toy->settings.size(), 1u);
  EXPECT_EQ(toy->settings[0].name, "level");
}

TEST(Registry, BackendsListsInterpAndEveryRegisteredBackend) {
  std::vector<BackendInfo> all = backends();
  std::vector<std::string> names;
  for (const BackendInfo& b : all) names.push_back(b.name);
  EXPECT_EQ(names, backend_names());
  for (const char* name : {"interp", "toy", "twin"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  EXPECT_NE(preferred_backend_name(), "toy") << "registered with preference 0, below interp's";
  auto interp = std::find_if(all.begin(), all.end(), [](const BackendInfo& b) { return b.name == "interp"; });
  EXPECT_EQ(interp->preference, 1);
  EXPECT_TRUE(interp->settings.empty());
}

TEST(Registry, ReadingThroughSourcesIsACapabilityABackendMayLack) {
  Options o;
  o.threads = 4;
  EXPECT_TRUE(find_backend("interp").read_through_sources(o));
  EXPECT_FALSE(find_backend("toy").read_through_sources(o));
  EXPECT_EQ(o.threads, 4);
  EXPECT_TRUE(o.backends.empty());
}

}  // namespace
