// Statements and control flow.  Scalar kernels branch; SPMD kernels narrow
// the execution mask instead, and branch only to skip work no lane needs.
#include "lowering.hpp"

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
      spmd() && facts_.divergent.at(&s) ? masked_branch(s, *i) : branch(*i);
    } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
      spmd() && facts_.divergent.at(&s) ? masked_loop(*l, s) : loop(*l, s);
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
  if (is_break) b_.CreateStore(b_.CreateAnd(b_.CreateLoad(mask_type(), l.active), b_.CreateNot(exec())), l.active);
  b_.CreateStore(llvm::Constant::getNullValue(mask_type()), exec_);
}

Value* Lowering::any(Value* mask) { return b_.CreateOrReduce(mask); }

llvm::AllocaInst* Lowering::entry_alloca(llvm::Type* t, const char* name) {
  llvm::IRBuilder<> entry(&fn_->getEntryBlock(), fn_->getEntryBlock().begin());
  return entry.CreateAlloca(t, nullptr, name);
}

void Lowering::branch(const ir::If& s) {
  BasicBlock* then_bb = BasicBlock::Create(ctx_, "then", fn_);
  BasicBlock* else_bb = BasicBlock::Create(ctx_, "else", fn_);
  BasicBlock* join = BasicBlock::Create(ctx_, "endif", fn_);
  b_.CreateCondBr(truthy(read(s.cond, 0), p_.type_of(s.cond.var).scalar), then_bb, else_bb);
  for (auto [bb, body] : {std::pair{then_bb, &s.then_body}, std::pair{else_bb, &s.else_body}}) {
    b_.SetInsertPoint(bb);
    block(*body);
    b_.CreateBr(join);
  }
  b_.SetInsertPoint(join);
}

void Lowering::enter_masked(const ir::Stmt& s) {
  VarSet keep = facts_.live_at_rejoin.at(&s);
  if (!keep_.empty())
    for (std::size_t v = 0; v < keep.size(); ++v) keep[v] = keep[v] || keep_.back()[v];
  keep_.push_back(std::move(keep));
}

void Lowering::leave_masked() { keep_.pop_back(); }

// Each side runs under its share of the lanes, and is skipped when that
// share is empty.  Afterwards the lanes that finished either side go on:
// lanes that broke or continued inside it do not.
void Lowering::masked_branch(const ir::Stmt& s, const ir::If& i) {
  Value* before = exec();
  Value* cond = widen(truthy(read(i.cond, 0), p_.type_of(i.cond.var).scalar));
  enter_masked(s);
  Value* finished = nullptr;
  for (auto [body, lanes] : {std::pair{&i.then_body, b_.CreateAnd(before, cond)},
                             std::pair{&i.else_body, b_.CreateAnd(before, b_.CreateNot(cond))}}) {
    b_.CreateStore(lanes, exec_);
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
  }
  leave_masked();
  b_.CreateStore(finished, exec_);
}

// Each loop counts its iterations: past the cap, the kernel stops and
// reports the loop and the element (the first lane still looping).
void Lowering::check_iterations(std::int64_t number, Value* count, Value* active, BasicBlock* next) {
  auto* i64 = b_.getInt64Ty();
  BasicBlock* runaway = BasicBlock::Create(ctx_, "loop.runaway", fn_);
  Value* n = b_.CreateLoad(i64, count);
  b_.CreateStore(b_.CreateAdd(n, b_.getInt64(1)), count);
  b_.CreateCondBr(b_.CreateICmpUGE(n, b_.getInt64(o_.max_loop_iterations)), runaway, next);

  b_.SetInsertPoint(runaway);
  Value* element = b_.CreateLoad(i64, element_);
  if (active) {
    Value* bits = b_.CreateBitCast(active, b_.getIntNTy(static_cast<unsigned>(width_)));
    Value* lane = b_.CreateBinaryIntrinsic(llvm::Intrinsic::cttz, bits, b_.getFalse());
    element = b_.CreateAdd(element, b_.CreateZExt(lane, i64));
  }
  for (auto [slot, x] : {std::pair{0, static_cast<Value*>(b_.getInt64(number + 1))}, std::pair{1, element}}) {
    auto* store = b_.CreateStore(x, b_.CreateConstInBoundsGEP1_64(i64, status_, slot));
    store->setAtomic(llvm::AtomicOrdering::Monotonic);
    store->setAlignment(llvm::Align(8));
  }
  b_.CreateRetVoid();
}

// top -> [test ->] body -> update -> [test ->] top ..., the test before or
// after the body as the loop says.
void Lowering::loop(const ir::Loop& l, const ir::Stmt& s) {
  std::int64_t number = static_cast<std::int64_t>(loops_.size());
  loops_.push_back(&s);
  llvm::AllocaInst* count = entry_alloca(b_.getInt64Ty(), "iterations");
  b_.CreateStore(b_.getInt64(0), count);

  BasicBlock* top = BasicBlock::Create(ctx_, "loop.top", fn_);
  BasicBlock* test = BasicBlock::Create(ctx_, "loop.test", fn_);
  BasicBlock* body = BasicBlock::Create(ctx_, "loop.body", fn_);
  BasicBlock* update = BasicBlock::Create(ctx_, "loop.update", fn_);
  BasicBlock* exit = BasicBlock::Create(ctx_, "loop.exit", fn_);
  b_.CreateBr(top);

  b_.SetInsertPoint(top);
  check_iterations(number, count, nullptr, l.test_at_top ? test : body);

  b_.SetInsertPoint(test);
  block(l.header);
  b_.CreateCondBr(truthy(read(l.cond, 0), p_.type_of(l.cond.var).scalar), l.test_at_top ? body : top, exit);

  b_.SetInsertPoint(body);
  loop_stack_.push_back({exit, update, nullptr});
  block(l.body);
  loop_stack_.pop_back();
  b_.CreateBr(update);

  b_.SetInsertPoint(update);
  block(l.update);
  b_.CreateBr(l.test_at_top ? top : test);

  b_.SetInsertPoint(exit);
}

// The same shape, run while any lane is active; the test retires the lanes
// whose condition failed.  Every lane that entered leaves at the exit.
void Lowering::masked_loop(const ir::Loop& l, const ir::Stmt& s) {
  std::int64_t number = static_cast<std::int64_t>(loops_.size());
  loops_.push_back(&s);
  llvm::AllocaInst* count = entry_alloca(b_.getInt64Ty(), "iterations");
  llvm::AllocaInst* active = entry_alloca(mask_type(), "active");
  Value* entered = exec();
  b_.CreateStore(b_.getInt64(0), count);
  b_.CreateStore(entered, active);
  enter_masked(s);

  BasicBlock* top = BasicBlock::Create(ctx_, "loop.top", fn_);
  BasicBlock* test = BasicBlock::Create(ctx_, "loop.test", fn_);
  BasicBlock* body = BasicBlock::Create(ctx_, "loop.body", fn_);
  BasicBlock* update = BasicBlock::Create(ctx_, "loop.update", fn_);
  BasicBlock* exit = BasicBlock::Create(ctx_, "loop.exit", fn_);
  auto run_active = [&] { b_.CreateStore(b_.CreateLoad(mask_type(), active), exec_); };
  b_.CreateBr(top);

  b_.SetInsertPoint(top);
  check_iterations(number, count, b_.CreateLoad(mask_type(), active), l.test_at_top ? test : body);

  b_.SetInsertPoint(test);
  run_active();
  block(l.header);
  Value* staying = b_.CreateAnd(b_.CreateLoad(mask_type(), active),
                                widen(truthy(read(l.cond, 0), p_.type_of(l.cond.var).scalar)));
  b_.CreateStore(staying, active);
  b_.CreateCondBr(any(staying), l.test_at_top ? body : top, exit);

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
  leave_masked();
  b_.CreateStore(entered, exec_);
}

}  // namespace sh::cpu
