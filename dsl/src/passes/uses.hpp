#pragma once
// Facts about where variables are defined and read, shared by the passes.
#include <set>
#include <unordered_map>
#include <vector>

#include "sh/ir/program.hpp"

namespace sh::passes {

// A statement's position: the block that holds it and its index there.
struct Site {
  const ir::Block* block = nullptr;
  std::size_t index = 0;
};

using Path = std::vector<Site>;  // from the program body down to a statement

// True where every run that reaches `path` has passed `site` first.
bool dominated(const Path& path, const Site& site);

struct Definitions {
  std::unordered_map<ir::VarId, int> count;     // assignments to each variable
  std::unordered_map<ir::VarId, Path> single;   // where, for those assigned once
  std::unordered_map<ir::VarId, const ir::Assign*> assign;
};
Definitions collect_definitions(const ir::Block& body);

// Variables assigned anywhere inside a block (nested blocks included).
std::set<ir::VarId> written_in(const ir::Block& b);
std::set<ir::VarId> written_in(const ir::Loop& l);

// Calls f(operand&) for every operand of the statement itself (not nested).
template <class S, class F>
void for_each_own_operand(S& s, F f) {
  if (auto* a = std::get_if<ir::Assign>(&s.node)) {
    for (auto& o : a->args) f(o);
  } else if (auto* i = std::get_if<ir::If>(&s.node)) {
    f(i->cond);
  } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
    f(l->cond);
  } else if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
    f(sc->index);
    f(sc->value);
  } else if (auto* pf = std::get_if<ir::Prefetch>(&s.node)) {
    f(pf->index);
  }
}

// Is the variable immutable for the whole run (never assigned)?
inline bool never_written(const ir::Program& p, const Definitions& d, ir::VarId v) {
  ir::VarKind k = p.var(v).kind;
  return k == ir::VarKind::Const || k == ir::VarKind::Uniform || (k == ir::VarKind::Input && !d.count.count(v));
}

}  // namespace sh::passes
