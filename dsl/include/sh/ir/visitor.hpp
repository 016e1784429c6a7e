#pragma once
// Walking and rewriting statement trees.  A Visitor reads; a Mutator rebuilds
// a block, where each statement may become none, one or several.  Passes
// override only the node kinds they care about.
#include "sh/ir/program.hpp"

namespace sh::ir {

class Visitor {
 public:
  virtual ~Visitor() = default;
  void visit(const Block& block);
  void visit(const Stmt& stmt);

  virtual void visit(const Assign&) {}
  virtual void visit(const If& s);
  virtual void visit(const Loop& s);
  virtual void visit(const Break&) {}
  virtual void visit(const Continue&) {}
  virtual void visit(const Scatter&) {}
  virtual void visit(const Prefetch&) {}
};

class Mutator {
 public:
  virtual ~Mutator() = default;
  Block mutate(Block block);

  // Each appends what `s` becomes to `out`; the defaults keep it, with its
  // nested blocks mutated.
  virtual void mutate(Assign s, Block& out);
  virtual void mutate(If s, Block& out);
  virtual void mutate(Loop s, Block& out);
  virtual void mutate(Break s, Block& out);
  virtual void mutate(Continue s, Block& out);
  virtual void mutate(Scatter s, Block& out);
  virtual void mutate(Prefetch s, Block& out);
};

// Whether some assignment in the program performs `op`.
bool uses(const Program& p, Op op);

}  // namespace sh::ir
