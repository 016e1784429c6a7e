#pragma once
// The recording in progress: the program being built, the map from DSL
// variables to IR registers, and the stack of open control-flow constructs.
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "sh/detail/buffer.hpp"
#include "sh/detail/value.hpp"
#include "sh/program.hpp"

namespace sh::detail {

class Recorder {
 public:
  explicit Recorder(std::string name);

  const std::string& name() const { return prog_.name; }
  [[noreturn]] void fail(const std::string& what) const;

  void declare(const std::shared_ptr<VarNode>& node, Declared how);
  ir::Operand read(const Value& v);
  ir::VarId write_target(const Value& v);
  ir::VarId new_temp(ir::Type t);
  void rename(const VarNode* node, const std::string& name);
  int table_index(const std::shared_ptr<TableStorage>& table);
  void emit(ir::Assign a);
  void emit_scatter(ir::Scatter s) { current_->push_back(ir::Stmt{s}); }
  void emit_prefetch(ir::Prefetch p) { current_->push_back(ir::Stmt{p}); }
  // Emits op(args) into a new temporary and returns the variable.
  Value emit_result(ir::Type type, ir::Op op, std::vector<ir::Operand> args, int table = -1);
  const ir::Program& program() const { return prog_; }

  void begin_if(const Value& cond);
  void begin_else();
  void end_if();
  void begin_while();
  void while_condition(const Value& cond);
  void end_while();
  void begin_do();
  void begin_until();
  void until_condition(const Value& cond);
  void begin_for();
  void for_condition(const Value& cond);
  void for_body();
  void end_for();
  void emit_break();
  void emit_continue();

  Program finish();

 private:
  enum class Frame { IfThen, IfElse, WhileHeader, WhileBody, DoBody, DoHeader, ForHeader, ForUpdate, ForBody };
  struct Open {
    Frame frame;
    ir::Stmt* stmt;
    ir::Block* outer;
  };

  ir::VarId id_of(const std::shared_ptr<VarNode>& node);
  ir::VarId local_copy(const VarNode* input, ir::VarId id);
  ir::Operand condition(const Value& cond, const char* construct);
  ir::Loop& open_loop(Frame first, bool test_at_top);
  void check_nesting(const char* what) const;  // before an if or a loop opens
  Open& expect(std::initializer_list<Frame> frames, const char* what);
  void close(ir::Block* next);
  void jump_statement(ir::Stmt s, const char* macro);
  static const char* frame_name(Frame f);

  ir::Program prog_;
  std::vector<std::shared_ptr<VarNode>> uniforms_;
  std::vector<std::shared_ptr<TableStorage>> tables_;
  std::unordered_map<const VarNode*, ir::VarId> ids_;
  std::vector<std::shared_ptr<VarNode>> alive_;  // keeps map keys from being reused
  std::unordered_set<ir::VarId> written_outputs_;
  std::vector<ir::Assign> local_copies_;  // inputs written by the program, copied first
  std::vector<Open> open_;
  ir::Block* current_;
  // This recording's number in the process (VarNode::recording): unlike
  // its address, never another recording's after it ends.
  std::uint64_t serial_;
};

Recorder* current_recorder();

// Pushes a recording for the lifetime of the scope.
class RecordingScope {
 public:
  explicit RecordingScope(std::string name);
  ~RecordingScope();
  RecordingScope(const RecordingScope&) = delete;
  RecordingScope& operator=(const RecordingScope&) = delete;
  Recorder& recorder() { return *recorder_; }

 private:
  std::unique_ptr<Recorder> recorder_;
};

}  // namespace sh::detail
