#pragma once
// What a kernel does, from its IR.  How it reads its tables: where elements
// that run side by side (SIMD lanes along a row of the launch domain, or a
// GPU's work-items) read, so that a backend can load a run of them at once.
// What a kernel costs: operations counted by class, one per
// component, for straight-line code and per loop iteration; and the
// critical path of straight-line code under a machine with a given number
// of units per class and their latencies (a list scheduler over the
// dependence graph).  Moves and casts cost nothing here.
#include <array>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <string>
#include <vector>

#include "sh/ir/program.hpp"

namespace sh::analysis {

enum class Unit : std::uint8_t { Mul, Add, Div, Negate, Compare, Transcendental, TableRead };
inline constexpr int kUnits = 7;
const char* unit_name(Unit u);

struct OpCounts {
  std::array<std::uint64_t, kUnits> n{};
  std::uint64_t& operator[](Unit u) { return n[static_cast<int>(u)]; }
  std::uint64_t operator[](Unit u) const { return n[static_cast<int>(u)]; }
  std::uint64_t total() const;
  OpCounts& operator+=(const OpCounts& o);
  OpCounts times(std::uint64_t k) const;
  std::string describe() const;  // "9 mul, 7 add, 1 div, 2 neg"
};

struct LoopCost {
  std::string loop;                       // the loop's first line, as printed
  int depth = 0;                          // 0: outermost
  OpCounts per_iteration;                 // header, test, body and update (nested loops per their iteration count where known)
  std::optional<std::uint64_t> trips;     // a constant trip count, where the IR shows one
  std::optional<OpCounts> total;
};

struct Cost {
  OpCounts outside_loops;  // both sides of every branch counted
  std::vector<LoopCost> loops;
};

Cost count_operations(const ir::Program& p);
std::string describe(const Cost& c);

struct Machine {
  std::array<int, kUnits> units{1, 1, 1, 1, 1, 1, 1};      // 0: unbounded
  std::array<int, kUnits> latency{1, 1, 1, 1, 1, 1, 1};    // cycles
  bool one_at_a_time = false;  // a single unit for every class: sequential execution
};

// Cycles from the first operation to the last result of a straight-line
// program (throws sh::Error on one with branches or loops).
std::uint64_t critical_path(const ir::Program& p, const Machine& m);

// Where neighbouring elements of one row of the launch domain read a table:
// all at one element (coordinates that do not depend on the element), at
// consecutive elements (x + c along the row, where x is position()'s and c
// does not depend on the element; clamping at the table's edge is allowed),
// or anywhere.
enum class Access : std::uint8_t { Same, Consecutive, Scattered };
const char* access_name(Access a);

struct ReadAccess {
  // A hint from the IR alone: a backend that loads a run of elements on it
  // checks at run time that the lanes do read one (the row's and the
  // table's edges, data-dependent coordinates that happen to agree).
  Access hint = Access::Scattered;
  // Proven: the coordinates as asked (before the clamp to the table's edge)
  // are in every lane the first lane's plus (lane, 0, 0), so that a backend
  // need only test the run's ends against the table's.  Holds for values
  // each written once, outside every if and loop, from position(),
  // constants and uniforms by + and -.
  bool proven_run = false;
  // Proven too, for a run whose coordinates are position() plus constants:
  // those constants, dimension by dimension (coordinate d is position
  // component d plus offset[d]).  A backend can then test every such read
  // of an element batch against the table's edges once, before the body.
  std::optional<std::array<int, 3>> offset;
};

// Per table read (`load` of legal IR, `fetch` before it) in the program.
std::unordered_map<const ir::Assign*, ReadAccess> table_access(const ir::Program& p);

// A table's stencil taps (reads with a proven offset from position()):
// their smallest and largest offsets, dimension by dimension.  A backend
// tests a batch of elements against these once, before the body.
struct TapSpan {
  std::array<int, 3> low{}, high{};
};
// Per table of the program, its taps' span; none where it has no tap.
std::vector<std::optional<TapSpan>> tap_spans(const ir::Program& p,
                                              const std::unordered_map<const ir::Assign*, ReadAccess>& access);

// What SPMD code generation (elements side by side in SIMD lanes) needs
// to know about a program beyond its IR.
//
// Uniform values are the same in every lane that reads them: they stay
// scalars (a loop over a table's triangles reads each one once, not by a
// gather), and an `if` or a loop steered by them is a plain branch.
// Everything an input reaches is varying, but for a vote across lanes
// (any_lane), which is one answer for the lanes that vote.  So is a write
// where lanes may disagree (under a varying `if`, in a loop lanes leave at
// different iterations) of a variable live where the lanes that did not
// write it wait; one that only the writing lanes read stays uniform.
//
// A varying write under a mask must keep the inactive lanes' old values
// only where some lane may read them: where the variable is live at a point
// the inactive lanes wait at (after the `if` or loop, at the else side of an
// `if` while its then side runs, or at a loop's update, where continuing
// lanes rejoin).
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

// Whether a loop body continues its loop (a continue not of a loop nested
// in it).
bool continues(const ir::Block& body);

// By VarId, bit c: component c of the variable may be read as it was when
// the element began (zero), no write before the read on some path; an
// output read so when the element ends.  A backend that starts every
// register and array at zero needs to only for these (constants and
// uniforms, never written, have their read bits too).
std::vector<std::uint8_t> unwritten_reads(const ir::Program& p);

}  // namespace sh::analysis
