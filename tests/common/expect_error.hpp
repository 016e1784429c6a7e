#pragma once
// Runs `f` and expects an sh::Error whose message holds every fragment.
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include <sh/error.hpp>

template <class F>
void expect_error(F f, std::initializer_list<const char*> fragments) {
  try {
    f();
    FAIL() << "expected sh::Error";
  } catch (const sh::Error& e) {
    for (const char* s : fragments) EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what();
  }
}
