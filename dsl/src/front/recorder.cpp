#include "recorder.hpp"

#include <atomic>

#include "sh/error.hpp"
#include "sh/ir/printer.hpp"

namespace sh::detail {
namespace {

thread_local std::vector<Recorder*> recording_stack;

std::string describe(const ir::Program& p, ir::VarId id) {
  const ir::Var& v = p.var(id);
  std::string what = ir::var_kind_name(v.kind);
  if (!v.name.empty()) return what + " '" + v.name + "'";
  return what + " %" + std::to_string(id);
}

}  // namespace

Recorder* current_recorder() { return recording_stack.empty() ? nullptr : recording_stack.back(); }

RecordingScope::RecordingScope(std::string name) : recorder_(std::make_unique<Recorder>(std::move(name))) {
  recording_stack.push_back(recorder_.get());
}

RecordingScope::~RecordingScope() { recording_stack.pop_back(); }

Recorder::Recorder(std::string name) : current_(&prog_.body) {
  static std::atomic<std::uint64_t> recordings{0};
  serial_ = ++recordings;
  prog_.name = std::move(name);
}

void Recorder::fail(const std::string& what) const { throw Error("program '" + prog_.name + "': " + what); }

void Recorder::declare(const std::shared_ptr<VarNode>& node, Declared how) {
  node->recording = serial_;
  ir::VarId id = id_of(node);
  if (how == Declared::Input || how == Declared::InOut) prog_.inputs.push_back(id);
  if (how == Declared::Output || how == Declared::InOut) prog_.outputs.push_back(id);
}

ir::VarId Recorder::id_of(const std::shared_ptr<VarNode>& node) {
  auto it = ids_.find(node.get());
  if (it != ids_.end()) return it->second;
  if (node->kind != ir::VarKind::Uniform && node->kind != ir::VarKind::Const && node->recording != serial_)
    fail("uses a variable of another program ('" + node->name + "'); pass values through inputs or uniforms");
  ir::Var v;
  v.kind = node->kind;
  v.type = node->type;
  v.name = node->name;
  v.length = node->length;
  if (node->kind == ir::VarKind::Const) v.value = node->value;
  ir::VarId id = prog_.add_var(std::move(v));
  if (node->kind == ir::VarKind::Uniform) {
    prog_.uniforms.push_back(id);
    uniforms_.push_back(node);
  }
  ids_.emplace(node.get(), id);
  alive_.push_back(node);
  return id;
}

ir::Operand Recorder::read(const Value& v) {
  ir::VarId id = id_of(v.node);
  if (v.node->kind == ir::VarKind::Output && !written_outputs_.count(id))
    fail("reads " + describe(prog_, id) + " before anything was written to it");
  return ir::Operand{id, v.swizzle};
}

// As in Sh, a program may write its inputs: the first write gives the input
// a local copy (a fresh register, copied from the input at the start of the
// program), and from then on the program reads and writes the copy.  The
// input stream itself is never written.
ir::VarId Recorder::local_copy(const VarNode* input, ir::VarId id) {
  ir::Var copy;
  copy.type = prog_.var(id).type;
  if (!prog_.var(id).name.empty()) copy.name = prog_.var(id).name + "_local";
  ir::Swizzle whole = ir::Swizzle::identity(copy.type.width);
  ir::VarId local = prog_.add_var(std::move(copy));
  local_copies_.push_back(ir::Assign{local, whole, ir::Op::Mov, {ir::Operand{id, whole}}, -1});
  ids_[input] = local;
  return local;
}

ir::VarId Recorder::write_target(const Value& v) {
  ir::VarId id = id_of(v.node);
  switch (v.node->kind) {
    case ir::VarKind::Input:
      if (prog_.var(id).kind == ir::VarKind::Input) id = local_copy(v.node.get(), id);
      break;
    case ir::VarKind::Uniform:
      fail("writes " + describe(prog_, id) +
           "; uniforms are set on the host between runs (Sh wrote a copy local to the program: write to a "
           "variable initialised from the uniform instead)");
    case ir::VarKind::Const: fail("writes a constant");
    default: break;
  }
  if (v.swizzle.has_repeats()) fail("writes through a swizzle that names a component twice");
  return id;
}

void Recorder::rename(const VarNode* node, const std::string& name) {
  auto it = ids_.find(node);
  if (it != ids_.end()) prog_.vars[static_cast<std::size_t>(it->second)].name = name;
}

ir::VarId Recorder::new_temp(ir::Type t) {
  ir::Var v;
  v.type = t;
  return prog_.add_var(std::move(v));
}

int Recorder::table_index(const std::shared_ptr<TableStorage>& table) {
  for (std::size_t i = 0; i < tables_.size(); ++i)
    if (tables_[i] == table) return static_cast<int>(i);
  tables_.push_back(table);
  prog_.tables.push_back(table->decl);
  return static_cast<int>(tables_.size() - 1);
}

void Recorder::emit(ir::Assign a) {
  if (prog_.var(a.dest).kind == ir::VarKind::Output || prog_.var(a.dest).kind == ir::VarKind::InOut)
    written_outputs_.insert(a.dest);
  current_->push_back(ir::Stmt{std::move(a)});
}

Value Recorder::emit_result(ir::Type type, ir::Op op, std::vector<ir::Operand> args, int table) {
  auto node = std::make_shared<VarNode>();
  node->type = type;
  node->recording = serial_;
  ir::VarId dest = id_of(node);
  ir::Swizzle all = ir::Swizzle::identity(type.width);
  emit(ir::Assign{dest, all, op, std::move(args), table});
  return Value{std::move(node), all};
}

// ---- control flow ------------------------------------------------------

const char* Recorder::frame_name(Frame f) {
  switch (f) {
    case Frame::IfThen: case Frame::IfElse: return "SH_IF (no SH_ENDIF)";
    case Frame::WhileHeader: case Frame::WhileBody: return "SH_WHILE (no SH_ENDWHILE)";
    case Frame::DoBody: case Frame::DoHeader: return "SH_DO (no SH_UNTIL)";
    default: return "SH_FOR (no SH_ENDFOR)";
  }
}

ir::Operand Recorder::condition(const Value& cond, const char* construct) {
  if (cond.width() != 1)
    fail(std::string(construct) + " condition has " + std::to_string(cond.width()) +
         " components; it must have one (use any() or all())");
  return read(cond);
}

Recorder::Open& Recorder::expect(std::initializer_list<Frame> frames, const char* what) {
  if (!open_.empty())
    for (Frame f : frames)
      if (open_.back().frame == f) return open_.back();
  fail(std::string(what) + (open_.empty() ? "" : std::string(" inside an open ") + frame_name(open_.back().frame)));
}

void Recorder::close(ir::Block* next) {
  open_.pop_back();
  current_ = next;
}

void Recorder::check_nesting(const char* what) const {
  if (open_.size() >= static_cast<std::size_t>(ir::kMaxNesting))
    fail(std::string(what) + " nested deeper than " + std::to_string(ir::kMaxNesting) + " levels of control flow");
}

void Recorder::begin_if(const Value& cond) {
  check_nesting("SH_IF");
  ir::If node;
  node.cond = condition(cond, "SH_IF");
  current_->push_back(ir::Stmt{std::move(node)});
  ir::Stmt* stmt = &current_->back();
  open_.push_back({Frame::IfThen, stmt, current_});
  current_ = &std::get<ir::If>(stmt->node).then_body;
}

void Recorder::begin_else() {
  Open& o = expect({Frame::IfThen}, "SH_ELSE without SH_IF");
  o.frame = Frame::IfElse;
  current_ = &std::get<ir::If>(o.stmt->node).else_body;
}

void Recorder::end_if() { close(expect({Frame::IfThen, Frame::IfElse}, "SH_ENDIF without SH_IF").outer); }

ir::Loop& Recorder::open_loop(Frame first, bool test_at_top) {
  check_nesting("a loop");
  ir::Loop loop;
  loop.test_at_top = test_at_top;
  current_->push_back(ir::Stmt{std::move(loop)});
  ir::Stmt* stmt = &current_->back();
  open_.push_back({first, stmt, current_});
  return std::get<ir::Loop>(stmt->node);
}

void Recorder::begin_while() { current_ = &open_loop(Frame::WhileHeader, true).header; }

void Recorder::while_condition(const Value& cond) {
  Open& o = expect({Frame::WhileHeader}, "SH_WHILE condition outside SH_WHILE");
  auto& loop = std::get<ir::Loop>(o.stmt->node);
  loop.cond = condition(cond, "SH_WHILE");
  o.frame = Frame::WhileBody;
  current_ = &loop.body;
}

void Recorder::end_while() { close(expect({Frame::WhileBody}, "SH_ENDWHILE without SH_WHILE").outer); }

void Recorder::begin_do() { current_ = &open_loop(Frame::DoBody, false).body; }

void Recorder::begin_until() {
  Open& o = expect({Frame::DoBody}, "SH_UNTIL without SH_DO");
  o.frame = Frame::DoHeader;
  current_ = &std::get<ir::Loop>(o.stmt->node).header;
}

void Recorder::until_condition(const Value& cond) {
  Open& o = expect({Frame::DoHeader}, "SH_UNTIL condition outside SH_UNTIL");
  ir::Operand until = condition(cond, "SH_UNTIL");
  // The loop goes on while the until-condition is false.
  ir::VarId keep_going = new_temp({prog_.type_of(until.var).scalar, 1});
  current_->push_back(ir::Stmt{ir::Assign{keep_going, ir::Swizzle::identity(1), ir::Op::Not, {until}, -1}});
  std::get<ir::Loop>(o.stmt->node).cond = ir::whole(prog_, keep_going);
  close(o.outer);
}

void Recorder::begin_for() { current_ = &open_loop(Frame::ForHeader, true).header; }

void Recorder::for_condition(const Value& cond) {
  Open& o = expect({Frame::ForHeader}, "SH_FOR condition outside SH_FOR");
  auto& loop = std::get<ir::Loop>(o.stmt->node);
  loop.cond = condition(cond, "SH_FOR");
  o.frame = Frame::ForUpdate;
  current_ = &loop.update;
}

void Recorder::for_body() {
  Open& o = expect({Frame::ForUpdate}, "SH_FOR body outside SH_FOR");
  o.frame = Frame::ForBody;
  current_ = &std::get<ir::Loop>(o.stmt->node).body;
}

void Recorder::end_for() { close(expect({Frame::ForBody}, "SH_ENDFOR without SH_FOR").outer); }

void Recorder::jump_statement(ir::Stmt s, const char* macro) {
  for (auto it = open_.rbegin(); it != open_.rend(); ++it) {
    if (it->frame == Frame::IfThen || it->frame == Frame::IfElse) continue;
    if (it->frame == Frame::WhileBody || it->frame == Frame::DoBody || it->frame == Frame::ForBody) {
      current_->push_back(std::move(s));
      return;
    }
    break;
  }
  fail(std::string(macro) + " outside a loop body");
}

void Recorder::emit_break() { jump_statement(ir::Stmt{ir::Break{}}, "SH_BREAK"); }
void Recorder::emit_continue() { jump_statement(ir::Stmt{ir::Continue{}}, "SH_CONTINUE"); }

Program Recorder::finish() {
  if (!open_.empty()) fail(std::string("ends with ") + frame_name(open_.back().frame) + " left open");
  // Before everything, so that the copy holds the input on every path.
  for (auto it = local_copies_.rbegin(); it != local_copies_.rend(); ++it)
    prog_.body.insert(prog_.body.begin(), ir::Stmt{*it});
  return Program(std::move(prog_), std::move(uniforms_), std::move(tables_));
}

}  // namespace sh::detail
