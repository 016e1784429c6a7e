#include "lower.hpp"

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>

#include "signature.hpp"

namespace sh::cpu {
namespace {

using llvm::BasicBlock;
using llvm::Value;

class Lowering {
 public:
  Lowering(const ir::Program& p, const Options& o, llvm::LLVMContext& ctx)
      : p_(p), o_(o), ctx_(ctx), module_(std::make_unique<llvm::Module>(p.name, ctx)), b_(ctx) {}

  Lowered run() {
    if (o_.math == MathMode::Fast) b_.setFastMathFlags(llvm::FastMathFlags::getFast());
    function();
    return Lowered{std::move(module_), std::move(loops_)};
  }

 private:
  // ---- types ---------------------------------------------------------------

  llvm::Type* reg_type(ir::Scalar s) const {
    switch (s) {
      case ir::Scalar::F32:
        return o_.precision == Precision::F32 ? llvm::Type::getFloatTy(ctx_) : llvm::Type::getDoubleTy(ctx_);
      case ir::Scalar::F64: return llvm::Type::getDoubleTy(ctx_);
      default: return llvm::Type::getInt32Ty(ctx_);
    }
  }
  llvm::Type* storage_type(ir::Scalar s) const {
    switch (s) {
      case ir::Scalar::F32: return llvm::Type::getFloatTy(ctx_);
      case ir::Scalar::F64: return llvm::Type::getDoubleTy(ctx_);
      default: return llvm::Type::getInt32Ty(ctx_);
    }
  }
  llvm::Type* reg_type(ir::VarId v) const { return reg_type(p_.type_of(v).scalar); }

  // ---- the function and the stream loop -------------------------------------

  void function() {
    auto* ptr = b_.getPtrTy();
    auto* i64 = b_.getInt64Ty();
    auto* type = llvm::FunctionType::get(b_.getVoidTy(), {i64, i64, ptr, ptr, ptr, ptr, ptr, ptr}, false);
    fn_ = llvm::Function::Create(type, llvm::Function::ExternalLinkage, kKernelSymbol, module_.get());
    if (o_.math == MathMode::Precise) fn_->addFnAttr("denormal-fp-math", "ieee,ieee");
    auto arg = fn_->arg_begin();
    Value *begin = arg++, *end = arg++;
    inputs_ = arg++;
    outputs_ = arg++;
    uniforms_ = arg++;
    tables_ = arg++;
    dims_ = arg++;
    status_ = arg++;

    BasicBlock* entry = BasicBlock::Create(ctx_, "entry", fn_);
    BasicBlock* head = BasicBlock::Create(ctx_, "element.head", fn_);
    BasicBlock* body = BasicBlock::Create(ctx_, "element.body", fn_);
    BasicBlock* exit = BasicBlock::Create(ctx_, "exit", fn_);
    b_.SetInsertPoint(entry);
    element_ = b_.CreateAlloca(i64, nullptr, "element");
    b_.CreateStore(begin, element_);
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
    allocate_registers();
    b_.CreateBr(head);

    b_.SetInsertPoint(head);
    Value* e = b_.CreateLoad(i64, element_);
    b_.CreateCondBr(b_.CreateICmpSLT(e, end), body, exit);

    b_.SetInsertPoint(body);
    start_element(e);
    block(p_.body);
    finish_element(e);
    b_.CreateStore(b_.CreateAdd(e, b_.getInt64(1)), element_);
    b_.CreateBr(head);

    b_.SetInsertPoint(exit);
    b_.CreateRetVoid();
  }

  // Constants and uniforms are SSA values; every other variable is one
  // stack slot per component (mem2reg makes them SSA again).
  void allocate_registers() {
    slots_.resize(p_.vars.size());
    ssa_.assign(p_.vars.size(), false);
    for (std::size_t u = 0; u < p_.uniforms.size(); ++u) {
      ir::VarId v = p_.uniforms[u];
      ssa_[v] = true;
      for (int c = 0; c < p_.type_of(v).width; ++c) {
        Value* ptr = b_.CreateConstInBoundsGEP1_64(b_.getDoubleTy(), uniforms_, 4 * u + c);
        slots_[v][c] = convert_double(b_.CreateLoad(b_.getDoubleTy(), ptr), p_.type_of(v).scalar);
      }
    }
    for (std::size_t v = 0; v < p_.vars.size(); ++v) {
      const ir::Var& var = p_.vars[v];
      if (var.kind == ir::VarKind::Uniform) continue;
      if (var.kind == ir::VarKind::Const) {
        ssa_[v] = true;
        for (int c = 0; c < var.type.width; ++c) slots_[v][c] = constant(var.type.scalar, var.value[c]);
        continue;
      }
      for (int c = 0; c < var.type.width; ++c) slots_[v][c] = b_.CreateAlloca(reg_type(var.type.scalar));
    }
  }

  Value* convert_double(Value* d, ir::Scalar s) {
    llvm::Type* t = reg_type(s);
    if (t->isDoubleTy()) return d;
    if (t->isFloatTy()) return b_.CreateFPTrunc(d, t);
    return b_.CreateFPToSI(d, t);
  }

  Value* constant(ir::Scalar s, double v) {
    llvm::Type* t = reg_type(s);
    if (t->isIntegerTy()) return b_.getInt32(static_cast<std::uint32_t>(static_cast<std::int32_t>(v)));
    return llvm::ConstantFP::get(t, v);
  }

  // Every register starts an element at zero; inputs are loaded.
  void start_element(Value* e) {
    for (std::size_t v = 0; v < p_.vars.size(); ++v)
      if (!ssa_[v])
        for (int c = 0; c < p_.vars[v].type.width; ++c)
          b_.CreateStore(llvm::Constant::getNullValue(reg_type(static_cast<ir::VarId>(v))), slots_[v][c]);
    for (std::size_t i = 0; i < p_.inputs.size(); ++i) {
      ir::VarId v = p_.inputs[i];
      Value* base = input_base_[i];
      for (int c = 0; c < p_.type_of(v).width; ++c) {
        Value* x = b_.CreateLoad(storage_type(p_.type_of(v).scalar), component_ptr(base, v, e, c));
        b_.CreateStore(from_storage(x, p_.type_of(v).scalar), slots_[v][c]);
      }
    }
  }

  void finish_element(Value* e) {
    for (std::size_t o = 0; o < p_.outputs.size(); ++o) {
      ir::VarId v = p_.outputs[o];
      Value* base = output_base_[o];
      for (int c = 0; c < p_.type_of(v).width; ++c) {
        Value* x = b_.CreateLoad(reg_type(v), slots_[v][c]);
        b_.CreateStore(to_storage(x, p_.type_of(v).scalar), component_ptr(base, v, e, c));
      }
    }
  }

  Value* pointer_at(Value* array, std::size_t k) {
    return b_.CreateLoad(b_.getPtrTy(), b_.CreateConstInBoundsGEP1_64(b_.getPtrTy(), array, k));
  }
  Value* component_ptr(Value* base, ir::VarId v, Value* e, int c) {
    ir::Type t = p_.type_of(v);
    Value* index = b_.CreateAdd(b_.CreateMul(e, b_.getInt64(t.width)), b_.getInt64(c));
    return b_.CreateInBoundsGEP(storage_type(t.scalar), base, index);
  }
  Value* from_storage(Value* x, ir::Scalar s) {
    return x->getType() == reg_type(s) ? x : b_.CreateFPExt(x, reg_type(s));
  }
  Value* to_storage(Value* x, ir::Scalar s) {
    return x->getType() == storage_type(s) ? x : b_.CreateFPTrunc(x, storage_type(s));
  }

  // ---- statements -------------------------------------------------------------

  void block(const ir::Block& body) {
    for (const ir::Stmt& s : body) {
      if (b_.GetInsertBlock()->getTerminator()) return;  // after a break/continue
      if (auto* a = std::get_if<ir::Assign>(&s.node)) assign(*a);
      else if (auto* i = std::get_if<ir::If>(&s.node)) branch(*i);
      else if (auto* l = std::get_if<ir::Loop>(&s.node)) loop(*l, s);
      else if (std::holds_alternative<ir::Break>(s.node)) b_.CreateBr(targets_.back().exit);
      else b_.CreateBr(targets_.back().next);
    }
  }

  void branch(const ir::If& s) {
    BasicBlock* then_bb = BasicBlock::Create(ctx_, "then", fn_);
    BasicBlock* else_bb = BasicBlock::Create(ctx_, "else", fn_);
    BasicBlock* join = BasicBlock::Create(ctx_, "endif", fn_);
    b_.CreateCondBr(truthy(read(s.cond, 0), p_.type_of(s.cond.var).scalar), then_bb, else_bb);
    for (auto [bb, body] : {std::pair{then_bb, &s.then_body}, std::pair{else_bb, &s.else_body}}) {
      b_.SetInsertPoint(bb);
      block(*body);
      if (!b_.GetInsertBlock()->getTerminator()) b_.CreateBr(join);
    }
    b_.SetInsertPoint(join);
  }

  // header -> test -> body -> update -> (header | test) ...; the iteration
  // counter turns a runaway loop into a status report.
  void loop(const ir::Loop& l, const ir::Stmt& s) {
    std::int64_t number = static_cast<std::int64_t>(loops_.size());
    loops_.push_back(&s);
    auto* i64 = b_.getInt64Ty();
    llvm::IRBuilder<> entry(&fn_->getEntryBlock(), fn_->getEntryBlock().begin());
    Value* count = entry.CreateAlloca(i64, nullptr, "iterations");
    b_.CreateStore(b_.getInt64(0), count);

    BasicBlock* top = BasicBlock::Create(ctx_, "loop.top", fn_);
    BasicBlock* test = BasicBlock::Create(ctx_, "loop.test", fn_);
    BasicBlock* body = BasicBlock::Create(ctx_, "loop.body", fn_);
    BasicBlock* update = BasicBlock::Create(ctx_, "loop.update", fn_);
    BasicBlock* exit = BasicBlock::Create(ctx_, "loop.exit", fn_);
    BasicBlock* runaway = BasicBlock::Create(ctx_, "loop.runaway", fn_);
    b_.CreateBr(top);

    b_.SetInsertPoint(top);
    Value* n = b_.CreateLoad(i64, count);
    b_.CreateStore(b_.CreateAdd(n, b_.getInt64(1)), count);
    b_.CreateCondBr(b_.CreateICmpUGE(n, b_.getInt64(o_.max_loop_iterations)), runaway, l.test_at_top ? test : body);

    b_.SetInsertPoint(runaway);
    report_runaway(number);

    b_.SetInsertPoint(test);
    block(l.header);
    b_.CreateCondBr(truthy(read(l.cond, 0), p_.type_of(l.cond.var).scalar), l.test_at_top ? body : top, exit);

    b_.SetInsertPoint(body);
    targets_.push_back({exit, update});
    block(l.body);
    targets_.pop_back();
    if (!b_.GetInsertBlock()->getTerminator()) b_.CreateBr(update);

    b_.SetInsertPoint(update);
    block(l.update);
    b_.CreateBr(l.test_at_top ? top : test);

    b_.SetInsertPoint(exit);
  }

  void report_runaway(std::int64_t number) {
    auto* i64 = b_.getInt64Ty();
    auto* first = b_.CreateStore(b_.getInt64(number + 1), status_);
    first->setAtomic(llvm::AtomicOrdering::Monotonic);
    first->setAlignment(llvm::Align(8));
    auto* second = b_.CreateStore(b_.CreateLoad(i64, element_), b_.CreateConstInBoundsGEP1_64(i64, status_, 1));
    second->setAtomic(llvm::AtomicOrdering::Monotonic);
    second->setAlignment(llvm::Align(8));
    b_.CreateRetVoid();
  }

  // ---- assignments ------------------------------------------------------------

  Value* read(const ir::Operand& o, int i) {
    int c = o.swizzle[o.width() == 1 ? 0 : i];
    if (ssa_[o.var]) return slots_[o.var][c];
    return b_.CreateLoad(reg_type(o.var), slots_[o.var][c]);
  }

  void assign(const ir::Assign& a) {
    std::array<Value*, 4> result{};
    if (ir::is_table_read(a.op)) {
      table_read(a, result);
    } else {
      ir::Scalar from = p_.type_of(a.args[0].var).scalar, to = p_.type_of(a.dest).scalar;
      for (int i = 0; i < a.mask.size; ++i) {
        Value* x[3] = {nullptr, nullptr, nullptr};
        for (std::size_t k = 0; k < a.args.size(); ++k) x[k] = read(a.args[k], i);
        result[i] = operation(a.op, from, to, x[0], x[1], x[2]);
      }
    }
    for (int i = 0; i < a.mask.size; ++i) b_.CreateStore(result[i], slots_[a.dest][a.mask[i]]);
  }

  Value* truthy(Value* x, ir::Scalar s) {
    if (ir::is_float(s)) return b_.CreateFCmpOGT(x, llvm::ConstantFP::get(x->getType(), 0.0));
    return b_.CreateICmpSGT(x, b_.getInt32(0));
  }

  Value* mask(Value* bit, llvm::Type* t) {
    return t->isIntegerTy() ? b_.CreateZExt(bit, t) : b_.CreateUIToFP(bit, t);
  }

  Value* intrinsic(llvm::Intrinsic::ID id, std::initializer_list<Value*> args) {
    llvm::Function* f = llvm::Intrinsic::getDeclaration(module_.get(), id, {(*args.begin())->getType()});
    return b_.CreateCall(f, args);
  }

  // A C math library function, in the precision of x.
  Value* libm(const char* name, std::initializer_list<Value*> args) {
    llvm::Type* t = (*args.begin())->getType();
    std::string symbol = t->isFloatTy() ? std::string(name) + "f" : name;
    std::vector<llvm::Type*> params(args.size(), t);
    llvm::FunctionCallee f = module_->getOrInsertFunction(symbol, llvm::FunctionType::get(t, params, false));
    return b_.CreateCall(f, args);
  }

  Value* operation(ir::Op op, ir::Scalar from, ir::Scalar to, Value* a, Value* b, Value* c) {
    using ir::Op;
    llvm::Type* t = a->getType();
    switch (op) {
      case Op::Mov: return a;
      case Op::Cast: return cast(a, from, to);
      case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne:
        return mask(compare(op, a, b, ir::is_float(from)), t);
      case Op::And: return mask(b_.CreateAnd(truthy(a, from), truthy(b, from)), t);
      case Op::Or: return mask(b_.CreateOr(truthy(a, from), truthy(b, from)), t);
      case Op::Not: return mask(b_.CreateNot(truthy(a, from)), t);
      case Op::Cond: return b_.CreateSelect(truthy(a, from), b, c);
      default: break;
    }
    return ir::is_float(from) ? float_op(op, a, b) : int_op(op, a, b);
  }

  Value* compare(ir::Op op, Value* a, Value* b, bool is_float) {
    using P = llvm::CmpInst::Predicate;
    static const std::pair<P, P> kPredicates[] = {
        {P::FCMP_OLT, P::ICMP_SLT}, {P::FCMP_OLE, P::ICMP_SLE}, {P::FCMP_OGT, P::ICMP_SGT},
        {P::FCMP_OGE, P::ICMP_SGE}, {P::FCMP_OEQ, P::ICMP_EQ},  {P::FCMP_UNE, P::ICMP_NE}};
    auto [fp, ip] = kPredicates[static_cast<int>(op) - static_cast<int>(ir::Op::Lt)];
    return is_float ? b_.CreateFCmp(fp, a, b) : b_.CreateICmp(ip, a, b);
  }

  Value* cast(Value* a, ir::Scalar from, ir::Scalar to) {
    llvm::Type* t = reg_type(to);
    if (to == ir::Scalar::Bool) return mask(truthy(a, from), t);
    if (to == ir::Scalar::I32) {
      if (!ir::is_float(from)) return a;
      // NaN gives 0 and out-of-range values saturate, by definition.
      llvm::Function* f = llvm::Intrinsic::getDeclaration(module_.get(), llvm::Intrinsic::fptosi_sat, {t, a->getType()});
      return b_.CreateCall(f, {a});
    }
    if (!ir::is_float(from)) return b_.CreateSIToFP(a, t);
    if (a->getType() == t) return a;
    return t->isDoubleTy() ? b_.CreateFPExt(a, t) : b_.CreateFPTrunc(a, t);
  }

  Value* float_op(ir::Op op, Value* a, Value* b) {
    using ir::Op;
    namespace I = llvm::Intrinsic;
    llvm::Type* t = a->getType();
    Value* one = llvm::ConstantFP::get(t, 1.0);
    switch (op) {
      case Op::Add: return b_.CreateFAdd(a, b);
      case Op::Sub: return b_.CreateFSub(a, b);
      case Op::Mul: return b_.CreateFMul(a, b);
      case Op::Div: return b_.CreateFDiv(a, b);
      case Op::Mod: return b_.CreateFRem(a, b);
      case Op::Neg: return b_.CreateFNeg(a);
      case Op::Min: return intrinsic(I::minnum, {a, b});
      case Op::Max: return intrinsic(I::maxnum, {a, b});
      case Op::Abs: return intrinsic(I::fabs, {a});
      case Op::Sign: {
        Value* zero = llvm::ConstantFP::get(t, 0.0);
        Value* neg = b_.CreateSelect(b_.CreateFCmpOLT(a, zero), llvm::ConstantFP::get(t, -1.0), a);
        return b_.CreateSelect(b_.CreateFCmpOGT(a, zero), one, neg);
      }
      case Op::Floor: return intrinsic(I::floor, {a});
      case Op::Ceil: return intrinsic(I::ceil, {a});
      case Op::Round: return intrinsic(I::round, {a});
      case Op::Sqrt: return intrinsic(I::sqrt, {a});
      case Op::Rsqrt: return b_.CreateFDiv(one, intrinsic(I::sqrt, {a}));
      case Op::Rcp: return b_.CreateFDiv(one, a);
      case Op::Pow: return intrinsic(I::pow, {a, b});
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
      default: return llvm::UndefValue::get(t);
    }
  }

  Value* int_op(ir::Op op, Value* a, Value* b) {
    using ir::Op;
    namespace I = llvm::Intrinsic;
    Value* zero = b_.getInt32(0);
    switch (op) {
      case Op::Add: return b_.CreateAdd(a, b);
      case Op::Sub: return b_.CreateSub(a, b);
      case Op::Mul: return b_.CreateMul(a, b);
      case Op::Div: case Op::Mod: {
        // x / 0 and x % 0 give 0; INT_MIN / -1 wraps to INT_MIN (divide by 1).
        Value* by_zero = b_.CreateICmpEQ(b, zero);
        Value* overflow = b_.CreateAnd(b_.CreateICmpEQ(a, b_.getInt32(0x80000000u)), b_.CreateICmpEQ(b, b_.getInt32(-1)));
        Value* safe = b_.CreateSelect(b_.CreateOr(by_zero, overflow), b_.getInt32(1), b);
        Value* r = op == Op::Div ? b_.CreateSDiv(a, safe) : b_.CreateSRem(a, safe);
        if (op == Op::Mod) r = b_.CreateSelect(overflow, zero, r);
        return b_.CreateSelect(by_zero, zero, r);
      }
      case Op::Neg: return b_.CreateNeg(a);
      case Op::Abs: {
        llvm::Function* f = llvm::Intrinsic::getDeclaration(module_.get(), I::abs, {a->getType()});
        return b_.CreateCall(f, {a, b_.getFalse()});
      }
      case Op::Sign: {
        Value* neg = b_.CreateSelect(b_.CreateICmpSLT(a, zero), b_.getInt32(-1), zero);
        return b_.CreateSelect(b_.CreateICmpSGT(a, zero), b_.getInt32(1), neg);
      }
      case Op::Min: return intrinsic(I::smin, {a, b});
      case Op::Max: return intrinsic(I::smax, {a, b});
      case Op::Floor: case Op::Ceil: case Op::Round: return a;
      default: return llvm::UndefValue::get(a->getType());
    }
  }

  // ---- tables -------------------------------------------------------------------

  // Clamps exactly as sh::fetch_index / sample_index do.
  void table_read(const ir::Assign& a, std::array<Value*, 4>& result) {
    const ir::TableDecl& t = p_.tables[a.table];
    const ir::Operand& coord = a.args[0];
    ir::Scalar coord_scalar = p_.type_of(coord.var).scalar;
    auto* i64 = b_.getInt64Ty();
    Value* flat = b_.getInt64(0);
    Value* stride = b_.getInt64(1);
    for (int d = 0; d < t.rank; ++d) {
      Value* dim = table_dims_[a.table][d];
      Value* i = read(coord, d);
      if (a.op == ir::Op::Sample) {
        Value* scaled = b_.CreateFMul(i, b_.CreateSIToFP(dim, i->getType()));
        i = cast(intrinsic(llvm::Intrinsic::floor, {scaled}), coord_scalar, ir::Scalar::I32);
      }
      Value* clamped = intrinsic(llvm::Intrinsic::smin, {intrinsic(llvm::Intrinsic::smax, {i, b_.getInt32(0)}),
                                                         b_.CreateSub(dim, b_.getInt32(1))});
      flat = b_.CreateAdd(flat, b_.CreateMul(b_.CreateZExt(clamped, i64), stride));
      stride = b_.CreateMul(stride, b_.CreateZExt(dim, i64));
    }
    Value* base = table_base_[a.table];
    llvm::Type* st = storage_type(t.element.scalar);
    for (int c = 0; c < t.element.width; ++c) {
      Value* index = b_.CreateAdd(b_.CreateMul(flat, b_.getInt64(t.element.width)), b_.getInt64(c));
      result[c] = from_storage(b_.CreateLoad(st, b_.CreateInBoundsGEP(st, base, index)), t.element.scalar);
    }
  }

  struct Targets {
    BasicBlock* exit;  // break
    BasicBlock* next;  // continue
  };

  const ir::Program& p_;
  const Options& o_;
  llvm::LLVMContext& ctx_;
  std::unique_ptr<llvm::Module> module_;
  llvm::IRBuilder<> b_;
  llvm::Function* fn_ = nullptr;
  Value *inputs_ = nullptr, *outputs_ = nullptr, *uniforms_ = nullptr, *tables_ = nullptr, *dims_ = nullptr,
        *status_ = nullptr, *element_ = nullptr;
  std::vector<Value*> input_base_, output_base_, table_base_;
  std::vector<std::array<Value*, 3>> table_dims_;
  std::vector<std::array<Value*, 4>> slots_;
  std::vector<bool> ssa_;
  std::vector<Targets> targets_;
  std::vector<const ir::Stmt*> loops_;
};

}  // namespace

Lowered lower(const ir::Program& program, const Options& options, llvm::LLVMContext& context) {
  return Lowering(program, options, context).run();
}

}  // namespace sh::cpu
