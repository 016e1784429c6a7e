#include "truth_values.hpp"

#include <unordered_map>
#include <vector>

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/InstIterator.h>
#include <llvm/IR/IntrinsicInst.h>
#include <llvm/IR/PatternMatch.h>
#include <llvm/IR/ValueHandle.h>
#include <llvm/Transforms/Utils/Local.h>

namespace sh::cpu {
namespace {

using namespace llvm::PatternMatch;

// How deep a chain of minima and maxima is followed: a program's && of
// many tests is a chain as long as its tests.
constexpr int kDeepest = 64;

// Whether a constant that is not NaN is true (greater than 0).
bool positive(const llvm::APFloat& c) { return c.isNonZero() && !c.isNegative(); }

// One test `x > 0` rewritten from conditions.  Values are visited once
// each: a program's && and || may share their operands, and the tree of
// minima and maxima they make is then a graph of many more paths than
// nodes.
class Rewrite {
 public:
  explicit Rewrite(llvm::Instruction* test) : test_(test), b_(test) {}

  // Whether x can be written from conditions: x a mask converted to 1s and
  // 0s, a constant that is not NaN, a select between two such values (its
  // condition one bit, or one a lane), or their minimum or maximum
  // (neither NaN, so the minimum is positive exactly where both are).
  bool possible(llvm::Value* x, int depth = 0) {
    auto [at, fresh] = possible_.try_emplace(x, false);
    if (!fresh) return at->second;
    const llvm::APFloat* constant = nullptr;
    llvm::Value *a = nullptr, *b = nullptr;
    bool can = false;
    if (mask(x) || (match(x, m_APFloat(constant)) && !constant->isNaN())) {
      can = true;
    } else if (depth < kDeepest && match(x, m_Select(m_Value(), m_Value(a), m_Value(b)))) {
      can = possible(a, depth + 1) && possible(b, depth + 1);
    } else if (auto* call = llvm::dyn_cast<llvm::IntrinsicInst>(x); call && depth < kDeepest) {
      llvm::Intrinsic::ID id = call->getIntrinsicID();
      can = (id == llvm::Intrinsic::minnum || id == llvm::Intrinsic::maxnum) &&
            possible(call->getArgOperand(0), depth + 1) && possible(call->getArgOperand(1), depth + 1);
    }
    return possible_[x] = can;  // not `at`: the calls above may have moved it
  }

  // `x > 0` from the conditions possible() found, built before the test.
  llvm::Value* truth(llvm::Value* x) {
    if (auto at = built_.find(x); at != built_.end()) return at->second;
    const llvm::APFloat* constant = nullptr;
    llvm::Value *condition = nullptr, *a = nullptr, *b = nullptr;
    llvm::Value* made = nullptr;
    if (llvm::Value* bits = mask(x)) {
      made = bits;
    } else if (match(x, m_APFloat(constant))) {
      made = positive(*constant) ? llvm::ConstantInt::getTrue(test_->getType())
                                 : llvm::ConstantInt::getFalse(test_->getType());
    } else if (match(x, m_Select(m_Value(condition), m_Value(a), m_Value(b)))) {
      made = choose(condition, truth(a), truth(b));
    } else {
      auto* call = llvm::cast<llvm::IntrinsicInst>(x);
      llvm::Value* first = truth(call->getArgOperand(0));
      llvm::Value* second = truth(call->getArgOperand(1));
      made = call->getIntrinsicID() == llvm::Intrinsic::minnum ? b_.CreateAnd(first, second)
                                                               : b_.CreateOr(first, second);
    }
    return built_[x] = made;
  }

 private:
  // The mask m where x is uitofp(m): 1s and 0s converted from bits, as the
  // lowering converts an integer truth value.
  static llvm::Value* mask(llvm::Value* x) {
    llvm::Value* bits = nullptr;
    return match(x, m_UIToFP(m_Value(bits))) && bits->getType()->isIntOrIntVectorTy(1) ? bits : nullptr;
  }

  // condition ? if_true : otherwise, of truths: where they are always and
  // never, the condition itself (or its negation), with as many lanes as
  // the test (one bit that chooses between vectors, as a uniform branch's
  // 1 or -1 does, is splat).
  llvm::Value* choose(llvm::Value* condition, llvm::Value* if_true, llvm::Value* otherwise) {
    if (if_true == otherwise) return if_true;
    auto* always = llvm::ConstantInt::getTrue(test_->getType());
    auto* never = llvm::ConstantInt::getFalse(test_->getType());
    bool plain = if_true == always && otherwise == never, negated = if_true == never && otherwise == always;
    if (!plain && !negated) return b_.CreateSelect(condition, if_true, otherwise);
    if (auto* vector = llvm::dyn_cast<llvm::VectorType>(test_->getType()); vector && !condition->getType()->isVectorTy())
      condition = b_.CreateVectorSplat(vector->getElementCount(), condition);
    return plain ? condition : b_.CreateNot(condition);
  }

  llvm::Instruction* test_;
  llvm::IRBuilder<> b_;
  std::unordered_map<llvm::Value*, bool> possible_;
  std::unordered_map<llvm::Value*, llvm::Value*> built_;
};

}  // namespace

llvm::PreservedAnalyses TruthValuesPass::run(llvm::Function& f, llvm::FunctionAnalysisManager&) {
  // Held by handles: deleting one test's dead operands may delete a test
  // found after it (a select's condition that nothing else uses).
  std::vector<llvm::WeakVH> tests;
  for (llvm::Instruction& i : llvm::instructions(f)) {
    llvm::FCmpInst::Predicate predicate{};
    if (match(&i, m_FCmp(predicate, m_Value(), m_AnyZeroFP())) && predicate == llvm::FCmpInst::FCMP_OGT)
      tests.emplace_back(&i);
  }
  bool changed = false;
  for (llvm::WeakVH& held : tests) {
    auto* test = llvm::dyn_cast_or_null<llvm::FCmpInst>(static_cast<llvm::Value*>(held));
    if (!test) continue;
    Rewrite rewrite(test);
    if (!rewrite.possible(test->getOperand(0))) continue;
    test->replaceAllUsesWith(rewrite.truth(test->getOperand(0)));
    llvm::RecursivelyDeleteTriviallyDeadInstructions(test);
    changed = true;
  }
  return changed ? llvm::PreservedAnalyses::none() : llvm::PreservedAnalyses::all();
}

}  // namespace sh::cpu
