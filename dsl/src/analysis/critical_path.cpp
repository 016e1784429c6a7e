// A list scheduler over the dependence graph of straight-line code: each
// operation (one per component) starts when its operands are ready and a
// unit of its class is free, highest remaining path first; units are not
// pipelined.  Moves pass values on at no cost.
#include <algorithm>
#include <map>
#include <queue>

#include "units.hpp"
#include "sh/error.hpp"

namespace sh::analysis {

namespace {

struct Node {
  int unit = -1;  // -1: a move (no cost)
  std::vector<int> preds, succs;
  std::uint64_t tail = 0;  // longest latency path from here to the end
};

std::vector<Node> dependence_graph(const ir::Program& p, const Machine& m) {
  std::vector<Node> nodes;
  std::map<std::pair<ir::VarId, int>, int> producer;  // (variable, component) -> node
  // A local array's reads wait on every store since its last fill: the
  // index each reads and each stored is known only as the program runs.
  std::map<ir::VarId, std::vector<int>> array_writers;
  auto is_array = [&](ir::VarId v) { return p.var(v).kind == ir::VarKind::Array; };
  for (const ir::Stmt& s : p.body) {
    if (std::holds_alternative<ir::Prefetch>(s.node)) continue;  // nothing waits on it
    auto* a = std::get_if<ir::Assign>(&s.node);
    if (!a) throw Error("program '" + p.name + "': the critical path is computed for straight-line assignments only (no branch, loop or scatter)");
    auto u = unit_of(a->op);
    std::vector<int> made;
    int lanes = is_table_read(a->op) ? 1 : a->mask.size;
    for (int i = 0; i < lanes; ++i) {
      Node n;
      n.unit = u ? static_cast<int>(*u) : -1;
      for (const ir::Operand& o : a->args) {
        if (is_array(o.var)) {
          const std::vector<int>& writers = array_writers[o.var];
          n.preds.insert(n.preds.end(), writers.begin(), writers.end());
          continue;
        }
        int reads = is_table_read(a->op) ? o.width() : 1;
        for (int r = 0; r < reads; ++r) {
          int c = is_table_read(a->op) ? o.swizzle[r] : o.component(i);
          auto it = producer.find({o.var, c});
          if (it != producer.end()) n.preds.push_back(it->second);
        }
      }
      nodes.push_back(std::move(n));
      made.push_back(static_cast<int>(nodes.size() - 1));
    }
    if (is_array(a->dest)) {
      std::vector<int>& writers = array_writers[a->dest];
      if (a->op == ir::Op::Fill) writers.clear();
      writers.insert(writers.end(), made.begin(), made.end());
      continue;
    }
    for (int i = 0; i < a->mask.size; ++i) producer[{a->dest, a->mask[i]}] = made[is_table_read(a->op) ? 0 : i];
  }
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (int pr : nodes[i].preds) nodes[pr].succs.push_back(static_cast<int>(i));
  for (std::size_t i = nodes.size(); i-- > 0;) {
    std::uint64_t own = nodes[i].unit < 0 ? 0 : static_cast<std::uint64_t>(m.latency[nodes[i].unit]);
    std::uint64_t after = 0;
    for (int s : nodes[i].succs) after = std::max(after, nodes[s].tail);
    nodes[i].tail = own + after;
  }
  return nodes;
}

}  // namespace

std::uint64_t critical_path(const ir::Program& p, const Machine& m) {
  for (int u = 0; u < kUnits; ++u)
    if (m.units[u] < 0 || m.latency[u] < 0)
      throw Error("critical_path: machine class " + std::to_string(u) + " has " + std::to_string(m.units[u]) +
                  " units of latency " + std::to_string(m.latency[u]) + "; neither may be negative");
  std::vector<Node> nodes = dependence_graph(p, m);
  std::vector<std::uint64_t> ready_at(nodes.size(), 0), done_at(nodes.size(), 0);
  std::vector<int> waiting(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) waiting[i] = static_cast<int>(nodes[i].preds.size());
  // Free times of each unit of each class (one shared unit when sequential).
  std::vector<std::vector<std::uint64_t>> free_at(kUnits);
  for (int u = 0; u < kUnits; ++u) free_at[u].assign(m.one_at_a_time ? 0 : static_cast<std::size_t>(m.units[u]), 0);
  std::uint64_t shared_free = 0;
  auto later = [&](int a, int b) {
    return ready_at[a] != ready_at[b] ? ready_at[a] > ready_at[b] : nodes[a].tail < nodes[b].tail;
  };
  std::priority_queue<int, std::vector<int>, decltype(later)> ready(later);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (!waiting[i]) ready.push(static_cast<int>(i));
  std::uint64_t end = 0;
  while (!ready.empty()) {
    int n = ready.top();
    ready.pop();
    std::uint64_t start = ready_at[n], finish = start;
    if (nodes[n].unit >= 0) {
      auto latency = static_cast<std::uint64_t>(m.latency[nodes[n].unit]);
      if (m.one_at_a_time) {
        start = std::max(start, shared_free);
        shared_free = start + latency;
      } else if (!free_at[nodes[n].unit].empty()) {
        auto unit = std::min_element(free_at[nodes[n].unit].begin(), free_at[nodes[n].unit].end());
        start = std::max(start, *unit);
        *unit = start + latency;
      }
      finish = start + latency;
    }
    done_at[n] = finish;
    end = std::max(end, finish);
    for (int s : nodes[n].succs) {
      ready_at[s] = std::max(ready_at[s], finish);
      if (--waiting[s] == 0) ready.push(s);
    }
  }
  return end;
}

}  // namespace sh::analysis
