// Control flow: C's where the lanes agree (or there is one), masks where
// they may not, and the iteration cap's count in every loop.
#include "generator.hpp"

#include "sh/ir/printer.hpp"

namespace sh::opencl {

// In the SPMD form the rest of a block after a break or continue runs for
// no lane, so it is not written.
void Generator::block(const ir::Block& b, int depth) {
  for (const ir::Stmt& s : b) {
    if (auto* a = std::get_if<ir::Assign>(&s.node)) {
      assign(*a, depth);
    } else if (auto* i = std::get_if<ir::If>(&s.node)) {
      divergent(s) ? masked_branch(*i, s, depth) : branch(*i, depth);
    } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
      divergent(s) ? masked_loop(*l, s, depth) : loop(*l, s, depth);
    } else if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
      scatter(*sc, depth);
    } else if (auto* pf = std::get_if<ir::Prefetch>(&s.node)) {
      prefetch(*pf, depth);
    } else {
      leave(std::holds_alternative<ir::Break>(s.node), depth);
      return;
    }
  }
}

// A masked loop's breaking lanes leave it for good and its continuing
// lanes come back at the update; a branching loop is left with C's jumps.
void Generator::leave(bool is_break, int depth) {
  const LoopExit& l = exits_.back();
  if (!l.active.empty()) {
    if (is_break) line(depth, l.active + " &= ~exec;");
    line(depth, "exec = 0;");
  } else if (is_break) {
    line(depth, l.wrapped ? "{ " + l.flag + " = 1; break; }" : "break;");
  } else {
    line(depth, "continue;");
  }
}

// A branch's condition: the SPMD form branches only where the running
// lanes agree, on a scalar register or a uniform.
std::string Generator::truthy(const ir::Operand& o) const {
  const ir::Var& v = p_.var(o.var);
  int c = o.swizzle[0];
  if (v.kind == ir::VarKind::Const) return "(" + number(v.type.scalar, v.value[c]) + " > 0)";
  if (truth_[o.var]) return "(" + reg(o.var, c) + ".s0 != 0)";
  return "(" + reg(o.var, c) + (spmd() && v.kind != ir::VarKind::Uniform && !scalar_register(o.var) ? ".s0" : "") + " > 0)";
}

void Generator::branch(const ir::If& s, int depth) {
  line(depth, "if " + truthy(s.cond) + " {");
  block(s.then_body, depth + 1);
  if (!s.else_body.empty()) {
    line(depth, "} else {");
    block(s.else_body, depth + 1);
  }
  line(depth, "}");
}

// Each side runs under its share of the lanes, and only when that share
// has one; afterwards the lanes that finished either side go on (those
// that broke or continued inside it do not).
void Generator::masked_branch(const ir::If& s, const ir::Stmt& at, int depth) {
  std::string n = std::to_string(branches_++), before = "before" + n, taken = "taken" + n, done = "done" + n;
  std::string mask = vec("int");
  line(depth, "{");
  line(depth + 1, "const " + mask + " " + before + " = exec, " + taken + " = " + lanes_where(s.cond) + ";");
  line(depth + 1, "exec = " + before + " & " + taken + ";");
  side(s.then_body, facts_.live_during_then.at(&at), depth + 1);
  line(depth + 1, "const " + mask + " " + done + " = exec;");
  line(depth + 1, "exec = " + before + " & ~" + taken + ";");
  side(s.else_body, facts_.live_at_rejoin.at(&at), depth + 1);
  line(depth + 1, "exec |= " + done + ";");
  line(depth, "}");
}

void Generator::side(const ir::Block& body, const analysis::VarSet& live, int depth) {
  if (body.empty()) return;
  line(depth, "if (" + any("exec") + ") {");
  enter_masked(live);
  block(body, depth + 1);
  keep_.pop_back();
  line(depth, "}");
}

// Under a mask, a write to a variable live where the waiting lanes
// rejoin keeps their values; any other write is dead for them.
void Generator::enter_masked(const analysis::VarSet& live) {
  analysis::VarSet keep = live;
  if (!keep_.empty())
    for (std::size_t v = 0; v < keep.size(); ++v) keep[v] = keep[v] || keep_.back()[v];
  keep_.push_back(std::move(keep));
}

// Past the iteration cap the kernel stops and reports the loop and the
// element (in the SPMD form, the first lane still looping).  The first
// work-item there claims the report (status[2]) atomically, so that two
// never mix one's loop with the other's element.
void Generator::count_iteration(int number, const std::string& counter, const std::string& element, int depth) {
  line(depth, "if (++" + counter + " > " + std::to_string(o_.max_loop_iterations) +
                  "L) { if (atomic_cmpxchg((volatile __global int*)(status + 2), 0, 1) == 0) { status[0] = " +
                  std::to_string(number + 1) + "; status[1] = " + element + "; } return; }");
}

// for (;;) { count; [header; test]; body; update; [header; test] }.  A
// body with `continue` runs inside do { } while (0), where `continue`
// reaches the update and `break` needs a flag to leave the loop.
// A branching loop inside masked code runs for the lanes running there,
// which agree on its test; every one of them may have left already (a
// break under a uniform if empties exec and goes on): then it is
// skipped, as its test would be on values no lane holds.
void Generator::loop(const ir::Loop& l, const ir::Stmt& s, int depth) {
  if (!masked()) return branching_loop(l, s, depth, "e");
  line(depth, "if " + any("exec") + " {");
  branching_loop(l, s, depth + 1, "e + " + first_lane() + "(exec)");
  line(depth, "}");
}

void Generator::branching_loop(const ir::Loop& l, const ir::Stmt& s, int depth, const std::string& element) {
  int number = loops_++;
  std::string n = std::to_string(number), counter = "iterations" + n, flag = "leave" + n;
  bool wrapped = analysis::continues(l.body);
  line(depth, "// " + ir::print(p_, s));
  line(depth, "long " + counter + " = 0;");
  if (wrapped) line(depth, "int " + flag + " = 0;");
  line(depth, "for (;;) {");
  auto test = [&] {
    block(l.header, depth + 1);
    line(depth + 1, "if (!" + truthy(l.cond) + ") break;");
  };
  // A pass is counted once its test (at the top) lets it in.
  if (l.test_at_top) test();
  count_iteration(number, counter, element, depth + 1);
  exits_.push_back({"", wrapped, flag});
  if (wrapped) {
    line(depth + 1, "do {");
    block(l.body, depth + 2);
    line(depth + 1, "} while (0);");
    line(depth + 1, "if (" + flag + ") break;");
  } else {
    block(l.body, depth + 1);
  }
  exits_.pop_back();
  block(l.update, depth + 1);
  if (!l.test_at_top) test();
  line(depth, "}");
}

// The same loop while any lane loops: the test retires the lanes whose
// condition failed, every part runs for the lanes still looping, and
// every lane that entered leaves at the end.
void Generator::masked_loop(const ir::Loop& l, const ir::Stmt& s, int depth) {
  int number = loops_++;
  std::string n = std::to_string(number), counter = "iterations" + n, active = "active" + n, entered = "entered" + n;
  std::string mask = vec("int");
  line(depth, "// " + ir::print(p_, s));
  line(depth, "{");
  line(depth + 1, "const " + mask + " " + entered + " = exec;");
  line(depth + 1, mask + " " + active + " = exec;");
  line(depth + 1, "long " + counter + " = 0;");
  line(depth + 1, "for (;;) {");
  enter_masked(facts_.live_at_rejoin.at(&s));
  // Every lane may have left by a break in the last pass: the loop is over
  // then, before another is counted (as each element's own loop).
  line(depth + 2, "if (!" + any(active) + ") break;");
  auto test = [&] {
    line(depth + 2, "exec = " + active + ";");
    block(l.header, depth + 2);
    line(depth + 2, active + " &= " + lanes_where(l.cond) + ";");
    line(depth + 2, "if (!" + any(active) + ") break;");
  };
  if (l.test_at_top) test();
  count_iteration(number, counter, "e + " + first_lane() + "(" + active + ")", depth + 2);
  line(depth + 2, "exec = " + active + ";");
  exits_.push_back({active, false, ""});
  block(l.body, depth + 2);
  exits_.pop_back();
  line(depth + 2, "exec = " + active + ";");
  block(l.update, depth + 2);
  if (!l.test_at_top) test();
  keep_.pop_back();
  line(depth + 1, "}");
  line(depth + 1, "exec = " + entered + ";");
  line(depth, "}");
}

}  // namespace sh::opencl
