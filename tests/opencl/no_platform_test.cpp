// Run with no OpenCL platform visible (OCL_ICD_VENDORS points nowhere):
// using the backend is an sh::Error that says how to install PoCL, and the
// rest of the project works.
#include <gtest/gtest.h>

#include <sh/opencl.hpp>
#include <sh/sh.hpp>

namespace {

using namespace sh;

TEST(OpenClWithoutPlatform, ErrorSaysHowToInstallPocl) {
  Program p = SH_BEGIN_PROGRAM("anything") {
    InputAttrib1f x;
    OutputAttrib1f r;
    r = x * 2.0f;
  } SH_END;
  Channel<Attrib1f> x(std::vector<float>{1, 2}), r;
  try {
    run(p, {x}, {r}, backend("opencl"));
    FAIL() << "expected sh::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no OpenCL platform"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("pocl-opencl-icd"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(opencl::devices().empty());
  run(p, {x}, {r}, backend("interp"));
  EXPECT_EQ(r[1], 4.f);
}

}  // namespace
