#include "harness.hpp"

namespace conformance {

std::vector<Mode> all_modes() {
  std::vector<Mode> modes;
  for (const std::string& b : sh::backend_names()) {
    modes.push_back({b, sh::Precision::F32, sh::MathMode::Precise});
    modes.push_back({b, sh::Precision::F64, sh::MathMode::Precise});
    modes.push_back({b, sh::Precision::F32, sh::MathMode::Fast});
  }
  return modes;
}

std::string describe(const Mode& m) {
  return m.backend + "_" + (m.precision == sh::Precision::F32 ? "f32" : "f64") + "_" +
         (m.math == sh::MathMode::Fast ? "fast" : "precise");
}

std::string mode_name(const testing::TestParamInfo<Mode>& info) { return describe(info.param); }

void PrintTo(const Mode& m, std::ostream* os) { *os << describe(m); }

INSTANTIATE_TEST_SUITE_P(Backends, Conformance, testing::ValuesIn(all_modes()), mode_name);
}  // namespace conformance
