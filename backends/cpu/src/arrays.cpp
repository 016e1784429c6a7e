// Local arrays (ir::VarKind::Array): one stack slot per component, an
// array of the register's type.  A uniform array is one for all lanes, so
// its element at a uniform index is one scalar load or store.  A varying
// array holds a vector per element, lane i's value in lane i: at a
// uniform index that is one vector load or store; at indices that differ
// between lanes, a gather or scatter of each lane's own column.  Legal IR
// indexes in range, so nothing here tests.
#include "lowering.hpp"

namespace sh::cpu {

using llvm::BasicBlock;
using llvm::Value;

llvm::Type* Lowering::array_type(ir::VarId v) const {
  return llvm::ArrayType::get(var_type(v), static_cast<std::uint64_t>(p_.var(v).length));
}

// Each lane's own component of elements `index` (a vector of indices):
// the array seen as scalars, lane i's at index * W + i.
Value* Lowering::lane_columns(ir::VarId array, int component, Value* index) {
  llvm::Type* scalar = var_type(array)->getScalarType();
  Value* at = b_.CreateAdd(b_.CreateMul(index, splat(b_.getInt32(static_cast<std::uint32_t>(width_)))),
                           lane_numbers());
  return b_.CreateInBoundsGEP(scalar, slots_[array][component], at);
}

void Lowering::array_element(const ir::Assign& a, std::array<Value*, 4>& result) {
  ir::VarId array = a.args[0].var;
  Value* index = read(a.args[1], 0);
  bool by_lane = index->getType()->isVectorTy();
  for (int c = 0; c < a.mask.size; ++c) {
    llvm::Type* t = var_type(array);
    Value* all_lanes = llvm::Constant::getAllOnesValue(mask_type());
    if (!by_lane) {
      result[c] = b_.CreateLoad(t, b_.CreateInBoundsGEP(array_type(array), slots_[array][c], {b_.getInt32(0), index}));
    } else if (varying(array)) {
      result[c] = b_.CreateMaskedGather(t, lane_columns(array, c, index), alignment(t->getScalarType()), all_lanes);
    } else {
      Value* places = b_.CreateInBoundsGEP(t, slots_[array][c], index);
      result[c] = b_.CreateMaskedGather(lanes(t), places, alignment(t), all_lanes);
    }
    if (varying(a.dest)) result[c] = widen(result[c]);
  }
}

// Under a mask only the running lanes store; outside masks every lane
// does (lanes past the stream's end hold values no one reads).  A uniform
// array is stored where the lanes running agree, as a uniform register is.
void Lowering::array_store(const ir::Assign& a) {
  ir::VarId array = a.dest;
  Value* index = read(a.args[0], 0);
  bool masked = !keep_.empty();
  for (int c = 0; c < a.mask.size; ++c) {
    Value* x = read(a.args[1], c);
    if (!varying(array)) {
      b_.CreateStore(x, b_.CreateInBoundsGEP(array_type(array), slots_[array][c], {b_.getInt32(0), index}));
      continue;
    }
    x = widen(x);
    llvm::Type* t = var_type(array);
    if (index->getType()->isVectorTy()) {
      Value* lanes_storing = masked ? exec() : llvm::Constant::getAllOnesValue(mask_type());
      b_.CreateMaskedScatter(x, lane_columns(array, c, index), alignment(t->getScalarType()), lanes_storing);
      continue;
    }
    Value* place = b_.CreateInBoundsGEP(array_type(array), slots_[array][c], {b_.getInt32(0), index});
    if (masked) x = b_.CreateSelect(exec(), x, b_.CreateLoad(t, place));
    b_.CreateStore(x, place);
  }
}

// Element by element in a loop of its own (LLVM makes a fill of zero a
// memset); under a mask the lanes not running keep theirs.
void Lowering::array_fill(const ir::Assign& a) {
  ir::VarId array = a.dest;
  bool masked = varying(array) && !keep_.empty();
  llvm::Type* t = var_type(array);
  std::array<Value*, 4> value{};
  for (int c = 0; c < a.mask.size; ++c) value[c] = varying(array) ? widen(read(a.args[0], c)) : read(a.args[0], c);
  Value* running = masked ? exec() : nullptr;
  BasicBlock* before = b_.GetInsertBlock();
  BasicBlock* body = BasicBlock::Create(ctx_, "fill", fn_);
  BasicBlock* done = BasicBlock::Create(ctx_, "fill.done", fn_);
  b_.CreateBr(body);
  b_.SetInsertPoint(body);
  llvm::PHINode* k = b_.CreatePHI(b_.getInt32Ty(), 2);
  k->addIncoming(b_.getInt32(0), before);
  for (int c = 0; c < a.mask.size; ++c) {
    Value* place = b_.CreateInBoundsGEP(array_type(array), slots_[array][c], {b_.getInt32(0), k});
    b_.CreateStore(masked ? b_.CreateSelect(running, value[c], b_.CreateLoad(t, place)) : value[c], place);
  }
  Value* next = b_.CreateAdd(k, b_.getInt32(1));
  k->addIncoming(next, body);
  b_.CreateCondBr(b_.CreateICmpULT(next, b_.getInt32(static_cast<std::uint32_t>(p_.var(array).length))), body, done);
  b_.SetInsertPoint(done);
}

}  // namespace sh::cpu
