#pragma once
// The single error type of the project: every fault a user can cause (while
// recording, optimising, compiling or running a program) is reported as an
// sh::Error whose message names the program and what is wrong.
#include <stdexcept>
#include <string>

namespace sh {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace sh
