#include "lower.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <llvm/ADT/StringMap.h>
#include <llvm/IR/IntrinsicsX86.h>
#include <llvm/Support/Host.h>

#include "lowering.hpp"
#include "signature.hpp"
#include "sh/ir/verifier.hpp"
#include "sh/ir/visitor.hpp"

namespace sh::cpu {

using llvm::BasicBlock;
using llvm::Value;

namespace {

// Whether a stencil's taps reach more than one row of some table.
bool taps_rows(const std::vector<std::optional<analysis::TapSpan>>& spans) {
  return std::any_of(spans.begin(), spans.end(), [](const auto& s) { return s && s->high[1] > s->low[1]; });
}

}  // namespace

Lowering::Lowering(const ir::Program& p, const sh::Options& o, int width, llvm::LLVMContext& ctx)
    : p_(p), o_(o), width_(width), ctx_(ctx), module_(std::make_unique<llvm::Module>(p.name, ctx)), b_(ctx) {
  ir::verify_legal(p);
  loops_ = loop_statements(p);
  if (spmd()) {
    facts_ = analysis::analyse_spmd(p);
    access_ = analysis::table_access(p);
    tap_spans_ = analysis::tap_spans(p, access_);
  }
  reads_position_ = ir::uses(p, ir::Op::Position);
  streams_ = kernel_streams(p, o);
  unwritten_reads_ = analysis::unwritten_reads(p);
  llvm::StringMap<bool> features = isa_features(o);
  avx512_ = features.lookup("avx512f");
  // Two rows' taps held at once need AVX-512's 32 vector registers: with
  // AVX2's 16 the code generator folds each load into its add again, and
  // the blur ran slower (BENCHMARKS.md, issue 25).
  pairs_rows_ = spmd() && avx512_ && !fetches_tables(o) && taps_rows(tap_spans_) &&
                std::none_of(p.tables.begin(), p.tables.end(), [](const ir::TableDecl& t) { return t.accumulator; });
  clamps_taps_ = spmd() && !fetches_tables(o) && taps_clamp();
  if (width_ == 16 && avx512_)
    lane_permute_ = llvm::Intrinsic::x86_avx512_permvar_sf_512;
  else if (width_ == 8 && features.lookup("avx2"))
    lane_permute_ = llvm::Intrinsic::x86_avx2_permps;
  else if (width_ == 4 && features.lookup("avx"))
    lane_permute_ = llvm::Intrinsic::x86_avx_vpermilvar_ps;
}

Lowered Lowering::run() {
  if (o_.math == MathMode::Fast) b_.setFastMathFlags(llvm::FastMathFlags::getFast());
  function();
  return Lowered{std::move(module_), std::move(loops_)};
}

// ---- types and constants -----------------------------------------------------

llvm::Type* Lowering::lanes(llvm::Type* scalar) const {
  return llvm::FixedVectorType::get(scalar, static_cast<unsigned>(width_));
}

llvm::Type* Lowering::scalar_type(ir::Scalar s) const {
  bool single = s == ir::Scalar::F32 && o_.precision == Precision::F32;
  if (!ir::is_float(s)) return llvm::Type::getInt32Ty(ctx_);
  return single ? llvm::Type::getFloatTy(ctx_) : llvm::Type::getDoubleTy(ctx_);
}

llvm::Type* Lowering::storage_scalar(ir::Scalar s) const {
  switch (s) {
    case ir::Scalar::F32: return llvm::Type::getFloatTy(ctx_);
    case ir::Scalar::F64: return llvm::Type::getDoubleTy(ctx_);
    default: return llvm::Type::getInt32Ty(ctx_);
  }
}

Value* Lowering::splat(Value* scalar) {
  return spmd() ? b_.CreateVectorSplat(static_cast<unsigned>(width_), scalar) : scalar;
}

Value* Lowering::constant(ir::Scalar s, double v) {
  llvm::Type* t = scalar_type(s);
  if (t->isIntegerTy()) return llvm::ConstantInt::get(t, static_cast<std::uint32_t>(static_cast<std::int32_t>(v)));
  return llvm::ConstantFP::get(t, v);
}

Value* Lowering::from_storage(Value* x, ir::Scalar s) {
  llvm::Type* t = reg_type(s, x->getType()->isVectorTy());
  return x->getType() == t ? x : b_.CreateFPExt(x, t);
}

Value* Lowering::to_storage(Value* x, ir::Scalar s) {
  llvm::Type* t = x->getType()->isVectorTy() ? lanes(storage_scalar(s)) : storage_scalar(s);
  return x->getType() == t ? x : b_.CreateFPTrunc(x, t);
}

// ---- the function and the stream loop -----------------------------------------

// Each trip of the stream loop runs `width_` elements; the last trip of a
// call may have fewer, and its missing lanes are masked off.
void Lowering::function() {
  auto* ptr = b_.getPtrTy();
  auto* i64 = b_.getInt64Ty();
  auto* type = llvm::FunctionType::get(b_.getVoidTy(), {i64, i64, ptr, ptr, ptr, ptr, ptr, ptr, ptr, i64}, false);
  fn_ = llvm::Function::Create(type, llvm::Function::ExternalLinkage, kKernelSymbol, module_.get());
  if (o_.math == MathMode::Precise) fn_->addFnAttr("denormal-fp-math", "ieee,ieee");
  if (spmd()) {
    // Let the code generator use registers as wide as the lanes ask for.
    std::string bits = std::to_string(std::min(512, width_ * 64));
    fn_->addFnAttr("min-legal-vector-width", bits);
    fn_->addFnAttr("prefer-vector-width", bits);
  }
  auto arg = fn_->arg_begin();
  Value *begin = call_begin_ = arg++, *end = arg++;
  inputs_ = arg++;
  outputs_ = arg++;
  uniforms_ = arg++;
  tables_ = arg++;
  dims_ = arg++;
  Value* domain = arg++;
  status_ = arg++;
  streamed_ = arg++;

  BasicBlock* entry = BasicBlock::Create(ctx_, "entry", fn_);
  BasicBlock* head = BasicBlock::Create(ctx_, "elements.head", fn_);
  BasicBlock* body = BasicBlock::Create(ctx_, "elements.body", fn_);
  BasicBlock* exit = BasicBlock::Create(ctx_, "exit", fn_);
  b_.SetInsertPoint(entry);
  element_ = b_.CreateAlloca(i64, nullptr, "element");
  b_.CreateStore(begin, element_);
  if (spmd()) exec_ = b_.CreateAlloca(mask_slot_type(), nullptr, "exec");
  // The buffers do not move during a call: their addresses are loaded
  // once, so stores to outputs cannot make the loop reload them.
  for (std::size_t i = 0; i < p_.inputs.size(); ++i) input_base_.push_back(pointer_at(inputs_, i));
  for (std::size_t o = 0; o < p_.outputs.size(); ++o) output_base_.push_back(pointer_at(outputs_, o));
  for (std::size_t t = 0; t < p_.tables.size(); ++t) {
    table_base_.push_back(pointer_at(tables_, t));
    std::array<Value*, 3> dims{};
    for (int d = 0; d < 3; ++d)
      dims[d] = b_.CreateLoad(b_.getInt32Ty(), b_.CreateConstInBoundsGEP1_64(b_.getInt32Ty(), dims_, 3 * t + d));
    table_dims_.push_back(dims);
  }
  if (reads_position_) start_place(begin, domain);
  if (pairs_rows_) {
    skip_at_ = b_.CreateAlloca(i64, nullptr, "pairs.skip_at");
    skip_last_at_ = b_.CreateAlloca(i64, nullptr, "pairs.skip_last_at");
    skip_last_x_ = b_.CreateAlloca(i64, nullptr, "pairs.skip_last_x");
    b_.CreateStore(b_.getInt64(-1), skip_at_);
  }
  allocate_registers();
  b_.CreateBr(head);

  b_.SetInsertPoint(head);
  Value* e = b_.CreateLoad(i64, element_);
  b_.CreateCondBr(b_.CreateICmpSLT(e, end), body, exit);

  b_.SetInsertPoint(body);
  Value* count = spmd() ? b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, b_.CreateSub(end, e), b_.getInt64(width_)) : nullptr;
  if (reads_position_) count = place_batch(count);
  batch_count_ = count;
  inside_batches(e, end, head);
  if (spmd()) store_mask(live_lanes(count), exec_);
  clear_registers();
  full_or_tail(count, [&](Value* tail) { load_inputs(e, tail); });
  block(p_.body);
  full_or_tail(count, [&](Value* tail) { store_outputs(e, tail); });
  Value* step = reads_position_ && spmd() ? count : b_.getInt64(width_);
  if (reads_position_) advance_place(step);
  b_.CreateStore(b_.CreateAdd(e, step), element_);
  b_.CreateBr(head);

  b_.SetInsertPoint(exit);
  order_streamed_stores();
  b_.CreateRetVoid();
}

void Lowering::set_batch_x(Value* x) {
  batch_place_[0] = x;
  position_[0] = b_.CreateTrunc(x, b_.getInt32Ty());
}

// The call's first element's place in the launch domain (signature.hpp):
// x, y, z, kept in slots and moved on batch by batch, so that only the
// call's start divides.
void Lowering::start_place(Value* begin, Value* domain) {
  llvm::Type* i64 = b_.getInt64Ty();
  Value* first = b_.CreateLoad(i64, domain);
  row_ = b_.CreateLoad(i64, b_.CreateConstInBoundsGEP1_64(i64, domain, 1));
  rows_ = b_.CreateLoad(i64, b_.CreateConstInBoundsGEP1_64(i64, domain, 2));
  Value* g = b_.CreateAdd(begin, first);
  Value* row_number = b_.CreateUDiv(g, row_);
  std::array<Value*, 3> at{b_.CreateURem(g, row_), b_.CreateURem(row_number, rows_), b_.CreateUDiv(row_number, rows_)};
  for (int k = 0; k < 3; ++k) {
    place_[k] = b_.CreateAlloca(i64, nullptr, "place");
    b_.CreateStore(at[k], place_[k]);
  }
}

// The batch's x (its first element's) and the y and z all of it shares,
// for a batch ends where its row does: x runs on by one per lane, and a
// read at x + c is a vector load.  Returns the batch's count, cut at the
// row's end.
Value* Lowering::place_batch(Value* count) {
  llvm::Type* i64 = b_.getInt64Ty();
  std::array<Value*, 3> at{};
  for (int k = 0; k < 3; ++k) {
    at[k] = batch_place_[k] = b_.CreateLoad(i64, place_[k]);
    position_[k] = b_.CreateTrunc(at[k], b_.getInt32Ty());
  }
  if (!spmd()) return count;
  return b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, count, b_.CreateSub(row_, at[0]));
}

// Past the batch's `step` elements: the next row (and layer) where this
// one ends.
void Lowering::advance_place(Value* step) {
  llvm::Type* i64 = b_.getInt64Ty();
  Value* x = b_.CreateAdd(b_.CreateLoad(i64, place_[0]), step);
  Value* y = b_.CreateLoad(i64, place_[1]);
  Value* z = b_.CreateLoad(i64, place_[2]);
  Value* row_done = b_.CreateICmpEQ(x, row_);
  Value* next_y = b_.CreateAdd(y, b_.getInt64(1));
  Value* layer_done = b_.CreateAnd(row_done, b_.CreateICmpEQ(next_y, rows_));
  b_.CreateStore(b_.CreateSelect(row_done, b_.getInt64(0), x), place_[0]);
  b_.CreateStore(b_.CreateSelect(layer_done, b_.getInt64(0), b_.CreateSelect(row_done, next_y, y)), place_[1]);
  b_.CreateStore(b_.CreateSelect(layer_done, b_.CreateAdd(z, b_.getInt64(1)), z), place_[2]);
}

// Component k of the element's position: x is one more in each lane.
Value* Lowering::position(int k, bool vary) {
  if (!vary) return position_[k];
  if (k > 0) return splat(position_[k]);
  return b_.CreateAdd(splat(position_[0]), lane_numbers());
}

// Constants and uniforms are SSA values; every other variable is one
// stack slot per component (mem2reg makes them SSA again).
void Lowering::allocate_registers() {
  slots_.resize(p_.vars.size());
  written_zero_.assign(p_.vars.size(), {});
  ssa_.assign(p_.vars.size(), false);
  for (std::size_t u = 0; u < p_.uniforms.size(); ++u) {
    ir::VarId v = p_.uniforms[u];
    ir::Scalar s = p_.type_of(v).scalar;
    ssa_[v] = true;
    for (int c = 0; c < p_.type_of(v).width; ++c) {
      Value* d = b_.CreateLoad(b_.getDoubleTy(), b_.CreateConstInBoundsGEP1_64(b_.getDoubleTy(), uniforms_, 4 * u + c));
      llvm::Type* t = scalar_type(s);
      slots_[v][c] = t->isDoubleTy() ? d : t->isFloatTy() ? b_.CreateFPTrunc(d, t) : b_.CreateFPToSI(d, t);
    }
  }
  for (std::size_t v = 0; v < p_.vars.size(); ++v) {
    const ir::Var& var = p_.vars[v];
    if (var.kind == ir::VarKind::Uniform) continue;
    if (var.kind == ir::VarKind::Const) {
      ssa_[v] = true;
      for (int c = 0; c < var.type.width; ++c) {
        slots_[v][c] = constant(var.type.scalar, var.value[c]);
        if (ir::is_float(var.type.scalar) && var.value[c] == 0)
          written_zero_[v][c] = hidden_zero(scalar_type(var.type.scalar), std::signbit(var.value[c]));
      }
      continue;
    }
    auto id = static_cast<ir::VarId>(v);
    llvm::Type* held = var.kind == ir::VarKind::Array ? array_type(id) : var_type(id);
    for (int c = 0; c < var.type.width; ++c) slots_[v][c] = b_.CreateAlloca(held);
  }
}

// LLVM 15's InstCombine rewrites `x > 0 ? 0 : x` as `x >= 0 ? 0 : x`
// (llvm-project issue 57357), which gives +0 where x is -0.  So a float
// zero that a move or a choice writes is one LLVM cannot see, read once
// from a volatile, and the rewrite never matches; arithmetic keeps the
// constant.
// One load per type and sign serves every constant.
Value* Lowering::hidden_zero(llvm::Type* t, bool negative) {
  Value*& known = hidden_zeros_[{t, negative}];
  if (known) return known;
  auto* zero = new llvm::GlobalVariable(*module_, t, true, llvm::GlobalValue::PrivateLinkage, llvm::ConstantFP::get(t, 0.0),
                                        "sh.zero");
  Value* x = b_.CreateLoad(t, zero, true);
  return known = negative ? b_.CreateFNeg(x) : x;
}

// Every register and array starts an element at zero, where a read may
// find it so: a zero stored into every stack slot as each batch began
// (1 600 in the 16-lane tracer, nearly all written before they are read)
// took mem2reg 10 of its 12 ms.  Elsewhere a lane that has not written a
// register yet holds undef (mem2reg's value for an unwritten slot), which
// masked writes keep and no read of that lane sees.
void Lowering::clear_registers() {
  const llvm::DataLayout& layout = module_->getDataLayout();
  for (std::size_t v = 0; v < p_.vars.size(); ++v) {
    if (ssa_[v]) continue;
    auto id = static_cast<ir::VarId>(v);
    for (int c = 0; c < p_.vars[v].type.width; ++c) {
      if (!(unwritten_reads_[v] >> c & 1)) continue;
      if (p_.vars[v].kind == ir::VarKind::Array)
        b_.CreateMemSet(slots_[v][c], b_.getInt8(0), layout.getTypeAllocSize(array_type(id)).getFixedValue(),
                        llvm::MaybeAlign(alignment(var_type(id)->getScalarType())));
      else
        b_.CreateStore(llvm::Constant::getNullValue(var_type(id)), slots_[v][c]);
    }
  }
}

llvm::Constant* Lowering::lane_numbers() {
  std::vector<llvm::Constant*> ids;
  for (int i = 0; i < width_; ++i) ids.push_back(b_.getInt32(static_cast<std::uint32_t>(i)));
  return llvm::ConstantVector::get(ids);
}

// In 32 bits: one compare of one register at every width (a compare of
// 64-bit lanes would take two at 16, and their masks a merge at each use).
Value* Lowering::live_lanes(Value* count) {
  return b_.CreateICmpSLT(lane_numbers(), splat(b_.CreateTrunc(count, b_.getInt32Ty())), "live");
}

// Emits `emit` once for a full set of lanes (tail = nullptr) and once for
// the stream's tail (tail = the live lanes), so full trips keep plain
// loads and stores.  Scalar kernels have no tail.
void Lowering::full_or_tail(Value* count, const std::function<void(Value* tail)>& emit) {
  if (!spmd()) return emit(nullptr);
  BasicBlock* full = BasicBlock::Create(ctx_, "full", fn_);
  BasicBlock* tail = BasicBlock::Create(ctx_, "tail", fn_);
  BasicBlock* join = BasicBlock::Create(ctx_, "joined", fn_);
  b_.CreateCondBr(b_.CreateICmpEQ(count, b_.getInt64(width_)), full, tail);
  b_.SetInsertPoint(full);
  emit(nullptr);
  b_.CreateBr(join);
  b_.SetInsertPoint(tail);
  emit(live_lanes(count));
  b_.CreateBr(join);
  b_.SetInsertPoint(join);
}

Value* Lowering::pointer_at(Value* array, std::size_t k) {
  return b_.CreateLoad(b_.getPtrTy(), b_.CreateConstInBoundsGEP1_64(b_.getPtrTy(), array, k));
}

// Streams are arrays of elements, components side by side: the lanes'
// elements are one block of width x lanes values.
Value* Lowering::element_pointer(Value* base, ir::Type t, Value* e) {
  return b_.CreateInBoundsGEP(storage_scalar(t.scalar), base, b_.CreateMul(e, b_.getInt64(t.width)));
}

// A lane mask for a block of `width` components per lane.
Value* Lowering::spread(Value* tail, int width) {
  std::vector<int> lane_of;
  for (int i = 0; i < width_ * width; ++i) lane_of.push_back(i / width);
  return b_.CreateShuffleVector(tail, lane_of);
}

std::array<Value*, 4> Lowering::deinterleave(Value* block, int width) {
  std::array<Value*, 4> components{};
  for (int c = 0; c < width; ++c) {
    std::vector<int> picks;
    for (int i = 0; i < width_; ++i) picks.push_back(i * width + c);
    components[c] = width == 1 ? block : b_.CreateShuffleVector(block, picks);
  }
  return components;
}

Value* Lowering::interleave(const std::array<Value*, 4>& components, int width) {
  if (width == 1) return components[0];
  // Concatenate the components pairwise (padding to a power of two), then
  // pick lane by lane.
  std::vector<Value*> parts(components.begin(), components.begin() + width);
  while (parts.size() > 1) {
    if (parts.size() % 2) parts.push_back(llvm::PoisonValue::get(parts[0]->getType()));
    std::vector<Value*> joined;
    for (std::size_t k = 0; k < parts.size(); k += 2) {
      auto n = static_cast<int>(llvm::cast<llvm::FixedVectorType>(parts[k]->getType())->getNumElements());
      std::vector<int> both;
      for (int i = 0; i < 2 * n; ++i) both.push_back(i);
      joined.push_back(b_.CreateShuffleVector(parts[k], parts[k + 1], both));
    }
    parts = std::move(joined);
  }
  std::vector<int> order;
  for (int i = 0; i < width_; ++i)
    for (int c = 0; c < width; ++c) order.push_back(c * width_ + i);
  return b_.CreateShuffleVector(parts[0], order);
}

void Lowering::load_inputs(Value* e, Value* tail) {
  for (std::size_t i = 0; i < p_.inputs.size(); ++i) {
    ir::VarId v = p_.inputs[i];
    ir::Type t = p_.type_of(v);
    llvm::Type* scalar = storage_scalar(t.scalar);
    Value* at = element_pointer(input_base_[i], t, e);
    std::array<Value*, 4> components{};
    if (!spmd()) {
      for (int c = 0; c < t.width; ++c)
        components[c] = b_.CreateLoad(scalar, b_.CreateConstInBoundsGEP1_64(scalar, at, static_cast<std::uint64_t>(c)));
    } else {
      auto* block_type = llvm::FixedVectorType::get(scalar, static_cast<unsigned>(width_ * t.width));
      Value* block = tail ? static_cast<Value*>(b_.CreateMaskedLoad(block_type, at, alignment(scalar), spread(tail, t.width),
                                                                    llvm::Constant::getNullValue(block_type)))
                          : b_.CreateAlignedLoad(block_type, at, alignment(scalar));
      components = deinterleave(block, t.width);
    }
    for (int c = 0; c < t.width; ++c) b_.CreateStore(from_storage(components[c], t.scalar), slots_[v][c]);
  }
}

void Lowering::store_outputs(Value* e, Value* tail) {
  if (spmd() && !tail) return store_full_batches(full_batches(e));
  for (std::size_t o = 0; o < p_.outputs.size(); ++o) {
    ir::VarId v = p_.outputs[o];
    ir::Type t = p_.type_of(v);
    llvm::Type* scalar = storage_scalar(t.scalar);
    Value* at = element_pointer(output_base_[o], t, e);
    std::array<Value*, 4> components = output_components(v);
    if (!spmd()) {
      for (int c = 0; c < t.width; ++c)
        b_.CreateStore(components[c], b_.CreateConstInBoundsGEP1_64(scalar, at, static_cast<std::uint64_t>(c)));
      continue;
    }
    b_.CreateMaskedStore(interleave(components, t.width), at, alignment(scalar), spread(tail, t.width));
  }
}

std::vector<Lowering::Batch> Lowering::full_batches(Value* e) {
  std::vector<Batch> full;
  for (std::size_t o = 0; o < p_.outputs.size(); ++o) {
    ir::VarId v = p_.outputs[o];
    ir::Type t = p_.type_of(v);
    Value* block = interleave(output_components(v), t.width);
    full.push_back({block, element_pointer(output_base_[o], t, e), alignment(storage_scalar(t.scalar))});
  }
  return full;
}

// Output v's components, as they are stored.
std::array<Value*, 4> Lowering::output_components(ir::VarId v) {
  ir::Type t = p_.type_of(v);
  std::array<Value*, 4> components{};
  for (int c = 0; c < t.width; ++c) components[c] = to_storage(b_.CreateLoad(var_type(v), slots_[v][c]), t.scalar);
  return components;
}

// Full batches of the outputs: past the cache where the run asks for it
// and each batch of 32 bytes or more starts on a multiple of the largest
// power of two dividing its size, up to a line, since a non-temporal
// store of a vector must be aligned so; else (and batches under 32
// bytes, a fraction of a line) as any store.  One test for them all, so
// that a kernel of many outputs grows by one branch.  The bytes stored are
// the same either way.
void Lowering::store_full_batches(const std::vector<Batch>& batches) {
  std::vector<std::uint64_t> lines;  // by batch: the alignment its streamed store needs
  for (const Batch& batch : batches) {
    std::uint64_t bytes = module_->getDataLayout().getTypeStoreSize(batch.block->getType());
    lines.push_back(std::min<std::uint64_t>(64, bytes & (~bytes + 1)));  // the largest power of two dividing it
  }
  auto plain = [&] {
    for (const Batch& batch : batches) b_.CreateAlignedStore(batch.block, batch.at, batch.natural);
  };
  Value* aligned = nullptr;
  for (std::size_t k = 0; k < batches.size(); ++k) {
    if (lines[k] < 32) continue;
    Value* address = b_.CreatePtrToInt(batches[k].at, b_.getInt64Ty());
    Value* on_line = b_.CreateICmpEQ(b_.CreateAnd(address, b_.getInt64(lines[k] - 1)), b_.getInt64(0));
    aligned = aligned ? b_.CreateAnd(aligned, on_line) : on_line;
  }
  if (!streams_ || !aligned) return plain();
  BasicBlock* past = BasicBlock::Create(ctx_, "store.streamed", fn_);
  BasicBlock* cached = BasicBlock::Create(ctx_, "store.cached", fn_);
  BasicBlock* done = BasicBlock::Create(ctx_, "store.done", fn_);
  b_.CreateCondBr(b_.CreateAnd(b_.CreateICmpNE(streamed_, b_.getInt64(0)), aligned), past, cached);
  b_.SetInsertPoint(past);
  llvm::MDNode* nontemporal = llvm::MDNode::get(ctx_, {llvm::ConstantAsMetadata::get(b_.getInt32(1))});
  for (std::size_t k = 0; k < batches.size(); ++k) {
    const Batch& batch = batches[k];
    if (lines[k] < 32) {
      b_.CreateAlignedStore(batch.block, batch.at, batch.natural);
      continue;
    }
    llvm::StoreInst* store = b_.CreateAlignedStore(batch.block, batch.at, llvm::Align(lines[k]));
    store->setMetadata(llvm::LLVMContext::MD_nontemporal, nontemporal);
  }
  b_.CreateBr(done);
  b_.SetInsertPoint(cached);
  plain();
  b_.CreateBr(done);
  b_.SetInsertPoint(done);
}

// Non-temporal stores are weakly ordered: a fence makes them visible
// before whatever the caller does next (a thread telling another it is
// done), as the stores of every other run are.
void Lowering::order_streamed_stores() {
  if (!streams_) return;
  BasicBlock* fence = BasicBlock::Create(ctx_, "streamed.fence", fn_);
  BasicBlock* done = BasicBlock::Create(ctx_, "streamed.done", fn_);
  b_.CreateCondBr(b_.CreateICmpNE(streamed_, b_.getInt64(0)), fence, done);
  b_.SetInsertPoint(fence);
  b_.CreateCall(llvm::Intrinsic::getDeclaration(module_.get(), llvm::Intrinsic::x86_sse_sfence));
  b_.CreateBr(done);
  b_.SetInsertPoint(done);
}

Lowered lower(const ir::Program& program, const sh::Options& options, int width, llvm::LLVMContext& context) {
  return Lowering(program, options, width, context).run();
}

}  // namespace sh::cpu
