#pragma once
#include <memory>

#include "sh/backend.hpp"

namespace sh::interp {

// The reference backend: walks the IR for each element, computing every
// operation exactly as sh::ir::eval defines it.
std::unique_ptr<Backend> make_backend();

}  // namespace sh::interp
