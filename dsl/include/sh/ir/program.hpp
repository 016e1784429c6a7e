#pragma once
// The IR of a program: a typed signature (inputs, outputs, uniforms, tables)
// and a body of structured statements.  Registers are variables, not SSA: an
// assignment writes the components its mask names and leaves the others.
#include <array>
#include <string>
#include <variant>
#include <vector>

#include "sh/ir/op.hpp"
#include "sh/ir/type.hpp"

namespace sh::ir {

using VarId = int;

// Array: an element's own scratch memory, `length` elements of `type`
// (a traversal's stack), zero when the element starts.  Only `element`
// reads it and only `store` writes it (ops.def); appended last, so that the
// serialized numbering of the others stays.
enum class VarKind : std::uint8_t { Input, Output, InOut, Uniform, Const, Temp, Array };
const char* var_kind_name(VarKind k);

struct Var {
  VarKind kind = VarKind::Temp;
  Type type;
  std::string name;            // for people only: never part of the hash
  std::array<double, 4> value{};  // the constant's components (Const only)
  int length = 0;                 // the array's elements (Array only)
};

// Arrays hold at most this many elements, and a program's arrays this
// many values in all: they live in registers' memory (a CPU thread's
// stack, which holds them for 16 elements side by side; an OpenCL
// work-item's private memory).
inline constexpr int kMaxArrayLength = 4096;
inline constexpr int kMaxArrayValues = 8192;

// Ifs and loops nest at most this deep: passes and backends walk the
// program's tree by recursion, a few stack frames a level (some 14 000
// levels overflowed an 8 MiB stack), and no program a person writes comes
// near it.
inline constexpr int kMaxNesting = 1000;

// A read of a variable through a swizzle; the swizzle's size is the width
// the operation sees.
struct Operand {
  VarId var = -1;
  Swizzle swizzle;
  int width() const { return swizzle.size; }
  // The variable's component that component i of the operand reads: a
  // one-component operand is the same in every component.
  int component(int i) const { return swizzle[width() == 1 ? 0 : i]; }
};

// A table the kernel reads, or an accumulator it adds into (Scatter).  An
// accumulator is never read by the program that adds into it: the order of
// the additions is left to the backend, so only the sums are defined.
// What a read outside a table gives (legalize.cpp lowers it): the nearest
// element on the edge, the element the coordinates wrap around to (as a
// tiled texture), or zero.  Adds into an accumulator always clamp.
enum class Edge : std::uint8_t { Clamp, Repeat, Zero };
const char* edge_name(Edge e);

struct TableDecl {
  Type element;
  int rank = 1;  // 1, 2 or 3 dimensions
  std::string name;
  bool accumulator = false;
  Edge edge = Edge::Clamp;
};

struct Stmt;
using Block = std::vector<Stmt>;

// dest[mask[i]] = op(args...)[i].  Table reads name their table.  A store
// writes one element of the array `dest` (mask: all its components) and
// leaves the others: the one assignment that does not overwrite its
// destination (overwrites()); a fill writes every element.
struct Assign {
  VarId dest = -1;
  Swizzle mask;
  Op op = Op::Mov;
  std::vector<Operand> args;
  int table = -1;
};

// Runs then_body where cond's single component is > 0, else_body otherwise.
struct If {
  Operand cond;
  Block then_body;
  Block else_body;
};

// One form serves while, do/until and for loops.  Each iteration runs header
// and tests cond (keep looping while cond > 0) either before the body
// (test_at_top) or after it.  `continue` goes on with update, then the test.
struct Loop {
  Block header;
  Operand cond;
  bool test_at_top = true;
  Block body;
  Block update;
};

struct Break {};
struct Continue {};

// Adds value to element index (integer coordinates, one per dimension,
// clamped to the edge like a read) of accumulator `table`: the language's
// reduction, a scatter-add.  Several elements may add to the same place.
struct Scatter {
  int table = -1;
  Operand index;
  Operand value;
};

// Asks for element index of table `table` (coordinates, one per
// dimension, as asked: legal IR does not clamp them, and one outside the
// table asks for nothing in it) to be brought near the
// processor, ahead of the read that will want it: a tree walk's next
// nodes, whose loads would otherwise wait on memory one after another.
// Only speed depends on it: a backend may do nothing, and no result, no
// fault and no output changes with it.
struct Prefetch {
  int table = -1;
  Operand index;
};

struct Stmt {
  std::variant<Assign, If, Loop, Break, Continue, Scatter, Prefetch> node;
};

struct Program {
  std::string name;
  std::vector<Var> vars;
  std::vector<VarId> inputs;    // in order; an InOut variable is in both lists
  std::vector<VarId> outputs;
  std::vector<VarId> uniforms;
  std::vector<TableDecl> tables;
  Block body;

  VarId add_var(Var v) {
    vars.push_back(std::move(v));
    return static_cast<VarId>(vars.size() - 1);
  }
  VarId add_const(Type t, const std::array<double, 4>& value);
  const Var& var(VarId id) const { return vars.at(static_cast<std::size_t>(id)); }
  Type type_of(VarId id) const { return var(id).type; }
};

// Whether the assignment replaces the components its mask names, as every
// assignment but a store into an array does.
inline bool overwrites(const Assign& a) { return a.op != Op::Store; }

// Operand reading all of a variable.
inline Operand whole(const Program& p, VarId id) {
  return Operand{id, Swizzle::identity(p.type_of(id).width)};
}

}  // namespace sh::ir
