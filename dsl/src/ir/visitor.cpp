#include "sh/ir/visitor.hpp"

namespace sh::ir {

void Visitor::visit(const Block& block) {
  for (const Stmt& s : block) visit(s);
}

void Visitor::visit(const Stmt& stmt) {
  std::visit([this](const auto& node) { visit(node); }, stmt.node);
}

void Visitor::visit(const If& s) {
  visit(s.then_body);
  visit(s.else_body);
}

void Visitor::visit(const Loop& s) {
  visit(s.header);
  visit(s.body);
  visit(s.update);
}

Block Mutator::mutate(Block block) {
  Block out;
  out.reserve(block.size());
  for (Stmt& s : block)
    std::visit([this, &out](auto& node) { mutate(std::move(node), out); }, s.node);
  return out;
}

void Mutator::mutate(Assign s, Block& out) { out.push_back(Stmt{std::move(s)}); }

void Mutator::mutate(If s, Block& out) {
  s.then_body = mutate(std::move(s.then_body));
  s.else_body = mutate(std::move(s.else_body));
  out.push_back(Stmt{std::move(s)});
}

void Mutator::mutate(Loop s, Block& out) {
  s.header = mutate(std::move(s.header));
  s.body = mutate(std::move(s.body));
  s.update = mutate(std::move(s.update));
  out.push_back(Stmt{std::move(s)});
}

void Mutator::mutate(Break s, Block& out) { out.push_back(Stmt{s}); }
void Mutator::mutate(Continue s, Block& out) { out.push_back(Stmt{s}); }
void Mutator::mutate(Scatter s, Block& out) { out.push_back(Stmt{s}); }
void Mutator::mutate(Prefetch s, Block& out) { out.push_back(Stmt{s}); }

bool uses(const Program& p, Op op) {
  struct Finder : Visitor {
    Op op;
    bool found = false;
    void visit(const Assign& a) override { found = found || a.op == op; }
    using Visitor::visit;
  } finder;
  finder.op = op;
  finder.visit(p.body);
  return finder.found;
}

}  // namespace sh::ir
