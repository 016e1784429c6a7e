#pragma once
// Shrinks a case on which a backend disagrees with the interpreter: one
// stream element, then statements removed (and ifs replaced by a branch)
// one at a time while the disagreement stays.  Greedy, so the result is
// small, not the smallest.
#include <functional>
#include <string>

#include "generator.hpp"

namespace fuzz_ir {

// `fails` says whether a candidate (always one that passes ir::verify and
// keeps inexact values out of exact places) still shows the disagreement;
// `element` is the stream element tried first, `keep` the output (by name)
// that shows it, kept even where the body no longer writes it.
Case minimize(Case c, std::size_t element, const std::string& keep, const std::function<bool(const Case&)>& fails);

// The case reduced to stream element `element`.
Case only_element(const Case& c, std::size_t element);

}  // namespace fuzz_ir
