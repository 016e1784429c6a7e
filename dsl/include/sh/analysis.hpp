#pragma once
// What a kernel costs, from its IR: operations counted by class, one per
// component, for straight-line code and per loop iteration; and the
// critical path of straight-line code under a machine with a given number
// of units per class and their latencies (a list scheduler over the
// dependence graph).  Moves and casts cost nothing here.
#include <array>
#include <cstdint>
#include <optional>
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

}  // namespace sh::analysis
