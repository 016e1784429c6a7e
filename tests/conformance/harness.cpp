#include "harness.hpp"

namespace conformance {
namespace {

std::string round_trip_fault(const sh::ir::Program& p, const std::string& what, const std::string& before,
                             const std::string& after) {
  return "roundtrip: program '" + p.name + "': " + what + "\nbefore:\n" + before + "after:\n" + after;
}

// Every program a test compiles goes through the serializer and back (the
// bytes the mpi wire, the kernel cache's key and --dump-ir use): the copy
// must serialize to the same bytes, print the same text and hash the same;
// then the interpreter compiles the copy, so the test's answers check it.
class RoundTrip : public sh::Backend {
 public:
  std::string name() const override { return "roundtrip"; }
  std::unique_ptr<sh::Kernel> compile(const sh::ir::Program& p, const sh::Options& o) override {
    std::string bytes = sh::ir::serialize(p);
    sh::ir::Program back = sh::ir::deserialize(bytes);
    if (sh::ir::serialize(back) != bytes)
      throw sh::Error(round_trip_fault(p, "serialized again, the bytes differ", sh::ir::print(p), sh::ir::print(back)));
    if (sh::ir::print(back) != sh::ir::print(p))
      throw sh::Error(round_trip_fault(p, "prints differently", sh::ir::print(p), sh::ir::print(back)));
    if (sh::ir::structural_hash(back) != sh::ir::structural_hash(p))
      throw sh::Error(round_trip_fault(p, "hashes differently", sh::ir::print(p), sh::ir::print(back)));
    return sh::find_backend("interp").compile(back, o);
  }
};

}  // namespace

std::vector<Mode> all_modes() {
  static const bool registered = [] {
    sh::register_backend("roundtrip", [] { return std::make_unique<RoundTrip>(); });
    return true;
  }();
  (void)registered;
  std::vector<Mode> modes;
  for (const std::string& b : sh::backend_names())
    for (const sh::Backend::Variant& v : sh::find_backend(b).variants()) {
      modes.push_back({b, v, sh::Precision::F32, sh::MathMode::Precise});
      modes.push_back({b, v, sh::Precision::F64, sh::MathMode::Precise});
      modes.push_back({b, v, sh::Precision::F32, sh::MathMode::Fast});
    }
  return modes;
}

std::string describe(const Mode& m) {
  std::string variant = m.variant.name.empty() ? "" : m.variant.name + "_";
  return m.backend + "_" + variant + (m.precision == sh::Precision::F32 ? "f32" : "f64") + "_" +
         (m.math == sh::MathMode::Fast ? "fast" : "precise");
}

std::string mode_name(const testing::TestParamInfo<Mode>& info) { return describe(info.param); }

void PrintTo(const Mode& m, std::ostream* os) { *os << describe(m); }

INSTANTIATE_TEST_SUITE_P(Backends, Conformance, testing::ValuesIn(all_modes()), mode_name);
}  // namespace conformance
