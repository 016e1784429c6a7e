// Assignments: operations component by component, and table reads.  The
// same code serves scalar and SPMD kernels: constants are made in the
// value's own type, so they are splats where the value is a vector.
#include "lowering.hpp"

#include <cstdint>
#include <functional>
#include <limits>

#include <llvm/IR/MDBuilder.h>

namespace sh::cpu {

using llvm::BasicBlock;
using llvm::Value;

Value* Lowering::read(const ir::Operand& o, int i) {
  int c = o.component(i);
  if (ssa_[o.var]) return slots_[o.var][c];
  return b_.CreateLoad(var_type(o.var), slots_[o.var][c]);
}

// Under a mask, lanes that are not running keep their value where some
// lane may read it later (analyse_spmd in sh/analysis.hpp).  Outside masks every lane
// runs, and lanes past the stream's end are never stored.
void Lowering::write(ir::VarId v, int component, Value* x) {
  Value* slot = slots_[v][component];
  if (varying(v) && !keep_.empty() && keep_.back()[v]) x = b_.CreateSelect(exec(), x, b_.CreateLoad(var_type(v), slot));
  b_.CreateStore(x, slot);
}

void Lowering::assign(const ir::Assign& a) {
  std::array<Value*, 4> result{};
  if (a.op == ir::Op::Store) return array_store(a);
  if (a.op == ir::Op::Fill) return array_fill(a);
  if (a.op == ir::Op::Element) {
    array_element(a, result);
  } else if (ir::is_table_read(a.op)) {
    table_read(a, result);
  } else if (a.op == ir::Op::Position) {
    for (int i = 0; i < a.mask.size; ++i) result[i] = position(i, varying(a.dest));
  } else {
    ir::Scalar from = p_.type_of(a.args[0].var).scalar, to = p_.type_of(a.dest).scalar;
    for (int i = 0; i < a.mask.size; ++i) {
      Value* x[3] = {nullptr, nullptr, nullptr};
      for (std::size_t k = 0; k < a.args.size(); ++k) {
        const ir::Operand& o = a.args[k];
        Value* zero = written_zero_[o.var][o.component(i)];
        bool written = a.op == ir::Op::Mov || (a.op == ir::Op::Cond && k > 0);
        x[k] = written && zero ? zero : read(o, i);
        if (varying(a.dest)) x[k] = widen(x[k]);
      }
      result[i] = operation(a.op, from, to, x[0], x[1], x[2]);
      if (varying(a.dest)) result[i] = widen(result[i]);  // a vote is one value
    }
  }
  for (int i = 0; i < a.mask.size; ++i) write(a.dest, a.mask[i], result[i]);
}

Value* Lowering::truthy(Value* x, ir::Scalar s) {
  if (ir::is_float(s)) return b_.CreateFCmpOGT(x, llvm::ConstantFP::get(x->getType(), 0.0));
  return b_.CreateICmpSGT(x, llvm::ConstantInt::get(x->getType(), 0));
}

// 0/1 in type t.  For floats a select, not uitofp: LLVM folds a later
// truthy() test of a select of constants back to the bits, not of uitofp.
Value* Lowering::mask(Value* bits, llvm::Type* t) {
  if (t->isIntOrIntVectorTy()) return b_.CreateZExt(bits, t);
  return b_.CreateSelect(bits, llvm::ConstantFP::get(t, 1.0), llvm::ConstantFP::get(t, 0.0));
}

Value* Lowering::intrinsic(llvm::Intrinsic::ID id, std::initializer_list<Value*> args) {
  llvm::Function* f = llvm::Intrinsic::getDeclaration(module_.get(), id, {(*args.begin())->getType()});
  return b_.CreateCall(f, args);
}

namespace {

// What LLVM may assume of a C library function whose errno no kernel
// reads: a call that reads and writes no memory, throws nothing and
// returns, which it may move, share or drop like an intrinsic's.
void touches_no_memory(llvm::Function& f) {
  f.setDoesNotAccessMemory();
  f.setDoesNotThrow();
  f.addFnAttr(llvm::Attribute::WillReturn);
}

}  // namespace

// A C math library function, in the precision of x.  With
// Rewrites::None LLVM does not know the call for the library's function
// (it is `nobuiltin`), so none of its library-call rewrites apply; it
// knows only that the function touches no memory.
Value* Lowering::libm(const char* name, std::initializer_list<Value*> args, Rewrites rewrites) {
  llvm::Type* t = (*args.begin())->getType();
  llvm::Type* scalar = t->getScalarType();
  std::string symbol = scalar->isFloatTy() ? std::string(name) + "f" : name;
  std::vector<llvm::Type*> params(args.size(), scalar);
  llvm::FunctionCallee f = module_->getOrInsertFunction(symbol, llvm::FunctionType::get(scalar, params, false));
  if (rewrites == Rewrites::None) touches_no_memory(*llvm::cast<llvm::Function>(f.getCallee()));
  if (!t->isVectorTy()) return library_call(b_, f, args, rewrites);
  llvm::CallInst* call = b_.CreateCall(lane_by_lane(f, symbol, t, args.size(), rewrites), args);
  call->setCallingConv(llvm::CallingConv::Fast);
  return call;
}

// A call of a C library function, `nobuiltin` where its rewrites are not
// allowed.
Value* Lowering::library_call(llvm::IRBuilder<>& b, llvm::FunctionCallee f, llvm::ArrayRef<Value*> args,
                              Rewrites rewrites) {
  llvm::CallInst* call = b.CreateCall(f, args);
  if (rewrites == Rewrites::None) call->addFnAttr(llvm::Attribute::NoBuiltin);
  return call;
}

// The function of libm on vectors: it calls the library lane by lane and
// the kernel passes it the vectors whole.  With the lanes taken apart in
// the kernel, the optimiser moved them through the kernel's joins, and
// LLVM 15's x86 code generation once spilled a lane of one half of a
// register as a scalar and reloaded it as that half: a lane read 0 (4
// lanes at SSE 4.2 in f64, fuzz_ir seed 4030253428435575742).
llvm::Function* Lowering::lane_by_lane(llvm::FunctionCallee f, const std::string& symbol, llvm::Type* vector,
                                       std::size_t arity, Rewrites rewrites) {
  std::string name;
  llvm::raw_string_ostream os(name);
  os << "sh_lanes." << symbol << (rewrites == Rewrites::None ? ".opaque." : ".") << *vector;
  if (llvm::Function* known = module_->getFunction(os.str())) return known;
  std::vector<llvm::Type*> params(arity, vector);
  llvm::Function* lanes = helper_function(os.str(), llvm::FunctionType::get(vector, params, false));
  touches_no_memory(*lanes);
  llvm::IRBuilder<> b(BasicBlock::Create(ctx_, "entry", lanes));
  Value* result = llvm::PoisonValue::get(vector);
  for (int lane = 0; lane < width_; ++lane) {
    std::vector<Value*> lane_args;
    for (llvm::Argument& a : lanes->args()) lane_args.push_back(b.CreateExtractElement(&a, static_cast<std::uint64_t>(lane)));
    result = b.CreateInsertElement(result, library_call(b, f, lane_args, rewrites), static_cast<std::uint64_t>(lane));
  }
  b.CreateRet(result);
  return lanes;
}

// LLVM 15 rewrites pow(2^n, y) as exp2(n * y) in precise math too, and
// n * y rounds: pow(2^24, 3.657086f) came out 38 ulp off, past pow's
// bound of 16 (fuzz_ir seed 12162375951230191656), and f64 loses as
// much.  So where the exponent is not a constant here, pow is a call LLVM
// does not rewrite (code generation would call the library lane by lane
// for the vector intrinsic too); a constant exponent's rewrites (x * x,
// sqrt, 1 / x) are exact, and fast math allows the rest.
Value* Lowering::power(Value* base, Value* exponent) {
  if (o_.math == MathMode::Fast || llvm::isa<llvm::Constant>(exponent))
    return intrinsic(llvm::Intrinsic::pow, {base, exponent});
  return libm("pow", {base, exponent}, Rewrites::None);
}

// One case per row of the op table (ops.def), no default: a new operation
// does not build until it is lowered here.
Value* Lowering::operation(ir::Op op, ir::Scalar from, ir::Scalar to, Value* a, Value* b, Value* c) {
  using ir::Op;
  using P = llvm::CmpInst::Predicate;
  namespace I = llvm::Intrinsic;
  llvm::Type* t = a->getType();
  const bool fp = ir::is_float(from);
  Value* one = fp ? llvm::ConstantFP::get(t, 1.0) : nullptr;
  switch (op) {
    case Op::Mov: return a;
    case Op::Cast: return cast(a, from, to);
    case Op::Add: return fp ? b_.CreateFAdd(a, b) : b_.CreateAdd(a, b);
    case Op::Sub: return fp ? b_.CreateFSub(a, b) : b_.CreateSub(a, b);
    case Op::Mul: return fp ? b_.CreateFMul(a, b) : b_.CreateMul(a, b);
    // Legal IR divides integers only by divisors that cannot trap.
    case Op::Div: return fp ? b_.CreateFDiv(a, b) : b_.CreateSDiv(a, b);
    case Op::Mod: return floor_remainder(a, b, fp);
    case Op::Neg: return fp ? b_.CreateFNeg(a) : b_.CreateNeg(a);
    case Op::Min: return intrinsic(fp ? I::minnum : I::smin, {a, b});
    case Op::Max: return intrinsic(fp ? I::maxnum : I::smax, {a, b});
    case Op::Abs:
      if (fp) return intrinsic(I::fabs, {a});
      return b_.CreateCall(llvm::Intrinsic::getDeclaration(module_.get(), I::abs, {t}), {a, b_.getFalse()});
    case Op::Sign: return sign(a, fp);
    case Op::Floor: return intrinsic(I::floor, {a});
    case Op::Ceil: return intrinsic(I::ceil, {a});
    case Op::Round: return round_half_up(a);
    case Op::Sqrt: return intrinsic(I::sqrt, {a});
    case Op::Rsqrt: return b_.CreateFDiv(one, intrinsic(I::sqrt, {a}));
    case Op::Rcp: return b_.CreateFDiv(one, a);
    case Op::Pow: return power(a, b);
    case Op::Exp: return intrinsic(I::exp, {a});
    case Op::Exp2: return intrinsic(I::exp2, {a});
    case Op::Log: return intrinsic(I::log, {a});
    case Op::Log2: return intrinsic(I::log2, {a});
    case Op::Sin: return intrinsic(I::sin, {a});
    case Op::Cos: return intrinsic(I::cos, {a});
    case Op::Tan: return libm("tan", {a});
    case Op::Asin: return libm("asin", {a});
    case Op::Acos: return libm("acos", {a});
    case Op::Atan: return libm("atan", {a});
    case Op::Atan2: return libm("atan2", {a, b});
    case Op::Sinh: return libm("sinh", {a});
    case Op::Cosh: return libm("cosh", {a});
    case Op::Tanh: return libm("tanh", {a});
    case Op::Asinh: return libm("asinh", {a});
    case Op::Acosh: return libm("acosh", {a});
    case Op::Atanh: return libm("atanh", {a});
    case Op::Exp10: return libm("exp10", {a});  // LLVM 15 has no exp10 intrinsic
    case Op::Log10: return intrinsic(I::log10, {a});
    case Op::Cbrt: return libm("cbrt", {a});
    case Op::BitAnd: return b_.CreateAnd(a, b);
    case Op::BitOr: return b_.CreateOr(a, b);
    case Op::BitXor: return b_.CreateXor(a, b);
    case Op::BitNot: return b_.CreateNot(a);
    // Legal IR shifts by counts in [0, 31] only.
    case Op::Shl: return b_.CreateShl(a, b);
    case Op::Shr: return b_.CreateAShr(a, b);
    case Op::Lt: return mask(fp ? b_.CreateFCmp(P::FCMP_OLT, a, b) : b_.CreateICmp(P::ICMP_SLT, a, b), t);
    case Op::Le: return mask(fp ? b_.CreateFCmp(P::FCMP_OLE, a, b) : b_.CreateICmp(P::ICMP_SLE, a, b), t);
    case Op::Gt: return mask(fp ? b_.CreateFCmp(P::FCMP_OGT, a, b) : b_.CreateICmp(P::ICMP_SGT, a, b), t);
    case Op::Ge: return mask(fp ? b_.CreateFCmp(P::FCMP_OGE, a, b) : b_.CreateICmp(P::ICMP_SGE, a, b), t);
    case Op::Eq: return mask(fp ? b_.CreateFCmp(P::FCMP_OEQ, a, b) : b_.CreateICmp(P::ICMP_EQ, a, b), t);
    case Op::Ne: return mask(fp ? b_.CreateFCmp(P::FCMP_UNE, a, b) : b_.CreateICmp(P::ICMP_NE, a, b), t);
    case Op::And: return mask(b_.CreateAnd(truthy(a, from), truthy(b, from)), t);
    case Op::Or: return mask(b_.CreateOr(truthy(a, from), truthy(b, from)), t);
    case Op::Not: return mask(b_.CreateNot(truthy(a, from)), t);
    case Op::Cond: return b_.CreateSelect(truthy(a, from), b, c);
    case Op::AnyLane: return any_lane(a, from);
    case Op::Extent: case Op::Load: break;  // table_read()
    case Op::Position: break;               // position()
    case Op::Element: case Op::Store: case Op::Fill: break;  // arrays.cpp
    case Op::Fetch: case Op::Sample: break;  // not legal IR: the backend refuses it at compile
  }
  throw Error(std::string("cpu backend: ") + ir::op_name(op) + " reached the arithmetic lowering");
}

// The lanes running this statement are the group: their answers or'd, one
// value for all of them.  A uniform value (and scalar code) is its own
// answer.
Value* Lowering::any_lane(Value* a, ir::Scalar from) {
  llvm::Type* t = a->getType();
  if (!t->isVectorTy()) return mask(truthy(a, from), t);
  return mask(any(b_.CreateAnd(truthy(a, from), exec())), t->getScalarType());
}

Value* Lowering::cast(Value* a, ir::Scalar from, ir::Scalar to) {
  llvm::Type* t = reg_type(to, a->getType()->isVectorTy());
  if (to == ir::Scalar::Bool) return mask(truthy(a, from), t);
  if (to == ir::Scalar::I32) {
    if (!ir::is_float(from)) return a;
    return saturating_to_i32(a, t);
  }
  if (!ir::is_float(from)) return b_.CreateSIToFP(a, t);
  if (a->getType() == t) return a;
  return t->getScalarType()->isDoubleTy() ? b_.CreateFPExt(a, t) : b_.CreateFPTrunc(a, t);
}

// Truncation toward 0 where the value fits, NaN to 0, and INT_MIN or
// INT_MAX beyond, by definition.  LLVM's fptosi.sat says the same, but x86
// code generation splits a vector of it into two compares and a conversion
// per lane (a hundred instructions at 16 lanes, nine times in the tracer);
// here the compares and selects work on the whole vector.
Value* Lowering::saturating_to_i32(Value* a, llvm::Type* t) {
  Value* low = llvm::ConstantFP::get(a->getType(), -2147483648.0);
  Value* high = llvm::ConstantFP::get(a->getType(), 2147483648.0);
  Value* below = b_.CreateFCmpOLT(a, low);
  Value* above = b_.CreateFCmpOGE(a, high);
  Value* fits = b_.CreateAnd(b_.CreateFCmpOGE(a, low), b_.CreateFCmpOLT(a, high));  // not NaN
  Value* truncated = b_.CreateFPToSI(b_.CreateSelect(fits, a, llvm::ConstantFP::get(a->getType(), 0.0)), t);
  Value* saturated = b_.CreateSelect(below, llvm::ConstantInt::getSigned(t, std::numeric_limits<std::int32_t>::min()), truncated);
  return b_.CreateSelect(above, llvm::ConstantInt::get(t, std::numeric_limits<std::int32_t>::max()), saturated);
}

// -1, 0 or 1; a float's ±0 and NaN pass through.
Value* Lowering::sign(Value* a, bool fp) {
  llvm::Type* t = a->getType();
  if (fp) {
    Value* zero = llvm::ConstantFP::get(t, 0.0);
    Value* neg = b_.CreateSelect(b_.CreateFCmpOLT(a, zero), llvm::ConstantFP::get(t, -1.0), a);
    return b_.CreateSelect(b_.CreateFCmpOGT(a, zero), llvm::ConstantFP::get(t, 1.0), neg);
  }
  Value* zero = llvm::ConstantInt::get(t, 0);
  Value* neg = b_.CreateSelect(b_.CreateICmpSLT(a, zero), llvm::ConstantInt::getSigned(t, -1), zero);
  return b_.CreateSelect(b_.CreateICmpSGT(a, zero), llvm::ConstantInt::get(t, 1), neg);
}

// The remainder with the sign of b (Sh's and GLSL's mod): C's, whose sign
// is a's, plus b where the signs differ and it is not 0.  For floats frem is
// exact and the one addition rounds (ir/eval.cpp says why that is the
// reference's result).  Legal IR never divides an integer by 0 or -1.
Value* Lowering::floor_remainder(Value* a, Value* b, bool fp) {
  if (fp) {
    Value* zero = llvm::ConstantFP::get(a->getType(), 0.0);
    Value* r = b_.CreateFRem(a, b);
    Value* signs_differ = b_.CreateXor(b_.CreateFCmpOLT(r, zero), b_.CreateFCmpOLT(b, zero));
    return b_.CreateSelect(b_.CreateAnd(b_.CreateFCmpONE(r, zero), signs_differ), b_.CreateFAdd(r, b), r);
  }
  Value* zero = llvm::ConstantInt::get(a->getType(), 0);
  Value* r = b_.CreateSRem(a, b);
  Value* signs_differ = b_.CreateICmpSLT(b_.CreateXor(r, b), zero);
  return b_.CreateSelect(b_.CreateAnd(b_.CreateICmpNE(r, zero), signs_differ), b_.CreateAdd(r, b), r);
}

// Halves toward +Inf (Sh's floor(a + 0.5)), exactly: a - floor(a) is exact
// wherever it lies near 0.5, where a + 0.5 itself may round.
Value* Lowering::round_half_up(Value* a) {
  llvm::Type* t = a->getType();
  Value* f = intrinsic(llvm::Intrinsic::floor, {a});
  Value* up = b_.CreateFCmpOGE(b_.CreateFSub(a, f), llvm::ConstantFP::get(t, 0.5));
  return b_.CreateSelect(up, b_.CreateFAdd(f, llvm::ConstantFP::get(t, 1.0)), f);
}

// A table's extent, or its element at coordinates in range (legal IR).  A
// varying read is a gather over the running lanes, indexed in 32 bits (the
// kernel refuses bigger tables) so that it is one gather instruction per 16
// lanes, not two; where lanes turn out to read one element it is one load,
// and where they read a run (x + c of a stencil), one vector load.
void Lowering::table_read(const ir::Assign& a, std::array<Value*, 4>& result) {
  const ir::TableDecl& t = p_.tables[a.table];
  bool gather = varying(a.dest);
  if (a.op == ir::Op::Extent) {
    for (int d = 0; d < t.rank; ++d) result[d] = gather ? widen(table_dims_[a.table][d]) : table_dims_[a.table][d];
    return;
  }
  Value* flat = flat_index(a.table, a.args[0], gather);
  if (fetches_tables(o_)) {
    std::array<Value*, 4> raw = gather ? fetch_lanes(a.table, flat) : fetch(a.table, flat);
    for (int c = 0; c < t.element.width; ++c) result[c] = from_storage(raw[c], t.element.scalar);
    return;
  }
  Value* base = table_base_[a.table];
  llvm::Type* scalar = storage_scalar(t.element.scalar);
  auto element = [&](Value* flat_index, bool as_gather) {
    std::array<Value*, 4> values{};
    for (int c = 0; c < t.element.width; ++c) {
      llvm::Type* flat_type = flat_index->getType();
      Value* index = b_.CreateAdd(b_.CreateMul(flat_index, llvm::ConstantInt::get(flat_type, t.element.width)),
                                  llvm::ConstantInt::get(flat_type, c));
      if (as_gather)  // a lane that does not run reads a running lane's element if it reads at all
        values[c] = gather_lanes(scalar, base, index, exec(), llvm::Constant::getNullValue(lanes(scalar)), nullptr);
      else
        values[c] = b_.CreateLoad(scalar, b_.CreateInBoundsGEP(scalar, base, index));
    }
    return values;
  };
  std::array<Value*, 4> raw{};
  if (!gather)
    raw = element(flat, false);
  else if (access_.at(&a).proven_run && batch_inside_ && access_.at(&a).offset)
    raw = tap(a.table, *access_.at(&a).offset);
  else if (access_.at(&a).proven_run)
    raw = run_or_gather(a, flat, element);
  else if (access_.at(&a).hint == analysis::Access::Consecutive)
    raw = consecutive_or_gather(a.table, flat, element);
  else
    raw = same_or_gather(flat, element);
  for (int c = 0; c < t.element.width; ++c) result[c] = from_storage(raw[c], t.element.scalar);
}

// The elements of `base` at `index` in the lanes of `lanes_read`,
// `otherwise` in the others.  AVX-512's masked gather reads only the
// lanes read, whatever the others' indices hold, and takes the index
// as it is: a select for those lanes would hide the index's sign
// extension from x86 code generation, which then splits 16 lanes into two
// gathers of 64-bit indices.  A target without a fast gather instruction
// (AVX2 without AVX-512) has LLVM split a masked gather into a branch and
// a block per lane, which multiplies the code generator's work; there a
// gather is a call of one function per element and index type that loads
// every lane one after another with no branch, the others at `readable`
// (null: the first lane read's index, or lane 0's where none is).  Not
// element 0: a table may hold only the rows its reads reach (run_fused's
// strips), and element 0 need not be one of them.
Value* Lowering::gather_lanes(llvm::Type* scalar, Value* base, Value* index, Value* lanes_read, Value* otherwise,
                              Value* readable) {
  if (avx512_)
    return b_.CreateMaskedGather(lanes(scalar), b_.CreateInBoundsGEP(scalar, base, index), alignment(scalar), lanes_read,
                                 otherwise);
  if (!readable) readable = splat(in_first_lane(index, lanes_read));
  index = b_.CreateSelect(lanes_read, index, readable);
  llvm::CallInst* values = b_.CreateCall(lane_loads(scalar, index->getType()), {base, index});
  values->setCallingConv(llvm::CallingConv::Fast);
  return b_.CreateSelect(lanes_read, values, otherwise);
}

// The function of gather_lanes: compiled once, called by every gather of
// its types, so that the kernel's code stays one block per branch.
llvm::Function* Lowering::lane_loads(llvm::Type* scalar, llvm::Type* index_type) {
  std::string name;
  llvm::raw_string_ostream os(name);
  os << "sh_lane_loads." << *scalar << "." << *index_type;
  if (llvm::Function* known = module_->getFunction(os.str())) return known;
  llvm::Function* f = helper_function(os.str(), llvm::FunctionType::get(lanes(scalar), {b_.getPtrTy(), index_type}, false));
  llvm::IRBuilder<> b(BasicBlock::Create(ctx_, "entry", f));
  Value* values = llvm::Constant::getNullValue(lanes(scalar));
  for (int i = 0; i < width_; ++i) {
    Value* at = b.CreateInBoundsGEP(scalar, f->getArg(0), b.CreateExtractElement(f->getArg(1), static_cast<std::uint64_t>(i)));
    values = b.CreateInsertElement(values, b.CreateLoad(scalar, at), static_cast<std::uint64_t>(i));
  }
  b.CreateRet(values);
  return f;
}

// A function of the kernel's module that its code calls rather than
// repeats: internal, never inlined, its vectors as wide as the kernel's.
llvm::Function* Lowering::helper_function(const std::string& name, llvm::FunctionType* type) {
  auto* f = llvm::Function::Create(type, llvm::Function::InternalLinkage, name, module_.get());
  f->setCallingConv(llvm::CallingConv::Fast);
  f->addFnAttr(llvm::Attribute::NoInline);
  for (const char* a : {"min-legal-vector-width", "prefer-vector-width"})
    if (fn_->hasFnAttribute(a)) f->addFnAttr(fn_->getFnAttribute(a));
  return f;
}

// Field k of a fetched table's TableAccess (signature.hpp).
Value* Lowering::access_field(int table, unsigned k) {
  llvm::Type* ptr = b_.getPtrTy();
  llvm::Type* i64 = b_.getInt64Ty();
  auto* access = llvm::StructType::get(ctx_, {ptr, i64, i64, i64, ptr, i64, ptr});
  return b_.CreateStructGEP(access, table_base_[table], k);
}

// Where a fetched table's element lies: inside the window, read inline and
// counted; outside, one call moves the window to it.
Value* Lowering::fetched_element(int table, Value* flat) {
  const ir::TableDecl& t = p_.tables[table];
  llvm::Type* ptr = b_.getPtrTy();
  llvm::Type* i64 = b_.getInt64Ty();
  Value* first = b_.CreateLoad(i64, access_field(table, 1));
  Value* offset = b_.CreateSub(flat, first);
  Value* inside = b_.CreateICmpULT(offset, b_.CreateSub(b_.CreateLoad(i64, access_field(table, 2)), first));
  BasicBlock* from_window = BasicBlock::Create(ctx_, "fetch.window", fn_);
  BasicBlock* by_call = BasicBlock::Create(ctx_, "fetch.call", fn_);
  BasicBlock* done = BasicBlock::Create(ctx_, "fetch.done", fn_);
  b_.CreateCondBr(inside, from_window, by_call);
  b_.SetInsertPoint(from_window);
  std::int64_t bytes = t.element.width * ir::storage_bytes(t.element.scalar);
  Value* window = b_.CreateLoad(ptr, access_field(table, 0));
  Value* inline_element = b_.CreateInBoundsGEP(b_.getInt8Ty(), window, b_.CreateMul(offset, b_.getInt64(bytes)));
  b_.CreateStore(b_.CreateAdd(b_.CreateLoad(i64, access_field(table, 3)), b_.getInt64(1)), access_field(table, 3));
  b_.CreateBr(done);
  b_.SetInsertPoint(by_call);
  auto* element_fn = llvm::FunctionType::get(ptr, {ptr, i64}, false);
  Value* called_element = b_.CreateCall(element_fn, b_.CreateLoad(ptr, access_field(table, 4)), {table_base_[table], flat});
  b_.CreateBr(done);
  b_.SetInsertPoint(done);
  llvm::PHINode* element = b_.CreatePHI(ptr, 2);
  element->addIncoming(inline_element, from_window);
  element->addIncoming(called_element, by_call);
  return element;
}

std::array<Value*, 4> Lowering::fetch(int table, Value* flat) {
  const ir::TableDecl& t = p_.tables[table];
  llvm::Type* scalar = storage_scalar(t.element.scalar);
  Value* element = fetched_element(table, flat);
  std::array<Value*, 4> values{};
  for (int c = 0; c < t.element.width; ++c)
    values[c] = b_.CreateLoad(scalar, b_.CreateConstInBoundsGEP1_64(scalar, element, static_cast<std::uint64_t>(c)));
  return values;
}

// In SPMD, in rounds: the first lane still waiting brings its element into
// the window (a call only where it lies outside), then every waiting lane
// whose element lies in the window reads it, one gather per component.  A
// whole table takes one round; lanes reading k blocks, k rounds.  The
// rounds are a function per element type, which each read of a table of
// that type calls with the table's access: inlined at every read (a
// tracer has dozens) they took a third of its fetched kernel's
// machine-code time, and one function per table a fifth.
std::array<Value*, 4> Lowering::fetch_lanes(int table, Value* flat) {
  const ir::TableDecl& t = p_.tables[table];
  llvm::CallInst* call = b_.CreateCall(fetch_rounds(table), {table_base_[table], flat, exec()});
  call->setCallingConv(llvm::CallingConv::Fast);
  std::array<Value*, 4> values{};
  for (int c = 0; c < t.element.width; ++c) values[c] = b_.CreateExtractValue(call, {static_cast<unsigned>(c)});
  return values;
}

// fetch_lanes' function for the tables of one element type: (a table's
// TableAccess, the lanes' flat indices, the lanes that read) to the
// components' vectors.  Lowered as the kernel is, with the function and
// the table's access its own meanwhile.
llvm::Function* Lowering::fetch_rounds(int table) {
  const ir::TableDecl& t = p_.tables[table];
  llvm::Type* scalar = storage_scalar(t.element.scalar);
  std::string name;
  llvm::raw_string_ostream os(name);
  os << "sh_fetch_lanes." << *scalar << "x" << t.element.width;
  if (llvm::Function* known = module_->getFunction(name)) return known;
  std::vector<llvm::Type*> components(static_cast<std::size_t>(t.element.width), lanes(scalar));
  llvm::Type* vectors = llvm::StructType::get(ctx_, components);
  llvm::Function* f = helper_function(
      name, llvm::FunctionType::get(vectors, {b_.getPtrTy(), lanes(b_.getInt32Ty()), mask_type()}, false));
  llvm::Function* kernel = fn_;
  Value* access = table_base_[table];
  llvm::IRBuilderBase::InsertPoint resume = b_.saveIP();
  fn_ = f;
  table_base_[table] = f->getArg(0);
  b_.SetInsertPoint(BasicBlock::Create(ctx_, "entry", f));
  llvm::AllocaInst* out = entry_alloca(vectors, "fetched");
  fetch_round_loop(table, f->getArg(1), f->getArg(2), out);
  b_.CreateRet(b_.CreateLoad(vectors, out));
  fn_ = kernel;
  table_base_[table] = access;
  b_.restoreIP(resume);
  return f;
}

// Where the lanes of `reading` find their elements in a fetched table's
// window: in scalars from its start, and which lie inside it.  In 32 bits,
// as the table's own indices are (below 2^31): the window's bounds, capped
// at 2^31, keep a lane's offset from its start below the span exactly
// where its element lies inside, wrapping where it lies before; the offset
// in scalars fits as the table's own does (CpuKernel::check_gather_range).
// Lanes of 64 bits would be two registers each.
std::pair<Value*, Value*> Lowering::window_lanes(int table, Value* flat, Value* reading) {
  const ir::TableDecl& t = p_.tables[table];
  auto bound = [&](unsigned field) {
    Value* bound = b_.CreateLoad(b_.getInt64Ty(), access_field(table, field));
    Value* capped = b_.CreateBinaryIntrinsic(llvm::Intrinsic::umin, bound, b_.getInt64(std::int64_t{1} << 31));
    return b_.CreateTrunc(capped, b_.getInt32Ty());
  };
  Value* first = bound(1);
  Value* offset = b_.CreateSub(flat, splat(first));
  Value* inside = b_.CreateAnd(reading, b_.CreateICmpULT(offset, splat(b_.CreateSub(bound(2), first))));
  return {b_.CreateMul(offset, splat(b_.getInt32(t.element.width))), inside};
}

// The rounds, into the struct of component vectors at `out`.
void Lowering::fetch_round_loop(int table, Value* flat, Value* running, Value* out) {
  const ir::TableDecl& t = p_.tables[table];
  llvm::Type* scalar = storage_scalar(t.element.scalar);
  llvm::Type* vector = lanes(scalar);
  llvm::Type* i64 = b_.getInt64Ty();
  llvm::Type* components = llvm::cast<llvm::AllocaInst>(out)->getAllocatedType();
  std::array<Value*, 4> slots{};
  for (int c = 0; c < t.element.width; ++c) {
    slots[c] = b_.CreateStructGEP(components, out, static_cast<unsigned>(c));
    b_.CreateStore(llvm::Constant::getNullValue(vector), slots[c]);
  }
  llvm::AllocaInst* waiting = entry_alloca(mask_slot_type(), "waiting");
  store_mask(running, waiting);
  BasicBlock* head = BasicBlock::Create(ctx_, "fetch.rounds", fn_);
  BasicBlock* round = BasicBlock::Create(ctx_, "fetch.round", fn_);
  BasicBlock* done = BasicBlock::Create(ctx_, "fetch.rounds.done", fn_);
  b_.CreateBr(head);
  b_.SetInsertPoint(head);
  Value* still = load_mask(waiting);
  b_.CreateCondBr(any(still), round, done);

  b_.SetInsertPoint(round);
  Value* leader = first_lane(still);
  fetched_element(table, b_.CreateZExt(b_.CreateExtractElement(flat, leader), i64));  // into the window
  auto [at, in_window] = window_lanes(table, flat, still);
  Value* window = b_.CreateLoad(b_.getPtrTy(), access_field(table, 0));
  // A lane not reading in this round reads the leading lane's element,
  // which the window holds, if it reads at all.
  Value* leader_at = splat(b_.CreateExtractElement(at, leader));
  for (int c = 0; c < t.element.width; ++c) {
    Value* component = b_.CreateConstInBoundsGEP1_64(scalar, window, static_cast<std::uint64_t>(c));
    b_.CreateStore(gather_lanes(scalar, component, at, in_window, b_.CreateLoad(vector, slots[c]), leader_at), slots[c]);
  }
  // fetched_element counted the first lane's read.
  Value* others = b_.CreateSub(b_.CreateAddReduce(b_.CreateZExt(in_window, lanes(i64))), b_.getInt64(1));
  b_.CreateStore(b_.CreateAdd(b_.CreateLoad(i64, access_field(table, 3)), others), access_field(table, 3));
  keep_lanes(waiting, b_.CreateNot(in_window));
  b_.CreateBr(head);
  b_.SetInsertPoint(done);
}

// Code for each lane that runs the current statement, lane by lane.
void Lowering::for_each_running_lane(const std::function<void(std::uint64_t lane)>& emit) {
  Value* running = exec();
  for (int lane = 0; lane < width_; ++lane) {
    auto k = static_cast<std::uint64_t>(lane);
    BasicBlock* body = BasicBlock::Create(ctx_, "lane", fn_);
    BasicBlock* next = BasicBlock::Create(ctx_, "lane.next", fn_);
    b_.CreateCondBr(b_.CreateExtractElement(running, k), body, next);
    b_.SetInsertPoint(body);
    emit(k);
    b_.CreateBr(next);
    b_.SetInsertPoint(next);
  }
}

// The element a read or scatter names (coordinates in range: legal IR),
// or a prefetch (coordinates as asked): i32 lanes where `gather`, else one
// i64.
Value* Lowering::flat_index(int table, const ir::Operand& coord, bool gather) {
  llvm::Type* index_type = gather ? lanes(b_.getInt32Ty()) : b_.getInt64Ty();
  auto index_of = [&](Value* i32) { return gather ? i32 : b_.CreateZExt(i32, index_type); };
  Value* flat = llvm::ConstantInt::get(index_type, 0);
  Value* stride = llvm::ConstantInt::get(index_type, 1);
  for (int d = 0; d < p_.tables[table].rank; ++d) {
    Value* dim = gather ? splat(table_dims_[table][d]) : table_dims_[table][d];
    Value* i = gather ? widen(read(coord, d)) : read(coord, d);
    flat = b_.CreateAdd(flat, b_.CreateMul(index_of(i), stride));
    stride = b_.CreateMul(stride, index_of(dim));
  }
  return flat;
}

// Atomic additions, so that threads may add to the same element.  In SPMD
// each running lane adds its own value, one lane after another: lanes of
// one set often add to the same element.
void Lowering::scatter(const ir::Scatter& sc) {
  const ir::TableDecl& t = p_.tables[sc.table];
  bool per_lane = spmd();
  Value* flat = flat_index(sc.table, sc.index, per_lane);
  llvm::Type* scalar = storage_scalar(t.element.scalar);
  std::array<Value*, 4> value{};
  for (int c = 0; c < t.element.width; ++c) {
    Value* x = read(sc.value, c);
    value[c] = to_storage(per_lane ? widen(x) : x, t.element.scalar);
  }
  auto add = [&](Value* element, auto lane_of) {
    for (int c = 0; c < t.element.width; ++c) {
      Value* at = b_.CreateInBoundsGEP(scalar, table_base_[sc.table],
                                       b_.CreateAdd(b_.CreateMul(element, b_.getInt64(t.element.width)), b_.getInt64(c)));
      auto op = ir::is_float(t.element.scalar) ? llvm::AtomicRMWInst::FAdd : llvm::AtomicRMWInst::Add;
      b_.CreateAtomicRMW(op, at, lane_of(value[c]), alignment(scalar), llvm::AtomicOrdering::Monotonic);
    }
  };
  if (!per_lane) return add(flat, [](Value* x) { return x; });
  for_each_running_lane([&](std::uint64_t k) {
    add(b_.CreateZExt(b_.CreateExtractElement(flat, k), b_.getInt64Ty()),
        [&](Value* x) { return b_.CreateExtractElement(x, k); });
  });
}

// A prefetch instruction never faults, at any address: so its coordinates
// are taken as they come, outside the table too (legal IR does not clamp
// them), and a lane that does not run asks for its element too: cheaper
// than a test.  The flat index's arithmetic wraps (no flag makes an
// overflow poison), so no coordinate makes the address undefined.  A
// fetched table is not in this process's memory: nothing to bring.
void Lowering::prefetch(const ir::Prefetch& pf) {
  if (fetches_tables(o_)) return;
  bool per_lane = varying(pf.index.var);
  Value* flat = flat_index(pf.table, pf.index, per_lane);
  if (!per_lane) return prefetch_element(pf.table, flat);
  for (int lane = 0; lane < width_; ++lane)
    prefetch_element(pf.table, b_.CreateZExt(b_.CreateExtractElement(flat, static_cast<std::uint64_t>(lane)), b_.getInt64Ty()));
}

// Asks for the cache line of a table's element (an i64 flat index).
void Lowering::prefetch_element(int table, Value* element) {
  const ir::TableDecl& t = p_.tables[table];
  Value* at = b_.CreateGEP(storage_scalar(t.element.scalar), table_base_[table],
                           b_.CreateMul(element, b_.getInt64(t.element.width)));
  b_.CreateIntrinsic(llvm::Intrinsic::prefetch, {at->getType()}, {at, b_.getInt32(0), b_.getInt32(3), b_.getInt32(1)});
}

// Gathers cost a load per lane.  Where every running lane reads the same
// element (coherent rays in one grid cell, say) one load serves them all:
// checked at run time, per table read.  With no lane running (statements
// after every lane broke out) lane 0's clamped index is read, harmlessly.
std::array<Value*, 4> Lowering::same_or_gather(Value* flat, const ElementRead& element) {
  Value* running = exec();
  Value* index = in_first_lane(flat, running);
  Value* same = b_.CreateOr(b_.CreateICmpEQ(flat, splat(index)), b_.CreateNot(running));
  BasicBlock* one = BasicBlock::Create(ctx_, "read.same", fn_);
  BasicBlock* many = BasicBlock::Create(ctx_, "read.gather", fn_);
  BasicBlock* join = BasicBlock::Create(ctx_, "read.done", fn_);
  b_.CreateCondBr(b_.CreateAndReduce(same), one, many);
  b_.SetInsertPoint(one);
  std::array<Value*, 4> loaded = element(index, false);
  for (Value*& x : loaded)
    if (x) x = splat(x);
  BasicBlock* one_end = b_.GetInsertBlock();
  b_.CreateBr(join);
  b_.SetInsertPoint(many);
  std::array<Value*, 4> gathered = element(flat, true);
  BasicBlock* many_end = b_.GetInsertBlock();
  b_.CreateBr(join);
  b_.SetInsertPoint(join);
  std::array<Value*, 4> joined{};
  for (int c = 0; c < 4 && loaded[c]; ++c) {
    llvm::PHINode* phi = b_.CreatePHI(loaded[c]->getType(), 2);
    phi->addIncoming(loaded[c], one_end);
    phi->addIncoming(gathered[c], many_end);
    joined[c] = phi;
  }
  return joined;
}

// Running lanes that read one element after another (a stencil's
// neighbour at x + c: table_access's hint) are one masked vector load of
// the run, components deinterleaved; where they do not (a row's edge, where
// reads clamp), a gather.
std::array<Value*, 4> Lowering::consecutive_or_gather(int table, Value* flat, const ElementRead& element) {
  Value* start = b_.CreateExtractElement(flat, std::uint64_t{0});
  Value* in_step = b_.CreateICmpEQ(flat, b_.CreateAdd(splat(start), lane_numbers()));
  Value* all_in_step = b_.CreateAndReduce(b_.CreateOr(in_step, b_.CreateNot(exec())));
  BasicBlock* run = BasicBlock::Create(ctx_, "read.run", fn_);
  BasicBlock* many = BasicBlock::Create(ctx_, "read.gather", fn_);
  b_.CreateCondBr(all_in_step, run, many);
  b_.SetInsertPoint(run);
  std::array<Value*, 4> loaded = masked_run(table, b_.CreateZExt(start, b_.getInt64Ty()), exec());
  BasicBlock* run_end = b_.GetInsertBlock();
  b_.SetInsertPoint(many);
  std::array<Value*, 4> gathered = element(flat, true);
  return joined(loaded, run_end, gathered, b_.GetInsertBlock(), p_.tables[table].element.width);
}

// A read whose coordinates as asked are proven to run along the row
// (table_access).  Of a table that clamps or reads zero, where the target
// permutes lanes: its window, tested only for x wrapping past INT_MAX.
// Otherwise, where the batch's run lies inside the table, nothing is
// clamped and it is one masked vector load, tested by its ends alone; at
// the table's edges, the clamped run of a table that clamps or reads zero,
// a gather of the wrapped coordinates of one that repeats.
std::array<Value*, 4> Lowering::run_or_gather(const ir::Assign& a, Value* flat, const ElementRead& element) {
  if (p_.tables[a.table].edge != ir::Edge::Repeat && permutes(a.table)) return window_or_gather(a, flat, element);
  Run r = run_of(a);
  BasicBlock* run = BasicBlock::Create(ctx_, "read.run", fn_);
  BasicBlock* edge = BasicBlock::Create(ctx_, "read.edge", fn_);
  b_.CreateCondBr(r.inside, run, edge);
  b_.SetInsertPoint(run);
  std::array<Value*, 4> loaded = masked_run(a.table, r.start, exec());
  BasicBlock* run_end = b_.GetInsertBlock();
  b_.SetInsertPoint(edge);
  std::array<Value*, 4> at_edge =
      p_.tables[a.table].edge == ir::Edge::Repeat ? element(flat, true) : clamped_run(a, flat);
  return joined(loaded, run_end, at_edge, b_.GetInsertBlock(), p_.tables[a.table].element.width);
}

// A proven run at the table's edge, where reads clamp (legal IR reads a
// Zero table at the clamped place too): the running lanes whose x lies in
// the row read it with one masked vector load, those before the row take
// its first element and those past it its last.  No gather: on AMD's Zen
// 4, which microcodes a 16-lane gather, the gathers cost a 512-pixel-wide
// blur 8-11 % of its time.
std::array<Value*, 4> Lowering::clamped_run(const ir::Assign& a, Value* flat) {
  Value* asked_x = widen(read(a.args[1], 0));
  return clamped_run(a.table, row_start(a, asked_x, flat), asked_x);
}

// The same for the lanes at `asked_x` of the row whose first element is
// at flat index `row`.
std::array<Value*, 4> Lowering::clamped_run(int table, Value* row, Value* asked_x) {
  const ir::TableDecl& t = p_.tables[table];
  llvm::Type* i64 = b_.getInt64Ty();
  Value* row_length = table_dims_[table][0];
  Value* before = b_.CreateICmpSLT(asked_x, splat(b_.getInt32(0)));
  Value* past = b_.CreateICmpSGE(asked_x, splat(row_length));
  Value* in_row = b_.CreateAnd(exec(), b_.CreateNot(b_.CreateOr(before, past)));
  Value* first_x = b_.CreateExtractElement(asked_x, std::uint64_t{0});
  std::array<Value*, 4> values = masked_run(table, b_.CreateAdd(row, b_.CreateSExt(first_x, i64)), in_row);
  llvm::Type* scalar = storage_scalar(t.element.scalar);
  Value* last = b_.CreateAdd(row, b_.CreateZExt(b_.CreateSub(row_length, b_.getInt32(1)), i64));
  for (int c = 0; c < t.element.width; ++c) {
    auto element_at = [&](Value* index) {
      Value* at = b_.CreateAdd(b_.CreateMul(index, b_.getInt64(t.element.width)), b_.getInt64(c));
      return splat(b_.CreateLoad(scalar, b_.CreateInBoundsGEP(scalar, table_base_[table], at)));
    };
    values[c] = b_.CreateSelect(before, element_at(row), b_.CreateSelect(past, element_at(last), values[c]));
  }
  return values;
}

// The flat index of the first element of the row a proven run reads: lane
// 0's clamped flat index less its clamped x.
Value* Lowering::row_start(const ir::Assign& a, Value* asked_x, Value* flat) {
  Value* first_x = b_.CreateExtractElement(asked_x, std::uint64_t{0});
  Value* last_x = b_.CreateSub(table_dims_[a.table][0], b_.getInt32(1));
  Value* first_x_clamped = clamped(first_x, b_.getInt32(0), last_x);
  return b_.CreateZExt(b_.CreateSub(b_.CreateExtractElement(flat, std::uint64_t{0}), first_x_clamped), b_.getInt64Ty());
}

// `v` no less than `low` and no more than `high` (signed; lane by lane
// where they are vectors).
Value* Lowering::clamped(Value* v, Value* low, Value* high) {
  return b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, b_.CreateBinaryIntrinsic(llvm::Intrinsic::smax, v, low), high);
}

// A run whose x passes INT_MAX within the batch has lanes far past the row
// and lanes wrapped far before it, which no window of the row holds: those
// (never in practice) gather at the clamped places; all others read their
// window.
std::array<Value*, 4> Lowering::window_or_gather(const ir::Assign& a, Value* flat, const ElementRead& element) {
  Value* asked_x = widen(read(a.args[1], 0));
  Value* first_x = b_.CreateExtractElement(asked_x, std::uint64_t{0});
  Value* wraps = b_.CreateICmpSGT(first_x, b_.getInt32(std::numeric_limits<std::int32_t>::max() - (width_ - 1)));
  BasicBlock* window = BasicBlock::Create(ctx_, "read.window", fn_);
  BasicBlock* wrapped = BasicBlock::Create(ctx_, "read.wrapped", fn_);
  b_.CreateCondBr(wraps, wrapped, window, llvm::MDBuilder(ctx_).createBranchWeights(1, 1 << 20));
  b_.SetInsertPoint(window);
  std::array<Value*, 4> in_window = window_run(a.table, row_start(a, asked_x, flat), asked_x);
  BasicBlock* window_end = b_.GetInsertBlock();
  b_.SetInsertPoint(wrapped);
  std::array<Value*, 4> gathered = element(flat, true);
  return joined(in_window, window_end, gathered, b_.GetInsertBlock(), p_.tables[a.table].element.width);
}

// A proven run along the row whose first element is at flat index `row`,
// where reads clamp (legal IR reads a Zero table at the clamped place too)
// and the target permutes lanes: one load of the
// `width_` elements of the row nearest the run, from which each lane takes
// its clamped element by one permute.  The window starts where the run
// does, moved into the row (a row shorter than the lanes is loaded
// masked); inside the row the permute keeps every lane in place, so a read
// needs no test of where it lies.
std::array<Value*, 4> Lowering::window_run(int table, Value* row, Value* asked_x) {
  Value* row_length = table_dims_[table][0];
  Value* clamped_x = clamped(asked_x, splat(b_.getInt32(0)), splat(b_.CreateSub(row_length, b_.getInt32(1))));
  // Where the row is shorter than the lanes, the window starts at 0.
  Value* last_start = b_.CreateSub(row_length, b_.getInt32(width_));
  Value* window = b_.CreateBinaryIntrinsic(
      llvm::Intrinsic::smax,
      b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, b_.CreateExtractElement(asked_x, std::uint64_t{0}), last_start),
      b_.getInt32(0));
  Value* in_row = b_.CreateICmpSLT(lane_numbers(), splat(b_.CreateSub(row_length, window)));
  Value* start = b_.CreateAdd(row, b_.CreateZExt(window, b_.getInt64Ty()));
  std::array<Value*, 4> values = masked_run(table, start, in_row);
  Value* index = b_.CreateSub(clamped_x, splat(window));
  for (int c = 0; c < p_.tables[table].element.width; ++c) values[c] = permuted(values[c], index);
  return values;
}

// Whether the target permutes a table's elements across lanes in one
// instruction: 32-bit elements, where lane_permute_ names one.
bool Lowering::permutes(int table) const {
  return lane_permute_ != llvm::Intrinsic::not_intrinsic &&
         storage_scalar(p_.tables[table].element.scalar)->getPrimitiveSizeInBits() == 32;
}

// Lane i of the result is lane index[i] of `values` (32-bit lanes).
Value* Lowering::permuted(Value* values, Value* index) {
  llvm::Type* floats = lanes(b_.getFloatTy());
  Value* moved = b_.CreateIntrinsic(lane_permute_, {}, {b_.CreateBitCast(values, floats), index});
  return b_.CreateBitCast(moved, values->getType());
}

// The run a proven read's lanes ask for: its start (the first lane's
// coordinates as asked) and whether it fits in the table.
Lowering::Run Lowering::run_of(const ir::Assign& a) {
  const ir::TableDecl& t = p_.tables[a.table];
  llvm::Type* i64 = b_.getInt64Ty();
  Value* inside = b_.getTrue();
  Value* start = b_.getInt64(0);
  Value* stride = b_.getInt64(1);
  for (int d = 0; d < t.rank; ++d) {
    Value* first = b_.CreateSExt(b_.CreateExtractElement(widen(read(a.args[1], d)), std::uint64_t{0}), i64);
    Value* extent = b_.CreateZExt(table_dims_[a.table][d], i64);
    // Starts of a run that fits: [0, extent - lanes]; one unsigned compare
    // (a negative start is a huge one), against a bound shared by the reads.
    Value* starts = d == 0 ? b_.CreateBinaryIntrinsic(llvm::Intrinsic::smax,
                                                      b_.CreateAdd(b_.CreateSub(extent, batch_count_), b_.getInt64(1)),
                                                      b_.getInt64(0))
                           : extent;
    inside = b_.CreateAnd(inside, b_.CreateICmpULT(first, starts));
    start = b_.CreateAdd(start, b_.CreateMul(first, stride));
    stride = b_.CreateMul(stride, extent);
  }
  return {inside, start};
}

// The flat index of a tap's run in a batch inside the table: position()
// plus the offset, in 64 bits, so that taps on one row share its address.
Value* Lowering::tap_start(int table, const std::array<int, 3>& offset) {
  llvm::Type* i64 = b_.getInt64Ty();
  Value* start = b_.getInt64(0);
  Value* stride = b_.getInt64(1);
  for (int d = 0; d < p_.tables[table].rank; ++d) {
    Value* at = b_.CreateNSWAdd(batch_place_[d], b_.getInt64(offset[d]));
    start = b_.CreateNSWAdd(start, b_.CreateNSWMul(at, stride));
    stride = b_.CreateNSWMul(stride, b_.CreateZExt(table_dims_[table][d], i64));
  }
  return start;
}

// Each row of a table's taps (by table and y and z offsets), with the
// smallest and largest x offset of its taps; ordered, so that their loads
// come in one order every time.
std::map<std::tuple<int, int, int>, std::pair<int, int>> Lowering::tap_row_spans() const {
  std::map<std::tuple<int, int, int>, std::pair<int, int>> spans;
  for (const auto& [read, access] : access_) {
    if (!access.proven_run || !access.offset) continue;
    const std::array<int, 3>& at = *access.offset;
    auto row = spans.try_emplace({read->table, at[1], at[2]}, at[0], at[0]).first;
    row->second = {std::min(row->second.first, at[0]), std::max(row->second.second, at[0])};
  }
  return spans;
}

// A stencil's taps along one row overlap: a 5-tap row read as five
// vector loads touches each element five times, and on AVX-512 four of the
// five loads cross a cache line.  Two loads, at the row's first and last
// tap, hold every element the row's taps read when they are at most a
// batch apart; the taps between are shuffles of the two (one `valignd` or
// `vpermt2ps` each), which freed a 5 x 5 blur's load port for 22 % of its
// time in a C++ scratch program on a Zen 4 host; an Intel host with one
// shuffle port showed no gain (BENCHMARKS.md, issue 25).  Without AVX-512
// a shuffle across a vector's 128-bit halves is two instructions
// (`vperm2f128`, then `vpalignr`), eight micro-operations on Zen 1, and a
// load a tap is faster: a third of the direct blur's time on such a host.
// A wider element's two runs are deinterleaved once, not once a tap.
void Lowering::load_tap_rows() {
  if (!avx512_) return;
  for (const auto& [row, span] : tap_row_spans()) {
    auto [low, high] = span;
    if (low == high || std::int64_t{high} - low > width_) continue;  // offsets may lie near the int limits
    auto [table, y, z] = row;
    auto load = [&](int x) { return masked_run(table, tap_start(table, {x, y, z}), exec()); };
    tap_rows_[row] = {low, high, load(low), load(high)};
  }
}

// A full batch with taps past its tables' edges, of a program whose tapped
// tables all clamp (clamps_taps_): every row of taps as two vectors, as
// inside, but each read clamped, the row's y and z once for its taps and
// its runs at the first and last tap as a window each (or a masked load
// and two selects where the target has no permute).  The body then reads
// its taps as it does inside: a row's taps cost two clamped reads and
// shuffles, where each alone was a clamped read with its own coordinates,
// and a 5 x 5 blur's two edge batches a row took 12 % of its time
// against the C++ loop's 3 % (BENCHMARKS.md, issue 25).
void Lowering::load_clamped_tap_rows() {
  llvm::Type* i64 = b_.getInt64Ty();
  for (const auto& [row, span] : tap_row_spans()) {
    auto [table, y, z] = row;
    auto [low, high] = span;
    Value* start = b_.getInt64(0);
    Value* stride = b_.CreateZExt(table_dims_[table][0], i64);
    for (int d = 1; d < p_.tables[table].rank; ++d) {
      Value* extent = b_.CreateZExt(table_dims_[table][d], i64);
      Value* at = b_.CreateAdd(batch_place_[d], b_.getInt64(d == 1 ? y : z));
      start = b_.CreateAdd(start, b_.CreateMul(clamped(at, b_.getInt64(0), b_.CreateSub(extent, b_.getInt64(1))), stride));
      stride = b_.CreateMul(stride, extent);
    }
    auto run = [&](int x) {
      Value* first = b_.CreateTrunc(b_.CreateAdd(batch_place_[0], b_.getInt64(x)), b_.getInt32Ty());
      Value* asked_x = b_.CreateAdd(splat(first), lane_numbers());
      return permutes(table) ? window_run(table, start, asked_x) : clamped_run(table, start, asked_x);
    };
    std::array<Value*, 4> first = run(low);
    tap_rows_[row] = {low, high, first, low == high ? first : run(high)};
  }
}

// Whether the batch's taps, as each lane asks for them, are in 32-bit
// range along every dimension, as load_clamped_tap_rows' coordinates must be
// to be the program's (theirs are 32-bit sums that could wrap).
Value* Lowering::taps_in_range() {
  Value* in_range = b_.getTrue();
  for (std::size_t t = 0; t < tap_spans_.size(); ++t) {
    if (!tap_spans_[t]) continue;
    for (int d = 0; d < p_.tables[t].rank; ++d) {
      std::int64_t high = std::int64_t{tap_spans_[t]->high[d]} + (d == 0 ? width_ - 1 : 0);
      Value* last = b_.CreateAdd(batch_place_[d], b_.getInt64(high));
      in_range = b_.CreateAnd(in_range, b_.CreateICmpSLE(last, b_.getInt64(std::numeric_limits<std::int32_t>::max())));
    }
  }
  return in_range;
}

// A tap of a batch inside its table: from its row's two vectors where
// load_tap_rows() loaded them, else its own load.
std::array<Value*, 4> Lowering::tap(int table, const std::array<int, 3>& offset) {
  auto row = tap_rows_.find({table, offset[1], offset[2]});
  if (row == tap_rows_.end()) return masked_run(table, tap_start(table, offset), exec());
  const TapRow& r = row->second;
  if (offset[0] == r.low) return r.first;
  if (offset[0] == r.high) return r.last;
  // Lane i reads the row at offset[0] + i: in the first run below
  // low + width_, past it in the last (which starts at high <= low + width_).
  std::vector<int> lanes;
  for (int i = 0; i < width_; ++i) {
    std::int64_t x = std::int64_t{offset[0]} + i;
    lanes.push_back(static_cast<int>(x - r.low < width_ ? x - r.low : width_ + x - r.high));
  }
  std::array<Value*, 4> values{};
  for (int c = 0; c < p_.tables[table].element.width; ++c) values[c] = b_.CreateShuffleVector(r.first[c], r.last[c], lanes);
  return values;
}

// Whether every tap of the batch lies inside its table: per table, the
// taps' smallest and largest offsets against its edges (null where the
// program has no tap).
Value* Lowering::batch_inside() {
  if (!spmd() || fetches_tables(o_)) return nullptr;
  llvm::Type* i64 = b_.getInt64Ty();
  Value* inside = nullptr;
  for (std::size_t t = 0; t < tap_spans_.size(); ++t) {
    if (!tap_spans_[t]) continue;
    for (int d = 0; d < p_.tables[t].rank; ++d) {
      Value* at = batch_place_[d];
      Value* low = b_.CreateAdd(at, b_.getInt64(tap_spans_[t]->low[d]));
      Value* high = b_.CreateAdd(at, b_.getInt64(tap_spans_[t]->high[d]));
      if (d == 0) high = b_.CreateAdd(high, b_.CreateSub(batch_count_, b_.getInt64(1)));
      Value* fits = b_.CreateAnd(b_.CreateICmpSGE(low, b_.getInt64(0)),
                                 b_.CreateICmpSLT(high, b_.CreateZExt(table_dims_[t][d], i64)));
      inside = inside ? b_.CreateAnd(inside, fits) : fits;
    }
  }
  return inside;
}

// The largest x at which a full batch's taps end inside every table they
// read along the row.
Value* Lowering::last_inside_x() {
  Value* last = nullptr;
  for (std::size_t t = 0; t < tap_spans_.size(); ++t) {
    if (!tap_spans_[t]) continue;
    Value* x = b_.CreateSub(b_.CreateZExt(table_dims_[t][0], b_.getInt64Ty()), b_.getInt64(std::int64_t{tap_spans_[t]->high[0]} + width_));
    last = last ? b_.CreateBinaryIntrinsic(llvm::Intrinsic::smin, last, x) : x;
  }
  return last;
}

// The elements from `start` on, one after another, in the lanes of
// `running`: a masked vector load (lanes not read are not touched, so the
// run may pass the table's ends there), components deinterleaved.
std::array<Value*, 4> Lowering::masked_run(int table, Value* start, Value* running) {
  const ir::TableDecl& t = p_.tables[table];
  int w = t.element.width;
  llvm::Type* scalar = storage_scalar(t.element.scalar);
  Value* at = b_.CreateGEP(scalar, table_base_[table], b_.CreateMul(start, b_.getInt64(w)));
  std::vector<int> per_value;
  for (int i = 0; i < width_ * w; ++i) per_value.push_back(i / w);
  Value* values_running = w == 1 ? running : b_.CreateShuffleVector(running, per_value);
  auto* block_type = llvm::FixedVectorType::get(scalar, static_cast<unsigned>(width_ * w));
  Value* block = b_.CreateMaskedLoad(block_type, at, alignment(scalar), values_running, llvm::Constant::getNullValue(block_type));
  return deinterleave(block, w);
}

// The values of two paths, where they meet; ends both blocks.
std::array<Value*, 4> Lowering::joined(const std::array<Value*, 4>& a, BasicBlock* from_a, const std::array<Value*, 4>& b,
                                       BasicBlock* from_b, int width) {
  BasicBlock* join = BasicBlock::Create(ctx_, "read.done", fn_);
  b_.SetInsertPoint(from_a);
  b_.CreateBr(join);
  b_.SetInsertPoint(from_b);
  b_.CreateBr(join);
  b_.SetInsertPoint(join);
  std::array<Value*, 4> out{};
  for (int c = 0; c < width; ++c) {
    llvm::PHINode* phi = b_.CreatePHI(a[c]->getType(), 2);
    phi->addIncoming(a[c], from_a);
    phi->addIncoming(b[c], from_b);
    out[c] = phi;
  }
  return out;
}

}  // namespace sh::cpu
