// Statements and control flow.  Scalar kernels branch; SPMD kernels narrow
// the execution mask instead, and branch only to skip work no lane needs.
#include "lowering.hpp"

#include <algorithm>
#include <tuple>

namespace sh::cpu {

using llvm::BasicBlock;
using llvm::Value;

// After a break or continue the rest of a block runs for no element (in
// SPMD: for no lane), so it is not emitted.
void Lowering::block(const ir::Block& body) {
  for (const ir::Stmt& s : body) {
    if (auto* a = std::get_if<ir::Assign>(&s.node)) {
      assign(*a);
    } else if (auto* i = std::get_if<ir::If>(&s.node)) {
      spmd() && facts_.divergent.at(&s) ? masked_branch(*i, s) : branch(*i);
    } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
      loop(*l, s, spmd() && facts_.divergent.at(&s));
    } else if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
      scatter(*sc);
    } else if (auto* pf = std::get_if<ir::Prefetch>(&s.node)) {
      prefetch(*pf);
    } else {
      leave(std::holds_alternative<ir::Break>(s.node));
      return;
    }
  }
}

void Lowering::leave(bool is_break) {
  const LoopState& l = loop_stack_.back();
  if (!l.active) {
    b_.CreateBr(is_break ? l.exit : l.next);
    // Whatever the enclosing statements emit next is unreachable.
    b_.SetInsertPoint(BasicBlock::Create(ctx_, "after.leave", fn_));
    return;
  }
  // Breaking lanes leave the loop for good; continuing lanes come back at
  // the update, which runs for every lane still looping.
  if (is_break) keep_lanes(l.active, b_.CreateNot(exec()));
  store_mask(llvm::Constant::getNullValue(mask_type()), exec_);
}

Value* Lowering::mask_from_slot(Value* held) {
  return avx512_ ? held : b_.CreateICmpSLT(held, llvm::Constant::getNullValue(held->getType()));
}

Value* Lowering::load_mask(llvm::AllocaInst* slot) { return mask_from_slot(b_.CreateLoad(mask_slot_type(), slot)); }

void Lowering::store_mask(Value* mask, llvm::AllocaInst* slot) {
  b_.CreateStore(avx512_ ? mask : b_.CreateSExt(mask, mask_slot_type()), slot);
}

// Clears the slot's lanes that are not in `mask`, and gives the lanes
// left.  Wide slots are and-ed as they are, so that a loop's mask stays in
// 32-bit lanes from one iteration to the next (the sign extension of an
// and of i1 lanes would be folded back into an i1 phi).
Value* Lowering::keep_lanes(llvm::AllocaInst* slot, Value* mask) {
  Value* kept = b_.CreateAnd(b_.CreateLoad(mask_slot_type(), slot), avx512_ ? mask : b_.CreateSExt(mask, mask_slot_type()));
  b_.CreateStore(kept, slot);
  return mask_from_slot(kept);
}

Value* Lowering::any(Value* mask) { return b_.CreateOrReduce(mask); }

// The lowest lane set in the mask; the lane count where none is.
Value* Lowering::first_lane(Value* mask) {
  Value* bits = b_.CreateBitCast(mask, b_.getIntNTy(static_cast<unsigned>(width_)));
  return b_.CreateBinaryIntrinsic(llvm::Intrinsic::cttz, bits, b_.getFalse());
}

// The element of `values` in the mask's lowest lane set; lane 0's where
// none is (the lane count, masked, is 0: widths are powers of two).
Value* Lowering::in_first_lane(Value* values, Value* mask) {
  Value* first = first_lane(mask);
  return b_.CreateExtractElement(values, b_.CreateAnd(first, llvm::ConstantInt::get(first->getType(), width_ - 1)));
}

Value* Lowering::condition(const ir::Operand& cond) { return truthy(read(cond, 0), p_.type_of(cond.var).scalar); }

llvm::AllocaInst* Lowering::entry_alloca(llvm::Type* t, const char* name) {
  llvm::IRBuilder<> entry(&fn_->getEntryBlock(), fn_->getEntryBlock().begin());
  return entry.CreateAlloca(t, nullptr, name);
}

void Lowering::branch(const ir::If& s) {
  BasicBlock* then_bb = BasicBlock::Create(ctx_, "then", fn_);
  BasicBlock* else_bb = BasicBlock::Create(ctx_, "else", fn_);
  BasicBlock* join = BasicBlock::Create(ctx_, "endif", fn_);
  b_.CreateCondBr(condition(s.cond), then_bb, else_bb);
  for (auto [bb, body] : {std::pair{then_bb, &s.then_body}, std::pair{else_bb, &s.else_body}}) {
    b_.SetInsertPoint(bb);
    block(*body);
    b_.CreateBr(join);
  }
  b_.SetInsertPoint(join);
}

void Lowering::enter_masked(const VarSet& live) {
  VarSet keep = live;
  if (!keep_.empty())
    for (std::size_t v = 0; v < keep.size(); ++v) keep[v] = keep[v] || keep_.back()[v];
  keep_.push_back(std::move(keep));
}

void Lowering::leave_masked() { keep_.pop_back(); }

// Each side runs under its share of the lanes, and is skipped when that
// share is empty.  Afterwards the lanes that finished either side go on:
// lanes that broke or continued inside it do not.
void Lowering::masked_branch(const ir::If& i, const ir::Stmt& s) {
  Value* before = exec();
  Value* cond = widen(condition(i.cond));
  Value* finished = nullptr;
  for (auto [body, lanes, live] :
       {std::tuple{&i.then_body, b_.CreateAnd(before, cond), &facts_.live_during_then.at(&s)},
        std::tuple{&i.else_body, b_.CreateAnd(before, b_.CreateNot(cond)), &facts_.live_at_rejoin.at(&s)}}) {
    enter_masked(*live);
    store_mask(lanes, exec_);
    if (!body->empty()) {
      BasicBlock* run = BasicBlock::Create(ctx_, "side", fn_);
      BasicBlock* done = BasicBlock::Create(ctx_, "side.done", fn_);
      b_.CreateCondBr(any(lanes), run, done);
      b_.SetInsertPoint(run);
      block(*body);
      b_.CreateBr(done);
      b_.SetInsertPoint(done);
    }
    finished = finished ? b_.CreateOr(finished, exec()) : exec();
    leave_masked();
  }
  store_mask(finished, exec_);
}

// Each loop counts its iterations: past the cap, the kernel stops and
// reports the loop and the element (the first lane still looping).  The
// first thread there claims the report by setting the loop's number, so
// that two never mix one's loop with the other's element; the caller
// reads both once every thread is done.
void Lowering::check_iterations(std::int64_t number, Value* count, Value* active, BasicBlock* next) {
  auto* i64 = b_.getInt64Ty();
  BasicBlock* runaway = BasicBlock::Create(ctx_, "loop.runaway", fn_);
  BasicBlock* claimed = BasicBlock::Create(ctx_, "loop.claimed", fn_);
  BasicBlock* stop = BasicBlock::Create(ctx_, "loop.stop", fn_);
  Value* n = b_.CreateLoad(i64, count);
  b_.CreateStore(b_.CreateAdd(n, b_.getInt64(1)), count);
  b_.CreateCondBr(b_.CreateICmpUGE(n, b_.getInt64(o_.max_loop_iterations)), runaway, next);

  b_.SetInsertPoint(runaway);
  auto* claim = b_.CreateAtomicCmpXchg(status_, b_.getInt64(0), b_.getInt64(number + 1), llvm::MaybeAlign(8),
                                       llvm::AtomicOrdering::Monotonic, llvm::AtomicOrdering::Monotonic);
  b_.CreateCondBr(b_.CreateExtractValue(claim, 1), claimed, stop);

  b_.SetInsertPoint(claimed);
  Value* element = b_.CreateLoad(i64, element_);
  if (active) element = b_.CreateAdd(element, b_.CreateZExt(first_lane(active), i64));
  b_.CreateStore(element, b_.CreateConstInBoundsGEP1_64(i64, status_, 1));
  b_.CreateBr(stop);

  b_.SetInsertPoint(stop);
  b_.CreateRetVoid();
}

// top -> [test ->] body -> update -> [test ->] top ..., the test before or
// after the body as the loop says.  A masked loop runs while any lane is
// active: the test retires the lanes whose condition failed, every part
// runs for the lanes still looping, and every lane that entered leaves at
// the exit.
void Lowering::loop(const ir::Loop& l, const ir::Stmt& s, bool masked) {
  auto numbered = std::find(loops_.begin(), loops_.end(), &s);  // loop_statements' number
  if (numbered == loops_.end()) numbered = loops_.insert(loops_.end(), &s);
  std::int64_t number = numbered - loops_.begin();
  llvm::AllocaInst* count = entry_alloca(b_.getInt64Ty(), "iterations");
  b_.CreateStore(b_.getInt64(0), count);
  llvm::AllocaInst* active = masked ? entry_alloca(mask_slot_type(), "active") : nullptr;
  Value* entered = masked ? exec() : nullptr;
  if (masked) {
    store_mask(entered, active);
    enter_masked(facts_.live_at_rejoin.at(&s));
  }
  auto run_active = [&] {
    if (masked) b_.CreateStore(b_.CreateLoad(mask_slot_type(), active), exec_);
  };

  BasicBlock* top = BasicBlock::Create(ctx_, "loop.top", fn_);
  BasicBlock* test = BasicBlock::Create(ctx_, "loop.test", fn_);
  BasicBlock* body = BasicBlock::Create(ctx_, "loop.body", fn_);
  BasicBlock* update = BasicBlock::Create(ctx_, "loop.update", fn_);
  BasicBlock* exit = BasicBlock::Create(ctx_, "loop.exit", fn_);
  // A branching loop inside masked code runs for the lanes running there,
  // which agree on its test; every one of them may have left already (a
  // break under a uniform if empties the mask and goes on): then it is
  // skipped, as its test would be on values no lane holds.
  bool inside_masks = !masked && !keep_.empty();
  if (inside_masks)
    b_.CreateCondBr(any(exec()), top, exit);
  else
    b_.CreateBr(top);

  b_.SetInsertPoint(top);
  Value* looping = masked ? load_mask(active) : inside_masks ? exec() : nullptr;
  if (masked) {
    // Every lane may have left by a break in the last pass: the loop is
    // over then, before another is counted (as each element's own loop).
    BasicBlock* counted = BasicBlock::Create(ctx_, "loop.count", fn_);
    b_.CreateCondBr(any(looping), counted, exit);
    b_.SetInsertPoint(counted);
  }
  // A pass is counted once its test (at the top) lets it in: a loop of
  // exactly the cap's passes runs.
  BasicBlock* let_in = l.test_at_top ? BasicBlock::Create(ctx_, "loop.let_in", fn_) : nullptr;
  if (l.test_at_top)
    b_.CreateBr(test);
  else
    check_iterations(number, count, looping, body);

  b_.SetInsertPoint(test);
  run_active();
  block(l.header);
  Value* go_on = condition(l.cond);
  if (masked) {
    go_on = any(keep_lanes(active, widen(go_on)));
  }
  b_.CreateCondBr(go_on, l.test_at_top ? let_in : top, exit);

  if (l.test_at_top) {
    b_.SetInsertPoint(let_in);
    check_iterations(number, count, masked ? load_mask(active) : inside_masks ? exec() : nullptr, body);
  }

  b_.SetInsertPoint(body);
  run_active();
  loop_stack_.push_back({exit, update, active});
  block(l.body);
  loop_stack_.pop_back();
  b_.CreateBr(update);

  b_.SetInsertPoint(update);
  run_active();
  block(l.update);
  b_.CreateBr(l.test_at_top ? top : test);

  b_.SetInsertPoint(exit);
  if (masked) {
    leave_masked();
    store_mask(entered, exec_);
  }
}

namespace {

void collect_loops(const ir::Block& body, std::vector<const ir::Stmt*>& out) {
  for (const ir::Stmt& s : body) {
    if (auto* i = std::get_if<ir::If>(&s.node)) {
      collect_loops(i->then_body, out);
      collect_loops(i->else_body, out);
    } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
      out.push_back(&s);
      collect_loops(l->header, out);
      collect_loops(l->body, out);
      collect_loops(l->update, out);
    } else if (std::holds_alternative<ir::Break>(s.node) || std::holds_alternative<ir::Continue>(s.node)) {
      return;
    }
  }
}

}  // namespace

std::vector<const ir::Stmt*> loop_statements(const ir::Program& program) {
  std::vector<const ir::Stmt*> loops;
  collect_loops(program.body, loops);
  return loops;
}

}  // namespace sh::cpu
