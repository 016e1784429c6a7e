#pragma once
// The state of one IR -> LLVM IR lowering, shared by its parts: lower.cpp
// (the stream loop, registers, inputs and outputs), stencil_rows.cpp (a
// stencil's batches along a row), flow.cpp (statements and control flow),
// operations.cpp (assignments, arithmetic and table reads) and arrays.cpp
// (local arrays).
//
// Lanes: with width 1 every register is a scalar and control flow is
// branches.  With width W > 1 the kernel is SPMD: a varying register is a
// <W x T> vector, lane i holding element e + i, a uniform one stays scalar
// (analyse_spmd in sh/analysis.hpp); divergent control flow narrows an
// execution mask (`exec`), a side of an `if` that no lane needs is skipped, and a loop
// runs while any lane is active.  Arithmetic is the same code for both:
// LLVM's operations take vectors as they take scalars.
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>

#include "lower.hpp"
#include "sh/analysis.hpp"

namespace sh::cpu {

using analysis::SpmdFacts;
using analysis::VarSet;

class Lowering {
 public:
  Lowering(const ir::Program& p, const sh::Options& o, int width, llvm::LLVMContext& ctx);
  Lowered run();

 private:
  using Value = llvm::Value;
  using BasicBlock = llvm::BasicBlock;

  bool spmd() const { return width_ > 1; }

  // ---- types and constants (lower.cpp) -----------------------------------
  bool varying(ir::VarId v) const { return spmd() && facts_.varying[v]; }
  llvm::Type* lanes(llvm::Type* scalar) const;  // <W x scalar>
  llvm::Type* scalar_type(ir::Scalar s) const;  // how one component computes
  llvm::Type* reg_type(ir::Scalar s, bool vary) const { return vary ? lanes(scalar_type(s)) : scalar_type(s); }
  llvm::Type* var_type(ir::VarId v) const { return reg_type(p_.type_of(v).scalar, varying(v)); }
  llvm::Type* storage_scalar(ir::Scalar s) const;  // how it lies in memory
  Value* splat(Value* scalar);                  // a uniform value in every lane
  Value* widen(Value* x) { return x->getType()->isVectorTy() ? x : splat(x); }
  Value* constant(ir::Scalar s, double v);
  Value* hidden_zero(llvm::Type* t, bool negative);
  Value* from_storage(Value* x, ir::Scalar s);
  Value* to_storage(Value* x, ir::Scalar s);

  // ---- the function, the stream loop and registers (lower.cpp) -------------
  void function();
  void allocate_registers();
  void clear_registers();
  void load_inputs(Value* e, Value* tail);
  void store_outputs(Value* e, Value* tail);
  std::array<Value*, 4> output_components(ir::VarId v);
  struct Batch {  // a full batch of an output, as it is stored
    Value* block;
    Value* at;
    llvm::Align natural;
  };
  std::vector<Batch> full_batches(Value* e);
  void store_full_batches(const std::vector<Batch>& batches);
  void order_streamed_stores();
  void full_or_tail(Value* count, const std::function<void(Value* tail)>& emit);
  Value* pointer_at(Value* array, std::size_t k);
  Value* element_pointer(Value* base, ir::Type t, Value* e);
  std::array<Value*, 4> deinterleave(Value* block, int width);
  Value* interleave(const std::array<Value*, 4>& components, int width);
  Value* spread(Value* tail, int width);
  Value* live_lanes(Value* count);
  llvm::Constant* lane_numbers();  // <0, 1, ..., W - 1> in i32
  void start_place(Value* begin, Value* domain);
  Value* place_batch(Value* count);
  void advance_place(Value* step);
  void set_batch_x(Value* x);
  void set_batch_y(Value* y);

  // ---- a stencil's batches along a row (stencil_rows.cpp) -------------------
  void inside_batches(Value* e, Value* end, BasicBlock* head);
  enum class Taps { Inside, Clamped };
  std::vector<Batch> inside_batch(Value* at, Taps taps = Taps::Inside);
  void clamped_batch(Value* e, Value* first_x, BasicBlock* head);
  bool taps_clamp() const;
  void leave_run(Value* x, Value* next, BasicBlock* head);
  void paired_batches(Value* e, Value* first_x, Value* last_x, BasicBlock* head);
  struct RowLoop {
    Value* x;                  // the last batch's
    Value* next;               // the element past it
    llvm::BranchInst* back;    // the loop's branch back to its start
  };
  void unroll_twice(llvm::BranchInst* back);
  RowLoop along_row(Value* e, Value* first_x, Value* last_x, const std::string& name,
                    const std::function<void(Value* at)>& trip);
  Value* pair_below(Value* e, Value* end, Value* first_x, Value* last_x);
  void skip_paired_run(Value* e, Value* first_x, BasicBlock* head);
  Value* last_batch_x(Value* e, Value* end, Value* first_x);
  void prefetch_next_rows();
  Value* position(int k, bool vary);

  // ---- statements and control flow (flow.cpp) ------------------------------
  void block(const ir::Block& body);
  void branch(const ir::If& s);
  void masked_branch(const ir::If& i, const ir::Stmt& s);
  void enter_masked(const VarSet& live);
  void leave_masked();
  void loop(const ir::Loop& l, const ir::Stmt& s, bool masked);
  void leave(bool is_break);
  void check_iterations(std::int64_t number, Value* count, Value* active, BasicBlock* next);
  Value* condition(const ir::Operand& cond);  // the i1 (or lanes of i1) an if or loop tests
  Value* any(Value* mask);
  Value* first_lane(Value* mask);
  Value* in_first_lane(Value* values, Value* mask);
  // Masks wait in stack slots between statements (mem2reg makes them SSA
  // values).  Without AVX-512's mask registers LLVM keeps a vector of i1
  // that crosses blocks as packed 16-bit lanes and unpacks it at every
  // use; there a slot holds 32-bit lanes, all ones or zero, as compares
  // make them and blends read them.
  Value* exec() { return load_mask(exec_); }
  Value* load_mask(llvm::AllocaInst* slot);
  void store_mask(Value* mask, llvm::AllocaInst* slot);
  Value* keep_lanes(llvm::AllocaInst* slot, Value* mask);
  llvm::Type* mask_type() const { return lanes(llvm::Type::getInt1Ty(ctx_)); }
  llvm::Type* mask_slot_type() const { return avx512_ ? mask_type() : lanes(llvm::Type::getInt32Ty(ctx_)); }
  Value* mask_from_slot(Value* held);
  llvm::AllocaInst* entry_alloca(llvm::Type* t, const char* name);

  // ---- assignments (operations.cpp) ----------------------------------------
  Value* read(const ir::Operand& o, int i);
  void write(ir::VarId v, int component, Value* x);
  void assign(const ir::Assign& a);
  Value* truthy(Value* x, ir::Scalar s);
  Value* mask(Value* bits, llvm::Type* t);
  Value* intrinsic(llvm::Intrinsic::ID id, std::initializer_list<Value*> args);
  enum class Rewrites { Allowed, None };
  Value* libm(const char* name, std::initializer_list<Value*> args, Rewrites rewrites = Rewrites::Allowed);
  static Value* library_call(llvm::IRBuilder<>& b, llvm::FunctionCallee f, llvm::ArrayRef<Value*> args,
                             Rewrites rewrites);
  llvm::Function* lane_by_lane(llvm::FunctionCallee f, const std::string& symbol, llvm::Type* vector, std::size_t arity,
                               Rewrites rewrites);
  Value* power(Value* base, Value* exponent);
  Value* operation(ir::Op op, ir::Scalar from, ir::Scalar to, Value* a, Value* b, Value* c);
  Value* cast(Value* a, ir::Scalar from, ir::Scalar to);
  Value* saturating_to_i32(Value* a, llvm::Type* t);
  Value* any_lane(Value* a, ir::Scalar from);
  Value* sign(Value* a, bool fp);
  Value* floor_remainder(Value* a, Value* b, bool fp);
  Value* round_half_up(Value* a);
  void table_read(const ir::Assign& a, std::array<Value*, 4>& result);
  Value* flat_index(int table, const ir::Operand& coord, bool gather);
  Value* access_field(int table, unsigned k);
  Value* fetched_element(int table, Value* flat);
  std::array<Value*, 4> fetch(int table, Value* flat);
  std::array<Value*, 4> fetch_lanes(int table, Value* flat);
  llvm::Function* fetch_rounds(int table);
  void fetch_round_loop(int table, Value* flat, Value* running, Value* out);
  std::pair<Value*, Value*> window_lanes(int table, Value* flat, Value* reading);
  void for_each_running_lane(const std::function<void(std::uint64_t lane)>& emit);
  void scatter(const ir::Scatter& sc);
  void prefetch(const ir::Prefetch& pf);
  void prefetch_element(int table, Value* element);
  // ---- local arrays (arrays.cpp) --------------------------------------------
  llvm::Type* array_type(ir::VarId v) const;
  Value* lane_columns(ir::VarId array, int component, Value* index);
  void array_element(const ir::Assign& a, std::array<Value*, 4>& result);
  void array_store(const ir::Assign& a);
  void array_fill(const ir::Assign& a);
  llvm::Align alignment(llvm::Type* scalar) const { return llvm::Align(scalar->getPrimitiveSizeInBits() / 8); }
  using ElementRead = std::function<std::array<Value*, 4>(Value*, bool)>;
  std::array<Value*, 4> same_or_gather(Value* flat, const ElementRead& element);
  std::array<Value*, 4> consecutive_or_gather(int table, Value* flat, const ElementRead& element);
  std::array<Value*, 4> run_or_gather(const ir::Assign& a, Value* flat, const ElementRead& element);
  struct Run {
    Value* inside;  // the whole run lies in the table
    Value* start;   // its first element's flat index
  };
  Run run_of(const ir::Assign& a);
  Value* tap_start(int table, const std::array<int, 3>& offset);
  // spmd, in a batch whose taps all lie inside: the taps of a table's row
  // (two or more along x, at most width_ apart) as the runs at its first
  // and last tap, loaded once at the batch's start, a vector a component;
  // each tap between is one shuffle of the two a component.
  struct TapRow {
    int low, high;
    std::array<Value*, 4> first, last;
  };
  std::map<std::tuple<int, int, int>, std::pair<int, int>> tap_row_spans() const;
  void load_tap_rows();
  void load_clamped_tap_rows();
  Value* taps_in_range();
  std::array<Value*, 4> tap(int table, const std::array<int, 3>& offset);
  Value* batch_inside();
  Value* last_inside_x();
  std::array<Value*, 4> joined(const std::array<Value*, 4>& a, BasicBlock* from_a, const std::array<Value*, 4>& b,
                               BasicBlock* from_b, int width);
  std::array<Value*, 4> clamped_run(const ir::Assign& a, Value* flat);
  std::array<Value*, 4> clamped_run(int table, Value* row, Value* asked_x);
  std::array<Value*, 4> window_or_gather(const ir::Assign& a, Value* flat, const ElementRead& element);
  std::array<Value*, 4> window_run(int table, Value* row, Value* asked_x);
  Value* row_start(const ir::Assign& a, Value* asked_x, Value* flat);
  Value* clamped(Value* v, Value* low, Value* high);
  bool permutes(int table) const;
  Value* permuted(Value* values, Value* index);
  std::array<Value*, 4> masked_run(int table, Value* start, Value* running);
  Value* gather_lanes(llvm::Type* scalar, Value* base, Value* index, Value* lanes_read, Value* otherwise,
                      Value* readable);
  llvm::Function* lane_loads(llvm::Type* scalar, llvm::Type* index_type);
  llvm::Function* helper_function(const std::string& name, llvm::FunctionType* type);

  struct LoopState {
    BasicBlock* exit;          // break, in a loop that branches
    BasicBlock* next;          // continue, likewise
    llvm::AllocaInst* active;  // a masked loop's lanes still looping; null where it branches
  };

  const ir::Program& p_;
  const sh::Options& o_;
  const int width_;
  llvm::LLVMContext& ctx_;
  std::unique_ptr<llvm::Module> module_;
  llvm::IRBuilder<> b_;
  llvm::Function* fn_ = nullptr;
  Value *inputs_ = nullptr, *outputs_ = nullptr, *uniforms_ = nullptr, *tables_ = nullptr, *dims_ = nullptr,
        *status_ = nullptr, *streamed_ = nullptr;
  // spmd on x86, no loops, stores not set to cached: the kernel can write
  // outputs past the cache
  bool streams_ = false;
  Value* call_begin_ = nullptr;  // the call's first element
  llvm::AllocaInst* element_ = nullptr;
  bool reads_position_ = false;
  Value *row_ = nullptr, *rows_ = nullptr;       // the launch domain's (signature.hpp)
  std::array<llvm::AllocaInst*, 3> place_{};  // the next batch's x, y, z
  std::array<Value*, 3> position_{};          // the batch's x (first lane), y, z
  std::array<Value*, 3> batch_place_{};       // the same in 64 bits, as table indices take them
  llvm::AllocaInst* exec_ = nullptr;  // spmd: the lanes running the current statement
  SpmdFacts facts_;
  std::unordered_map<const ir::Assign*, analysis::ReadAccess> access_;  // spmd: per table read
  std::vector<std::optional<analysis::TapSpan>> tap_spans_;              // spmd: per table, its stencil taps' offsets
  Value* batch_count_ = nullptr;  // spmd: the lanes that hold elements (the rest are past the end or the row)
  // spmd: the host has AVX-512, whose gather instruction is worth using and
  // whose mask registers hold i1 lanes (without it masks wait in 32-bit lanes)
  bool avx512_ = false;
  // spmd: the host's one-instruction permute of 32-bit lanes at width_
  // (vpermps; vpermilps at 4 lanes), or none
  llvm::Intrinsic::ID lane_permute_ = llvm::Intrinsic::not_intrinsic;
  bool batch_inside_ = false;     // spmd: lowering the body for a batch whose stencil taps are all inside
  // spmd: every table a stencil taps clamps, each row of taps at most a
  // batch wide (taps_clamp): full batches at the edges take clamped_batch
  bool clamps_taps_ = false;
  std::map<std::tuple<int, int, int>, TapRow> tap_rows_;  // spmd, inside: by table and the row's y and z offsets
  // spmd with AVX-512, taps on more than one row of a table, no
  // accumulator: rows' runs of inside batches may run together
  // (paired_batches), which then leaves where the next row's run starts
  // (-1: none), where the last row's does, and the x of their last batch
  bool pairs_rows_ = false;
  llvm::AllocaInst *skip_at_ = nullptr, *skip_last_at_ = nullptr, *skip_last_x_ = nullptr;
  // spmd, inside masked ifs and loops: the variables whose inactive lanes
  // must keep their values, innermost last.
  std::vector<VarSet> keep_;
  std::vector<Value*> input_base_, output_base_, table_base_;
  std::vector<std::array<Value*, 3>> table_dims_;
  std::vector<std::array<Value*, 4>> slots_;
  std::vector<std::uint8_t> unwritten_reads_;  // by variable: components a read may find unwritten
  std::vector<std::array<Value*, 4>> written_zero_;  // float constants' zero components, as a move writes them
  std::map<std::pair<llvm::Type*, bool>, Value*> hidden_zeros_;  // hidden_zero()'s loads, by type and sign
  std::vector<bool> ssa_;
  std::vector<LoopState> loop_stack_;
  std::vector<const ir::Stmt*> loops_;
};

}  // namespace sh::cpu
