#pragma once
#include <optional>

#include "sh/analysis.hpp"

namespace sh::analysis {

// The class an operation is counted and scheduled in; none for moves.
std::optional<Unit> unit_of(ir::Op op);

}  // namespace sh::analysis
