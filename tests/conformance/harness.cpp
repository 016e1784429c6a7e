#include "harness.hpp"

namespace conformance {

std::vector<Mode> all_modes() {
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
