#include "truth_values.hpp"

#include <vector>

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/InstIterator.h>
#include <llvm/IR/IntrinsicInst.h>
#include <llvm/IR/PatternMatch.h>
#include <llvm/Transforms/Utils/Local.h>

namespace sh::cpu {
namespace {

using namespace llvm::PatternMatch;

// How deep a chain of minima and maxima is followed: a program's && of
// many tests is a chain as long as its tests.
constexpr int kDeepest = 64;

// c where select(c, t, f) of constants is c's truth value (t > 0, f not),
// and its negation, always, never; a value that is none of these: false.
enum class Truth { Condition, Negated, Always, Never };

bool select_truth(llvm::Value* v, llvm::Value*& condition, Truth& truth) {
  const llvm::APFloat *t = nullptr, *f = nullptr;
  if (!match(v, m_Select(m_Value(condition), m_APFloat(t), m_APFloat(f))) || t->isNaN() || f->isNaN()) return false;
  bool when_true = t->isNonZero() && !t->isNegative(), when_false = f->isNonZero() && !f->isNegative();
  truth = when_true == when_false ? (when_true ? Truth::Always : Truth::Never)
                                  : (when_true ? Truth::Condition : Truth::Negated);
  return true;
}

// Whether `v > 0` can be written from conditions: v a select of constants
// that are not NaN, or the minimum or maximum of two such values (neither
// NaN, so the minimum is positive exactly where both are).
bool has_truth(llvm::Value* v, int depth) {
  llvm::Value* condition = nullptr;
  Truth truth{};
  if (select_truth(v, condition, truth)) return true;
  auto* call = llvm::dyn_cast<llvm::IntrinsicInst>(v);
  if (!call || depth == kDeepest) return false;
  llvm::Intrinsic::ID id = call->getIntrinsicID();
  if (id != llvm::Intrinsic::minnum && id != llvm::Intrinsic::maxnum) return false;
  return has_truth(call->getArgOperand(0), depth + 1) && has_truth(call->getArgOperand(1), depth + 1);
}

// `v > 0` from the conditions has_truth found, built where b is.
llvm::Value* truth_of(llvm::Value* v, llvm::IRBuilder<>& b) {
  llvm::Value* condition = nullptr;
  Truth truth{};
  if (select_truth(v, condition, truth)) {
    switch (truth) {
      case Truth::Condition: return condition;
      case Truth::Negated: return b.CreateNot(condition);
      case Truth::Always: return llvm::ConstantInt::getTrue(condition->getType());
      case Truth::Never: return llvm::ConstantInt::getFalse(condition->getType());
    }
  }
  auto* call = llvm::cast<llvm::IntrinsicInst>(v);
  llvm::Value* a = truth_of(call->getArgOperand(0), b);
  llvm::Value* c = truth_of(call->getArgOperand(1), b);
  return call->getIntrinsicID() == llvm::Intrinsic::minnum ? b.CreateAnd(a, c) : b.CreateOr(a, c);
}

}  // namespace

llvm::PreservedAnalyses TruthValuesPass::run(llvm::Function& f, llvm::FunctionAnalysisManager&) {
  std::vector<llvm::Instruction*> tests;
  for (llvm::Instruction& i : llvm::instructions(f)) {
    llvm::Value* x = nullptr;
    llvm::FCmpInst::Predicate predicate{};
    if (match(&i, m_FCmp(predicate, m_Value(x), m_AnyZeroFP())) && predicate == llvm::FCmpInst::FCMP_OGT &&
        has_truth(x, 0))
      tests.push_back(&i);
  }
  for (llvm::Instruction* test : tests) {
    llvm::IRBuilder<> b(test);
    test->replaceAllUsesWith(truth_of(test->getOperand(0), b));
    llvm::RecursivelyDeleteTriviallyDeadInstructions(test);
  }
  return tests.empty() ? llvm::PreservedAnalyses::all() : llvm::PreservedAnalyses::none();
}

}  // namespace sh::cpu
