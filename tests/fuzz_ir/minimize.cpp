#include "minimize.hpp"

#include <optional>

#include <sh/error.hpp>
#include <sh/ir/verifier.hpp>
#include <sh/ir/visitor.hpp>
#include <sh/passes.hpp>

#include "exactness.hpp"

namespace fuzz_ir {
namespace {

using namespace sh::ir;

enum class Edit { Remove, KeepThen, KeepElse, KeepBody };

// Applies `edit` to the statement numbered `target` in a preorder walk that
// starts at `first` (the prologue is left alone); says whether it did.
class Editor {
 public:
  Editor(int target, Edit edit) : target_(target), edit_(edit) {}
  bool applied = false;

  Block block(const Block& b) {
    Block out;
    for (const Stmt& s : b) statement(s, out);
    return out;
  }

 private:
  void statement(const Stmt& s, Block& out) {
    if (index_++ == target_) return edited(s, out);
    Stmt copy = s;
    if (auto* i = std::get_if<If>(&copy.node)) {
      i->then_body = block(i->then_body);
      i->else_body = block(i->else_body);
    } else if (auto* l = std::get_if<Loop>(&copy.node)) {
      l->header = block(l->header);
      l->body = block(l->body);
      l->update = block(l->update);
    }
    out.push_back(std::move(copy));
  }

  // Remove drops the statement; KeepThen and KeepElse put an if's branch
  // in its place, KeepBody a loop's body (run once).
  void edited(const Stmt& s, Block& out) {
    const If* i = std::get_if<If>(&s.node);
    const Loop* l = std::get_if<Loop>(&s.node);
    const Block* kept = edit_ == Edit::KeepThen && i ? &i->then_body
                        : edit_ == Edit::KeepElse && i ? &i->else_body
                        : edit_ == Edit::KeepBody && l ? &l->body
                                                       : nullptr;
    if (edit_ != Edit::Remove && !kept) return out.push_back(s);
    applied = true;
    if (kept) out.insert(out.end(), kept->begin(), kept->end());
  }

  int target_;
  Edit edit_;
  int index_ = 0;
};

bool acceptable(const Case& c) {
  try {
    verify(c.program);
  } catch (const sh::Error&) {
    return false;  // e.g. a break left outside its loop
  }
  return inexact_leak(c.program).empty();
}

std::optional<Case> try_edit(const Case& c, int target, Edit edit, const std::function<bool(const Case&)>& fails) {
  Case candidate = c;
  Block prologue(c.program.body.begin(), c.program.body.begin() + c.prologue);
  Block rest(c.program.body.begin() + c.prologue, c.program.body.end());
  Editor editor(target, edit);
  Block edited = editor.block(rest);
  if (!editor.applied) return std::nullopt;
  prologue.insert(prologue.end(), edited.begin(), edited.end());
  candidate.program.body = std::move(prologue);
  if (!acceptable(candidate) || !fails(candidate)) return std::nullopt;
  return candidate;
}

int statement_count(const Block& b) {
  int n = 0;
  for (const Stmt& s : b) {
    ++n;
    if (auto* i = std::get_if<If>(&s.node)) n += statement_count(i->then_body) + statement_count(i->else_body);
    if (auto* l = std::get_if<Loop>(&s.node))
      n += statement_count(l->header) + statement_count(l->body) + statement_count(l->update);
  }
  return n;
}

class Mentions : public Visitor {
 public:
  explicit Mentions(std::vector<int>& count) : count_(count) {}
  using Visitor::visit;
  void visit(const Assign& a) override {
    ++count_[a.dest];
    for (const Operand& o : a.args) ++count_[o.var];
  }
  void visit(const If& s) override {
    ++count_[s.cond.var];
    Visitor::visit(s);
  }
  void visit(const Loop& s) override {
    ++count_[s.cond.var];
    Visitor::visit(s);
  }
  void visit(const Scatter& s) override {
    ++count_[s.index.var];
    ++count_[s.value.var];
  }
  void visit(const Prefetch& s) override { ++count_[s.index.var]; }

 private:
  std::vector<int>& count_;
};

// Drops the prologue's writes of registers nothing after it mentions.
void drop_unused_initialisation(Case& c) {
  std::vector<int> count(c.program.vars.size(), 0);
  Mentions m(count);
  m.visit(Block(c.program.body.begin() + c.prologue, c.program.body.end()));
  for (VarId id : c.program.outputs) ++count[id];
  Block body;
  int kept = 0;
  for (int k = 0; k < static_cast<int>(c.program.body.size()); ++k) {
    const Stmt& s = c.program.body[k];
    if (k < c.prologue) {
      if (count[std::get<Assign>(s.node).dest] == 0) continue;
      ++kept;
    }
    body.push_back(s);
  }
  c.program.body = std::move(body);
  c.prologue = kept;
}

// Leaves out the inputs, uniforms and outputs nothing mentions after the
// prologue (with their data), then the variables no statement mentions.
Case without_unused_interface(Case c, const std::string& keep) {
  Program& p = c.program;
  std::vector<int> count(p.vars.size(), 0), everywhere(p.vars.size(), 0);
  Mentions m(count), all(everywhere);
  m.visit(Block(p.body.begin() + c.prologue, p.body.end()));
  all.visit(p.body);
  // Inputs and uniforms that the prologue reads for registers the body
  // uses stay; an output the body never writes goes.
  auto unused = [&](VarId id) { return count[id] == 0; };
  auto unread = [&](VarId id) { return everywhere[id] == 0; };
  for (std::size_t k = p.inputs.size(); k-- > 0;)
    if (unread(p.inputs[k]) && p.var(p.inputs[k]).kind == VarKind::Input) {
      p.vars[p.inputs[k]].kind = VarKind::Temp;
      p.inputs.erase(p.inputs.begin() + static_cast<std::ptrdiff_t>(k));
      c.inputs.erase(c.inputs.begin() + static_cast<std::ptrdiff_t>(k));
    }
  for (std::size_t k = p.uniforms.size(); k-- > 0;)
    if (unread(p.uniforms[k])) {
      p.vars[p.uniforms[k]].kind = VarKind::Temp;
      p.uniforms.erase(p.uniforms.begin() + static_cast<std::ptrdiff_t>(k));
      c.uniforms.erase(c.uniforms.begin() + static_cast<std::ptrdiff_t>(k));
    }
  std::erase_if(p.outputs, [&](VarId id) {
    if (!unused(id) || p.var(id).kind != VarKind::Output || p.var(id).name == keep) return false;
    p.vars[id].kind = VarKind::Temp;
    return true;
  });
  Block body;
  int prologue = 0;
  for (int k = 0; k < static_cast<int>(p.body.size()); ++k) {
    if (k < c.prologue && p.var(std::get<Assign>(p.body[k].node).dest).kind == VarKind::Temp &&
        unused(std::get<Assign>(p.body[k].node).dest))
      continue;
    prologue += k < c.prologue;
    body.push_back(p.body[k]);
  }
  p.body = std::move(body);
  c.prologue = prologue;
  c.program = sh::passes::compact_variables(std::move(c.program));
  return c;
}

}  // namespace

Case only_element(const Case& c, std::size_t element) {
  Case one = c;
  one.count = 1;
  for (Data& d : one.inputs) {
    auto first = d.values.begin() + static_cast<std::ptrdiff_t>(element * d.type.width);
    d.values.assign(first, first + d.type.width);
  }
  return one;
}

Case minimize(Case c, std::size_t element, const std::string& keep, const std::function<bool(const Case&)>& fails) {
  for (std::size_t k = 0; c.count > 1 && k <= c.count; ++k) {
    Case one = only_element(c, k == 0 ? element : k - 1);
    if (fails(one)) c = std::move(one);
  }
  for (bool progress = true; progress;) {
    progress = false;
    Block rest(c.program.body.begin() + c.prologue, c.program.body.end());
    for (int target = statement_count(rest) - 1; target >= 0; --target)
      for (Edit edit : {Edit::Remove, Edit::KeepThen, Edit::KeepElse, Edit::KeepBody})
        if (std::optional<Case> smaller = try_edit(c, target, edit, fails)) {
          c = std::move(*smaller);
          progress = true;
          break;
        }
  }
  Case trimmed = c;
  drop_unused_initialisation(trimmed);
  if (!acceptable(trimmed) || !fails(trimmed)) return c;
  // Twice: inputs that only dropped outputs' initialisation read go too.
  Case tidy = without_unused_interface(without_unused_interface(trimmed, keep), keep);
  return acceptable(tidy) && fails(tidy) ? tidy : trimmed;
}

}  // namespace fuzz_ir
