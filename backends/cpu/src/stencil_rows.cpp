// The stream loop's path for a stencil's batches (lowering.hpp): along a
// row, the batches whose taps all lie inside their tables, alone or two
// rows at a time.
#include "lowering.hpp"

namespace sh::cpu {

using llvm::BasicBlock;
using llvm::Value;

namespace {

// The rows whose runs of inside batches go together (paired_batches).
constexpr int kRowsTogether = 2;

}  // namespace

// Where the program reads tables at position() plus constants (a
// stencil's taps), full batches whose taps all lie inside their tables run
// in a loop of their own along the row, the body lowered a second time for
// them: each tap one vector load with no test and no mask, and one test
// per batch, whether the next batch is such a batch too.  Rows are long and
// taps short, so nearly every batch runs here; the stream loop's body,
// every tap tested, takes the rows' edges and the stream's tail.  Where
// the row below is in the call too, the two rows run together
// (paired_batches).
void Lowering::inside_batches(Value* e, Value* end, BasicBlock* head) {
  Value* inside = batch_inside();
  if (!inside) return;
  Value* count = batch_count_;
  Value* first_x = batch_place_[0];
  Value* step = b_.getInt64(width_);
  Value* last_x = last_batch_x(e, end, first_x);
  Value* full_inside = b_.CreateAnd(inside, b_.CreateICmpEQ(count, step));
  BasicBlock* edge = BasicBlock::Create(ctx_, "batch.edge", fn_);
  batch_count_ = step;
  if (pairs_rows_) {
    skip_paired_run(e, first_x, head);
    BasicBlock* pairs = BasicBlock::Create(ctx_, "pairs.enter", fn_);
    BasicBlock* not_paired = BasicBlock::Create(ctx_, "pairs.not_taken", fn_);
    b_.CreateCondBr(b_.CreateAnd(full_inside, pair_below(e, end, first_x, last_x)), pairs, not_paired);
    b_.SetInsertPoint(pairs);
    paired_batches(e, first_x, last_x, head);
    b_.SetInsertPoint(not_paired);
  }
  BasicBlock* alone = BasicBlock::Create(ctx_, "batches.enter", fn_);
  b_.CreateCondBr(full_inside, alone, edge);
  b_.SetInsertPoint(alone);
  RowLoop done = along_row(e, first_x, last_x, "batches", [&](Value* at) {
    prefetch_next_rows();
    store_full_batches(inside_batch(at));
  });
  if (!avx512_ && width_ == 8) unroll_twice(done.back);
  leave_run(done.x, done.next, head);

  b_.SetInsertPoint(edge);
  batch_count_ = count;
  set_batch_x(first_x);
  clamped_batch(e, first_x, head);
}

// A full batch whose taps pass its tables' edges (a row's first and last
// batches, the first and last rows) runs the body as an inside batch
// does, its rows of taps read clamped (load_clamped_tap_rows).  The stream
// loop's body, every tap tested, takes the rest: batches cut short, and
// the stencils of tables that repeat.
void Lowering::clamped_batch(Value* e, Value* first_x, BasicBlock* head) {
  if (!clamps_taps_) return;
  Value* count = batch_count_;
  Value* step = b_.getInt64(width_);
  BasicBlock* clamped = BasicBlock::Create(ctx_, "batch.clamped", fn_);
  BasicBlock* other = BasicBlock::Create(ctx_, "batch.other", fn_);
  b_.CreateCondBr(b_.CreateAnd(b_.CreateICmpEQ(count, step), taps_in_range()), clamped, other);
  b_.SetInsertPoint(clamped);
  batch_count_ = step;
  store_full_batches(inside_batch(e, Taps::Clamped));
  leave_run(first_x, b_.CreateNSWAdd(e, step), head);
  b_.SetInsertPoint(other);
  batch_count_ = count;
}

// Whether every table a stencil taps clamps at its edges (or reads zero,
// which legal IR reads at the clamped place too), and each row of its taps
// spans at most a batch: then a batch past the edges reads its taps as
// clamped_batch does.
bool Lowering::taps_clamp() const {
  bool any = false;
  for (std::size_t t = 0; t < tap_spans_.size(); ++t)
    if (tap_spans_[t]) {
      if (p_.tables[t].edge == ir::Edge::Repeat) return false;
      any = true;
    }
  for (const auto& [row, span] : tap_row_spans())
    if (std::int64_t{span.second} - span.first > width_) return false;
  return any;
}

// The body of element `at`'s batch, every lane live and every tap inside
// or, with `taps` Clamped, read clamped: its outputs' full batches, not
// yet stored.
std::vector<Lowering::Batch> Lowering::inside_batch(Value* at, Taps taps) {
  b_.CreateStore(at, element_);
  store_mask(llvm::Constant::getAllOnesValue(mask_type()), exec_);  // every lane live, as a constant
  if (taps == Taps::Clamped)
    load_clamped_tap_rows();
  else
    load_tap_rows();
  clear_registers();
  load_inputs(at, nullptr);
  batch_inside_ = true;
  block(p_.body);
  batch_inside_ = false;
  tap_rows_.clear();
  return full_batches(at);
}

// Past a run along the row whose last batch is at x: the stream loop goes
// on at element `next`.
void Lowering::leave_run(Value* x, Value* next, BasicBlock* head) {
  b_.CreateStore(x, place_[0]);
  advance_place(b_.getInt64(width_));
  b_.CreateStore(next, element_);
  b_.CreateBr(head);
}

// Rows of a stencil read the rows between them alike: a 5 x 5 blur's
// batches at (x, y) and (x, y + 1) read six rows, not ten.  So where the
// run's batches of the kRowsTogether - 1 rows below lie in the call, with
// their taps inside, each trip lowers the body for each row, every load of
// every row before any row's stores (an output may lie in a table's
// memory), and LLVM's value numbering shares what the rows read alike:
// their loads and their taps' shuffles: 7 % off the 5 x 5 blur at 16
// lanes, 18 % at 8, whose two loads a row cost more per element
// (BENCHMARKS.md, issue 25).
// The runs of the rows below are then done: skip_paired_run passes over
// each when the stream loop comes to it.
void Lowering::paired_batches(Value* e, Value* first_x, Value* last_x, BasicBlock* head) {
  RowLoop done = along_row(e, first_x, last_x, "pairs", [&](Value* at) {
    const std::array<Value*, 3> place = batch_place_, position = position_;
    Value* y = batch_place_[1];
    // The rows the next trip's rows read and this trip's do not: as many
    // as it has rows, past the highest this trip reads.
    for (int below = 1; below <= kRowsTogether; ++below) {
      set_batch_y(b_.CreateNSWAdd(y, b_.getInt64(kRowsTogether - 2 + below)));
      prefetch_next_rows();
    }
    std::vector<Batch> stored;
    for (int below = 0; below < kRowsTogether; ++below) {
      set_batch_y(b_.CreateNSWAdd(y, b_.getInt64(below)));
      std::vector<Batch> row = inside_batch(b_.CreateNSWAdd(at, b_.CreateNSWMul(row_, b_.getInt64(below))));
      stored.insert(stored.end(), row.begin(), row.end());
    }
    batch_place_ = place, position_ = position;
    store_full_batches(stored);
  });
  b_.CreateStore(b_.CreateAdd(e, row_), skip_at_);
  b_.CreateStore(b_.CreateAdd(e, b_.CreateMul(row_, b_.getInt64(kRowsTogether - 1))), skip_last_at_);
  b_.CreateStore(done.x, skip_last_x_);
  leave_run(done.x, done.next, head);
}

// A loop along the row over full batches whose taps lie inside, from the
// one at first_x (element e) to the one at last_x, `trip` emitting a
// trip's work for the batch at element `at`, in blocks named `name`.inside
// and `name`.left; leaves the builder in the latter, with the last batch's
// x and the element past it.
Lowering::RowLoop Lowering::along_row(Value* e, Value* first_x, Value* last_x, const std::string& name,
                                      const std::function<void(Value* at)>& trip) {
  Value* step = b_.getInt64(width_);
  BasicBlock* from = b_.GetInsertBlock();
  BasicBlock* run = BasicBlock::Create(ctx_, name + ".inside", fn_);
  BasicBlock* leave = BasicBlock::Create(ctx_, name + ".left", fn_);
  b_.CreateBr(run);

  b_.SetInsertPoint(run);
  llvm::PHINode* at = b_.CreatePHI(b_.getInt64Ty(), 2);
  llvm::PHINode* x = b_.CreatePHI(b_.getInt64Ty(), 2);
  at->addIncoming(e, from);
  x->addIncoming(first_x, from);
  set_batch_x(x);
  trip(at);
  Value* next = b_.CreateNSWAdd(at, step);
  Value* next_x = b_.CreateNSWAdd(x, step);
  at->addIncoming(next, b_.GetInsertBlock());
  x->addIncoming(next_x, b_.GetInsertBlock());
  llvm::BranchInst* back = b_.CreateCondBr(b_.CreateICmpSLE(next_x, last_x), run, leave);
  b_.SetInsertPoint(leave);
  return {x, next, back};
}

// Asks LLVM to unroll the loop that `back` closes twice over.  A batch of
// 8 lanes is one AVX2 register, and a 5 x 5 blur's trip 25 dependent adds
// and some ten instructions of its own (the prefetch, the store's choice,
// the counters): two batches a trip halve the latter per element, as 16
// lanes (two registers a value) do, and took the direct blur from 0.83x to
// 0.88x of the C++ loop (medians of five rounds in turn, BENCHMARKS.md,
// issue 25).  At 16 lanes on AVX2 the same made it slower.
void Lowering::unroll_twice(llvm::BranchInst* back) {
  llvm::Metadata* count[] = {llvm::MDString::get(ctx_, "llvm.loop.unroll.count"),
                             llvm::ConstantAsMetadata::get(b_.getInt32(2))};
  llvm::TempMDTuple self = llvm::MDNode::getTemporary(ctx_, {});
  llvm::MDNode* loop = llvm::MDNode::get(ctx_, {self.get(), llvm::MDNode::get(ctx_, count)});
  loop->replaceOperandWith(0, loop);
  back->setMetadata(llvm::LLVMContext::MD_loop, loop);
}

// Whether the rows below the batch at first_x (element e) can run beside
// this run: they are in the domain's layer, their batches up to last_x
// are in the call, and their taps lie inside.  And whether the stream
// loop will come to their runs' starts and no further batch of theirs
// before: it will where this row's batches were laid from its x = 0 on,
// as theirs will be, so that first_x is where their runs start too (a
// call that starts inside the row has its first row's batches elsewhere,
// and an inside batch of the row below may start its run earlier).
Value* Lowering::pair_below(Value* e, Value* end, Value* first_x, Value* last_x) {
  Value* y = batch_place_[1];
  Value* lowest = b_.CreateAdd(y, b_.getInt64(kRowsTogether - 1));
  Value* in_layer = b_.CreateICmpSLT(lowest, rows_);
  Value* run_end = b_.CreateAdd(b_.CreateAdd(e, b_.CreateMul(row_, b_.getInt64(kRowsTogether - 1))),
                                b_.CreateAdd(b_.CreateSub(last_x, first_x), b_.getInt64(width_)));
  Value* in_call = b_.CreateICmpSLE(run_end, end);
  Value* from_row_start = b_.CreateICmpSGE(b_.CreateSub(e, first_x), call_begin_);
  const std::array<Value*, 3> place = batch_place_, position = position_;
  set_batch_y(lowest);
  Value* inside = batch_inside();
  batch_place_ = place, position_ = position;
  return b_.CreateAnd(b_.CreateAnd(in_layer, in_call), b_.CreateAnd(from_row_start, inside));
}

// The batch at element e starts a run paired_batches did with a row
// above: the stream loop goes on past that run's last batch, and looks
// for the next row's run where there is one.
void Lowering::skip_paired_run(Value* e, Value* first_x, BasicBlock* head) {
  llvm::Type* i64 = b_.getInt64Ty();
  BasicBlock* done = BasicBlock::Create(ctx_, "pairs.done", fn_);
  BasicBlock* go_on = BasicBlock::Create(ctx_, "pairs.not_done", fn_);
  b_.CreateCondBr(b_.CreateICmpEQ(e, b_.CreateLoad(i64, skip_at_)), done, go_on);
  b_.SetInsertPoint(done);
  Value* last_row = b_.CreateICmpEQ(e, b_.CreateLoad(i64, skip_last_at_));
  b_.CreateStore(b_.CreateSelect(last_row, b_.getInt64(-1), b_.CreateAdd(e, row_)), skip_at_);
  Value* last_x = b_.CreateLoad(i64, skip_last_x_);
  leave_run(last_x, b_.CreateAdd(e, b_.CreateAdd(b_.CreateSub(last_x, first_x), b_.getInt64(width_))), head);
  b_.SetInsertPoint(go_on);
}

// The row that the batch under this one (at y + 1) will read first, for
// each two-dimensional table a stencil reads: its taps' lowest row moves
// down by one, so only the row past their highest is new to the cache.
// Fetched a row ahead, at this batch's x, it is there when the next row of
// batches comes; the hardware's prefetcher, which stops at a page's end,
// left the first load of each new row waiting on memory (5 % of a 5 x 5
// blur's samples).  Where that row lies past the table's last, the batch
// asks for the last row instead: a prefetch never faults, but one past the
// memory a table holds cost a Zen 1 host a page walk each, about 50 us for
// each of run_fused's strips, whose consumer's table holds only the
// strip's rows (BENCHMARKS.md, issue 25).
void Lowering::prefetch_next_rows() {
  llvm::Type* i64 = b_.getInt64Ty();
  for (std::size_t t = 0; t < tap_spans_.size(); ++t) {
    const ir::TableDecl& table = p_.tables[t];
    if (!tap_spans_[t] || table.rank != 2) continue;
    Value* x = b_.CreateAdd(batch_place_[0], b_.getInt64(tap_spans_[t]->low[0]));
    Value* next = b_.CreateAdd(batch_place_[1], b_.getInt64(std::int64_t{tap_spans_[t]->high[1]} + 1));
    Value* last = b_.CreateSub(b_.CreateZExt(table_dims_[t][1], i64), b_.getInt64(1));
    Value* y = b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, next, last);
    prefetch_element(static_cast<int>(t), b_.CreateAdd(x, b_.CreateMul(y, b_.CreateZExt(table_dims_[t][0], i64))));
  }
}

// The x of the last batch along this row, from the one at first_x
// (element e), that is full, in the row and the call, and has its taps
// inside: each batch starts past the one before, so only their ends along
// the row can leave.
Value* Lowering::last_batch_x(Value* e, Value* end, Value* first_x) {
  Value* step = b_.getInt64(width_);
  Value* in_row = b_.CreateSub(row_, step);
  Value* in_call = b_.CreateAdd(first_x, b_.CreateSub(b_.CreateSub(end, e), step));
  Value* last = b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, in_row, in_call);
  return b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, last, last_inside_x());
}

void Lowering::set_batch_y(Value* y) {
  batch_place_[1] = y;
  position_[1] = b_.CreateTrunc(y, b_.getInt32Ty());
}

}  // namespace sh::cpu
