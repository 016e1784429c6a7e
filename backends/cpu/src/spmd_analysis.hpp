#pragma once
// What SPMD lowering needs to know about a program beyond its IR.
//
// Uniform values are the same in every lane: they stay scalars (a loop over
// a table's triangles reads each one once, not by a gather), and an `if` or
// a loop steered by them is a plain branch.  Everything an input reaches,
// or that is written where lanes may disagree, is varying.
//
// A varying write under a mask must keep the inactive lanes' old values
// only where some lane may read them: where the variable is live at a point
// the inactive lanes wait at (after the `if` or loop, at the else side of an
// `if` while its then side runs, or at a loop's update, where continuing
// lanes rejoin).
#include <unordered_map>
#include <vector>

#include "sh/ir/program.hpp"

namespace sh::cpu {

using VarSet = std::vector<bool>;  // by VarId

struct SpmdFacts {
  VarSet varying;
  // Ifs whose condition is varying, loops whose lanes may leave at
  // different iterations: these run under masks, the others branch.
  std::unordered_map<const ir::Stmt*, bool> divergent;
  // Per if and loop: the variables live where its inactive lanes rejoin.
  std::unordered_map<const ir::Stmt*, VarSet> live_at_rejoin;
  // Per if: the variables live for the lanes that wait while its then side
  // runs (those after the if and those the else side reads).
  std::unordered_map<const ir::Stmt*, VarSet> live_during_then;
};

SpmdFacts analyse_spmd(const ir::Program& p);

}  // namespace sh::cpu
