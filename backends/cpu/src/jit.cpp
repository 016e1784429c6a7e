#include "jit.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <mutex>

#include <llvm/Analysis/CGSCCPassManager.h>
#include <llvm/Analysis/LoopAnalysisManager.h>
#include <llvm/Analysis/TargetLibraryInfo.h>
#include <llvm/Analysis/ValueTracking.h>
#include <llvm/Bitcode/BitcodeReader.h>
#include <llvm/Config/llvm-config.h>
#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/ExecutionEngine/JITEventListener.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/RTDyldObjectLinkingLayer.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/ExecutionEngine/SectionMemoryManager.h>
#include <llvm/IR/InstIterator.h>
#include <llvm/IR/IntrinsicInst.h>
#include <llvm/IR/PassManager.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>
#include <llvm/Transforms/InstCombine/InstCombine.h>
#include <llvm/Transforms/Scalar/EarlyCSE.h>
#include <llvm/Transforms/Scalar/SROA.h>
#include <llvm/Transforms/Scalar/SimplifyCFG.h>
#include <llvm/Transforms/Utils/Mem2Reg.h>

#include <tbb/task_arena.h>

#include "codegen.hpp"
#include "truth_values.hpp"
#include "sh/analysis.hpp"
#include "sh/detail/disk_cache.hpp"
#include "sh/error.hpp"
#include "sh/ir/serialize.hpp"

namespace sh::cpu {
namespace {

void initialise_llvm() {
  static std::once_flag once;
  std::call_once(once, [] {
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
  });
}

template <class T>
T unwrap(llvm::Expected<T> value, const ir::Program& p, const char* stage) {
  if (!value) throw Error("program '" + p.name + "': cpu backend: " + stage + ": " + llvm::toString(value.takeError()));
  return std::move(*value);
}

void check(llvm::Error err, const ir::Program& p, const char* stage) {
  if (err) throw Error("program '" + p.name + "': cpu backend: " + stage + ": " + llvm::toString(std::move(err)));
}

// What the optimiser may assume of the C library.  LLVM 15 rewrites
// exp2(int-to-float x) as ldexp(1, x), and for vectors it writes invalid IR
// (a vector compare zero-extended to a scalar, a call of ldexpl on vectors)
// that instruction selection aborts on: so ldexp is not offered.
llvm::TargetLibraryInfoImpl library_info(const llvm::Module& m) {
  llvm::TargetLibraryInfoImpl info(llvm::Triple(m.getTargetTriple()));
  info.setUnavailable(llvm::LibFunc_ldexp);
  info.setUnavailable(llvm::LibFunc_ldexpf);
  info.setUnavailable(llvm::LibFunc_ldexpl);
  return info;
}

// A kernel with loops of its own lowered to more instructions than this
// (the tracer, 6 600 without reflections to 11 500 with a light pass's
// luminance; the light pass, 12 000-13 500; every other kernel with loops
// measured is under 4 500, the intersector the largest) takes a short
// pipeline: registers to SSA
// values, the common subexpressions before and after the instruction
// combiner, the CFG simplified before and after.  Its loops run until rays
// finish, with little for O3's loop passes to hoist or unroll, while O3
// spent about 60 % of its compile on them: renders ran at the same speed,
// with the same images, and compiled in 35-45 % less time (with GVN where
// the second early CSE is now).
// Its machine code leaves out the passes MachinePasses::Lean names.
// Small kernels keep O3 and every machine pass, which their loops pay for
// (ray-triangle's 9 % at 16 lanes) and whose compile is short anyway; so
// do kernels without loops of their own, however large (a 5 x 5 blur's
// body lowered three times, 6 200-6 800), whose only loops are the
// backend's along the stream and its rows: O3 hoists what a row's batches
// share out of them, which the short pipeline left in the direct blur's
// inside loop.
constexpr unsigned kLargeKernel = 5000;

// An optimised kernel of more LLVM instructions than this (the tracer:
// 1 600 scalar, 2 500 at 16 lanes, 3 100 with fetched tables) is compiled
// in parts on the threads there are (codegen.hpp); the others (the
// intersector: 500-700) are not worth outlining.
constexpr unsigned kSplitKernel = 1200;

llvm::FunctionPassManager short_pipeline() {
  llvm::FunctionPassManager fpm;
  // The lowering's stack slots are plain values: mem2reg promotes them in
  // a third of SROA's time (7 against 20 ms on the tracer), leaving SROA
  // nothing to do but what it alone can.
  fpm.addPass(llvm::PromotePass());
  fpm.addPass(llvm::SROAPass());
  fpm.addPass(llvm::EarlyCSEPass(true));
  fpm.addPass(llvm::SimplifyCFGPass());
  fpm.addPass(llvm::InstCombinePass());
  fpm.addPass(TruthValuesPass());
  // Not GVN: on every tracer measured (each scene and accelerator, scalar
  // to 16 lanes) early CSE here gave the same module as GVN did (the lazy
  // octree's 3 instructions smaller) in about a third of the time.
  fpm.addPass(llvm::EarlyCSEPass());
  fpm.addPass(llvm::SimplifyCFGPass());
  fpm.addPass(TruthValuesPass());  // of the selects SimplifyCFG made of branches
  return fpm;
}

void optimise(llvm::Module& m, llvm::TargetMachine& tm, bool large) {
  llvm::LoopAnalysisManager lam;
  llvm::FunctionAnalysisManager fam;
  llvm::CGSCCAnalysisManager cgam;
  llvm::ModuleAnalysisManager mam;
  llvm::PassBuilder pb(&tm);
  fam.registerPass([&] { return llvm::TargetLibraryAnalysis(library_info(m)); });
  pb.registerModuleAnalyses(mam);
  pb.registerCGSCCAnalyses(cgam);
  pb.registerFunctionAnalyses(fam);
  pb.registerLoopAnalyses(lam);
  pb.crossRegisterProxies(lam, fam, cgam, mam);
  // After each run of the combiner, and last: the pipeline's last
  // SimplifyCFG makes selects of branches that set a truth value.
  pb.registerPeepholeEPCallback(
      [](llvm::FunctionPassManager& fpm, llvm::OptimizationLevel) { fpm.addPass(TruthValuesPass()); });
  pb.registerOptimizerLastEPCallback([](llvm::ModulePassManager& mpm, llvm::OptimizationLevel) {
    mpm.addPass(llvm::createModuleToFunctionPassAdaptor(TruthValuesPass()));
  });
  if (large)
    llvm::createModuleToFunctionPassAdaptor(short_pipeline()).run(m, mam);
  else
    pb.buildPerModuleDefaultPipeline(llvm::OptimizationLevel::O3).run(m, mam);
}

// minnum and maxnum give the operand that is not NaN, which x86's min and
// max instructions do not, so code generation adds a NaN test and a blend
// unless the call says no operand is NaN.  After optimisation the operands
// are plain values: where neither can be NaN (the 1s and 0s of
// comparisons, whose min and max are Sh's && and ||), the call says so and
// becomes one instruction.
void mark_min_max_without_nan(llvm::Module& m) {
  for (llvm::Function& f : m)
    for (llvm::Instruction& i : llvm::instructions(f)) {
      auto* call = llvm::dyn_cast<llvm::IntrinsicInst>(&i);
      if (!call || (call->getIntrinsicID() != llvm::Intrinsic::minnum && call->getIntrinsicID() != llvm::Intrinsic::maxnum))
        continue;
      if (llvm::isKnownNeverNaN(call->getArgOperand(0), nullptr) && llvm::isKnownNeverNaN(call->getArgOperand(1), nullptr))
        call->setHasNoNaNs(true);
    }
}

// The text of a module kept as bitcode: printing the tracer's took 6-11 ms
// of every compile, for a listing seldom asked for.
std::string module_text(const std::string& bitcode) {
  llvm::LLVMContext context;
  auto m = llvm::parseBitcodeFile(llvm::MemoryBufferRef(bitcode, "kernel"), context);
  if (!m) return "; the kernel's LLVM IR could not be read back: " + llvm::toString(m.takeError()) + "\n";
  std::string text;
  llvm::raw_string_ostream os(text);
  (*m)->print(os, nullptr);
  return text;
}

}  // namespace

Jitted::Jitted(const ir::Program& program, const sh::Options& options) {
  initialise_llvm();
  try {
    build(program, options, true);
  } catch (const Error&) {
    if (!from_cache()) throw;
    // A cached object that does not load (truncated, another LLVM): forget
    // it and compile afresh, keeping what is compiled in its place.
    cache_->forget();
    jit_.reset();
    build(program, options, false);
  }
}

const std::string& Jitted::llvm_ir() const {
  std::call_once(listing_read_, [this] {
    if (from_cache())
      llvm_ir_ = "; machine code loaded from the object cache\n" + module_text(cache_->module().value_or(""));
    else
      llvm_ir_ = module_text(compiled_module_);
  });
  return llvm_ir_;
}

// Times the phases of a build one after another.
class PhaseClock {
 public:
  explicit PhaseClock(std::vector<CompilePhase>& phases) : phases_(phases) { phases_.clear(); }
  void end(const char* phase) {
    auto now = std::chrono::steady_clock::now();
    phases_.push_back({phase, std::chrono::duration<double, std::milli>(now - start_).count()});
    start_ = now;
  }

 private:
  std::vector<CompilePhase>& phases_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// The cache key: the program as this backend gets it (structure only:
// names change no machine code), everything the machine code depends on
// besides, and the builds of this library, whose lowering made it, and of
// the language's, whose analyses (which values are uniform, which reads
// run along a row) steered the lowering.
std::string cache_key(const ir::Program& program, const sh::Options& options, int lanes,
                      const llvm::orc::JITTargetMachineBuilder& builder) {
  static const std::string library = detail::build_id(reinterpret_cast<const void*>(&lane_count)) + "+" +
                                     detail::build_id(reinterpret_cast<const void*>(&analysis::analyse_spmd));
  return ir::serialize(program, {.names = false}) + "|" + options.key() + "|" + std::to_string(lanes) + "|" +
         builder.getCPU() + "|" + builder.getFeatures().getString() + "|" + LLVM_VERSION_STRING + "|" + library;
}

void Jitted::build(const ir::Program& program, const sh::Options& options, bool read_cache) {
  PhaseClock clock(phases_);
  lanes_ = lane_count(options);
  auto builder = unwrap(llvm::orc::JITTargetMachineBuilder::detectHost(), program, "detecting the host CPU");
  if (std::string level = isa_cpu(options); !level.empty()) {
    builder.setCPU(level);
    builder.getFeatures() = llvm::SubtargetFeatures();
  }
  builder.setCodeGenOptLevel(llvm::CodeGenOpt::Aggressive);
  // f32 precise: no contraction into FMA, so a*b+c rounds twice as written.
  builder.getOptions().AllowFPOpFusion =
      options.math == MathMode::Fast ? llvm::FPOpFusion::Fast : llvm::FPOpFusion::Strict;
  // A library without a build ID cannot tell its machine code from an
  // older build's: it keeps none.
  bool keyed = !detail::build_id(reinterpret_cast<const void*>(&lane_count)).empty();
  cache_ = keyed ? ObjectCache::open(cache_key(program, options, lanes_, builder)) : std::nullopt;
  clock.end("cache key");
  if (read_cache && cache_ && cache_->has_object()) {
    // Machine code from an earlier compile: no lowering, no LLVM.
    loops_ = loop_statements(program);
    start_jit(program, builder);
    clock.end("JIT setup");
    std::vector<std::unique_ptr<llvm::MemoryBuffer>> objects = cache_->objects();
    if (objects.empty()) throw Error("program '" + program.name + "': cpu backend: the cached objects could not be read");
    for (auto& object : objects) check(jit_->addObjectFile(std::move(object)), program, "adding a cached object");
    link(program);
    clock.end("object from the cache, linked");
    return;
  }

  auto context = std::make_unique<llvm::LLVMContext>();
  Lowered lowered = lower(program, options, lanes_, *context);
  loops_ = std::move(lowered.loops);
  llvm::Module& m = *lowered.module;
  std::string problems;
  llvm::raw_string_ostream os(problems);
  if (llvm::verifyModule(m, &os))
    throw Error("program '" + program.name + "': cpu backend produced invalid LLVM IR: " + os.str());
  auto machine = unwrap(builder.createTargetMachine(), program, "creating the target machine");
  m.setDataLayout(machine->createDataLayout());
  m.setTargetTriple(machine->getTargetTriple().str());
  clock.end("lowering");

  bool large = !loops_.empty() && m.getInstructionCount() > kLargeKernel;
  optimise(m, *machine, large);
  mark_min_max_without_nan(m);
  // Invalid IR from the optimiser would abort the process in code
  // generation; an error names the program instead.
  if (llvm::verifyModule(m, &os))
    throw Error("program '" + program.name + "': cpu backend: LLVM's optimiser produced invalid IR: " + os.str());
  clock.end("LLVM optimisation");

  start_jit(program, builder);
  clock.end("JIT setup");
  int threads = tbb::this_task_arena::max_concurrency();
  if (options.threads > 0) threads = std::min(threads, options.threads);
  MachinePasses passes = large ? MachinePasses::Lean : MachinePasses::Full;
  Objects objects = compile_objects(m, builder, passes, kSplitKernel, static_cast<unsigned>(threads), program.name);
  cpu_ms_elsewhere_ = objects.cpu_ms_elsewhere;
  compiled_module_ = std::move(objects.module);
  clock.end("machine code");
  if (cache_) {
    cache_->store_module(compiled_module_);
    cache_->store(objects.parts);
    clock.end("stored");
  }
  for (const std::string& part : objects.parts)
    check(jit_->addObjectFile(llvm::MemoryBuffer::getMemBufferCopy(part, program.name)), program, "adding the object");
  link(program);
  clock.end("linked");
}

namespace {

// With SH_PERF_JITDUMP=1 the kernels' machine code is described to perf as
// it is linked (LLVM's jitdump files, under $JITDUMPDIR/.debug/jit, else
// ~/.debug/jit), so that `perf record -k 1`, `perf inject --jit` and `perf
// annotate` show a kernel's instructions with their samples.  The listener
// is one for the process, its file chosen when it is first asked for.
// Null where it is not asked for, or this LLVM was built without perf's
// listener.
llvm::JITEventListener* perf_listener() {
  const char* asked = std::getenv("SH_PERF_JITDUMP");
  if (!asked || std::string(asked) != "1") return nullptr;
  return llvm::JITEventListener::createPerfJITEventListener();
}

}  // namespace

// An LLJIT for the host that links the kernel's objects and resolves the C
// math library of this process.
void Jitted::start_jit(const ir::Program& program, const llvm::orc::JITTargetMachineBuilder& builder) {
  llvm::orc::LLJITBuilder jit;
  jit.setJITTargetMachineBuilder(builder);
  if (llvm::JITEventListener* perf = perf_listener())
    jit.setObjectLinkingLayerCreator([perf](llvm::orc::ExecutionSession& session, const llvm::Triple&) {
      auto layer = std::make_unique<llvm::orc::RTDyldObjectLinkingLayer>(
          session, [] { return std::make_unique<llvm::SectionMemoryManager>(); });
      layer->registerJITEventListener(*perf);
      return layer;
    });
  jit_ = unwrap(jit.create(), program, "creating the JIT");
  // Failures come back through lookup() as sh::Error; the session's own
  // report to stderr would only repeat them.
  jit_->getExecutionSession().setErrorReporter([](llvm::Error e) { llvm::consumeError(std::move(e)); });
  auto libm = unwrap(llvm::orc::DynamicLibrarySearchGenerator::GetForCurrentProcess(
                         jit_->getDataLayout().getGlobalPrefix()),
                     program, "opening the process symbols");
  jit_->getMainJITDylib().addGenerator(std::move(libm));
}

// Compiles (or links) what was added, and finds the kernel.
void Jitted::link(const ir::Program& program) {
  auto address = unwrap(jit_->lookup(kKernelSymbol), program, "compiling");
  entry_ = address.toPtr<KernelFn>();
}

Jitted::~Jitted() = default;

}  // namespace sh::cpu
