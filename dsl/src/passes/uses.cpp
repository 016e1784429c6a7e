#include "uses.hpp"

#include "sh/ir/visitor.hpp"

namespace sh::passes {
namespace {

void collect(const ir::Block& b, Definitions& d, Path& path) {
  for (std::size_t i = 0; i < b.size(); ++i) {
    const ir::Stmt& s = b[i];
    path.push_back(Site{&b, i});
    if (auto* a = std::get_if<ir::Assign>(&s.node)) {
      ++d.count[a->dest];
      d.single[a->dest] = path;
      d.assign[a->dest] = a;
    } else if (auto* f = std::get_if<ir::If>(&s.node)) {
      collect(f->then_body, d, path);
      collect(f->else_body, d, path);
    } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
      collect(l->header, d, path);
      collect(l->body, d, path);
      collect(l->update, d, path);
    }
    path.pop_back();
  }
}

struct Writes : ir::Visitor {
  using ir::Visitor::visit;
  std::set<ir::VarId> ids;
  void visit(const ir::Assign& a) override { ids.insert(a.dest); }
};

}  // namespace

bool dominated(const Path& path, const Site& site) {
  for (const Site& s : path)
    if (s.block == site.block && s.index > site.index) return true;
  return false;
}

Definitions collect_definitions(const ir::Block& body) {
  Definitions d;
  Path path;
  collect(body, d, path);
  for (auto it = d.single.begin(); it != d.single.end();) {
    if (d.count[it->first] != 1) {
      d.assign.erase(it->first);
      it = d.single.erase(it);
    } else {
      ++it;
    }
  }
  return d;
}

std::set<ir::VarId> written_in(const ir::Block& b) {
  Writes w;
  w.visit(b);
  return w.ids;
}

std::set<ir::VarId> written_in(const ir::Loop& l) {
  Writes w;
  w.visit(l.header);
  w.visit(l.body);
  w.visit(l.update);
  return w.ids;
}

}  // namespace sh::passes
