// A program linked with sh::dsl alone (no backend library): sh.hpp names
// no backend, so it builds and links, and runs on the interpreter, the one
// backend dsl has.
#include <gtest/gtest.h>

#include <sh/sh.hpp>

namespace {

using namespace sh;

TEST(DslOnly, RunsOnTheInterpreterWithNoBackendLinked) {
  EXPECT_EQ(backend_names(), std::vector<std::string>{"interp"});
  EXPECT_EQ(default_backend_name(), "interp");
  Program p = SH_BEGIN_PROGRAM("twice") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1, 2, 3}), out;
  out = p << in;
  EXPECT_EQ(out.values(), (std::vector<float>{2, 4, 6}));
}

}  // namespace
