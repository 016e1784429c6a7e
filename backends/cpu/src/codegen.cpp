#include "codegen.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <map>
#include <thread>

#include <llvm/Analysis/LoopInfo.h>
#include <llvm/Bitcode/BitcodeReader.h>
#include <llvm/Bitcode/BitcodeWriter.h>
#include <llvm/IR/Dominators.h>
#include <llvm/CodeGen/MachineModuleInfo.h>
#include <llvm/CodeGen/Passes.h>
#include <llvm/CodeGen/TargetPassConfig.h>
#include <llvm/IR/LegacyPassManager.h>
#include <llvm/Support/Error.h>
#include <llvm/Support/MemoryBuffer.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>
#include <llvm/Transforms/Utils/CodeExtractor.h>
#include <tbb/task_group.h>

#include "sh/detail/cpu_time.hpp"
#include "sh/error.hpp"

namespace sh::cpu {
namespace {

// The most parts a module is cut into: past a few, the loops left to
// outline are too small to balance the parts.
constexpr unsigned kMostParts = 4;

std::size_t instructions(const llvm::Loop& loop) {
  std::size_t n = 0;
  for (const llvm::BasicBlock* b : loop.blocks()) n += b->size();
  return n;
}

// The largest part when functions of `sizes` are dealt, largest first, to
// the part with the fewest instructions so far (as assign_parts deals
// them).
std::size_t largest_part(std::vector<std::size_t> sizes, unsigned parts) {
  std::sort(sizes.rbegin(), sizes.rend());
  std::vector<std::size_t> load(parts, 0);
  for (std::size_t n : sizes) *std::min_element(load.begin(), load.end()) += n;
  return *std::max_element(load.begin(), load.end());
}

// The most loops weighed against each other: their choices are 2^n.
constexpr std::size_t kCandidateLoops = 12;

// The headers of the loops to outline from `f` so that it and the loops
// make `parts` parts of about equal size: of its largest loops that fit in
// a part, the set, none inside another, whose largest part is smallest.
// The largest loops that fit are not enough: where one loop holds two
// others (the tracer's bounce loop, its two walks), they leave parts of
// 1 : 2.
std::vector<llvm::BasicBlock*> loops_to_outline(llvm::Function& f, unsigned parts) {
  llvm::DominatorTree dominators(f);
  llvm::LoopInfo info(dominators);
  llvm::SmallVector<llvm::Loop*, 4> loops = info.getLoopsInPreorder();
  std::stable_sort(loops.begin(), loops.end(),
                   [](const llvm::Loop* a, const llvm::Loop* b) { return instructions(*a) > instructions(*b); });
  std::size_t total = f.getInstructionCount();
  std::vector<llvm::Loop*> candidates;
  for (llvm::Loop* loop : loops)
    if (candidates.size() < kCandidateLoops && instructions(*loop) <= total / parts) candidates.push_back(loop);
  std::vector<std::size_t> size(candidates.size());
  std::vector<std::size_t> nests(candidates.size(), 0);  // bit j: one of i and j holds the other
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    size[i] = instructions(*candidates[i]);
    for (std::size_t j = 0; j < candidates.size(); ++j)
      if (i != j && (candidates[i]->contains(candidates[j]) || candidates[j]->contains(candidates[i])))
        nests[i] |= std::size_t{1} << j;
  }
  std::size_t best = total, best_set = 0;
  for (std::size_t set = 1; set < (std::size_t{1} << candidates.size()); ++set) {
    std::vector<std::size_t> sizes{total};
    bool nested = false;
    for (std::size_t i = 0; i < candidates.size() && !nested; ++i) {
      if (!(set >> i & 1)) continue;
      nested = (nests[i] & set) != 0;
      sizes.push_back(size[i]);
      sizes.front() -= size[i];
    }
    std::size_t largest = nested ? total : largest_part(sizes, parts);
    if (largest < best) best = largest, best_set = set;
  }
  std::vector<llvm::BasicBlock*> headers;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (best_set >> i & 1) headers.push_back(candidates[i]->getHeader());
  return headers;
}

// Each loop headed by one of `headers` becomes a function that `f` calls.
// The loops are found again before each: outlining one moves blocks
// around the others.
void outline(llvm::Function& f, const std::vector<llvm::BasicBlock*>& headers) {
  for (llvm::BasicBlock* header : headers) {
    llvm::DominatorTree dominators(f);
    llvm::LoopInfo info(dominators);
    llvm::Loop* loop = info.getLoopFor(header);
    if (!loop || loop->getHeader() != header) continue;
    llvm::CodeExtractor extractor(dominators, *loop, false, nullptr, nullptr, nullptr, "part");
    if (!extractor.isEligible()) continue;
    llvm::CodeExtractorAnalysisCache cache(f);
    extractor.extractCodeRegion(cache);
  }
}

// Each defined function to the part with the fewest instructions so far,
// largest first.  Functions get external names, so that one part calls
// what another defines.
std::map<std::string, unsigned> assign_parts(llvm::Module& m, unsigned parts) {
  std::vector<llvm::Function*> functions;
  for (llvm::Function& f : m)
    if (!f.isDeclaration()) {
      f.setLinkage(llvm::GlobalValue::ExternalLinkage);
      f.setDSOLocal(false);
      functions.push_back(&f);
    }
  std::stable_sort(functions.begin(), functions.end(),
                   [](const llvm::Function* a, const llvm::Function* b) { return a->getInstructionCount() > b->getInstructionCount(); });
  std::vector<std::size_t> load(parts, 0);
  std::map<std::string, unsigned> part;
  for (const llvm::Function* f : functions) {
    auto lightest = static_cast<unsigned>(std::min_element(load.begin(), load.end()) - load.begin());
    part[f->getName().str()] = lightest;
    load[lightest] += f->getInstructionCount();
  }
  return part;
}

// The machine passes' configuration as addPassesToEmitFile makes it (its
// verifier off, as there by default: the module was verified after
// optimisation), less what `passes` leaves out.
void add_machine_passes(llvm::legacy::PassManager& pm, llvm::LLVMTargetMachine& machine, MachinePasses passes,
                        llvm::raw_pwrite_stream& os, const std::string& program) {
  auto* info = new llvm::MachineModuleInfoWrapperPass(&machine);
  llvm::TargetPassConfig* config = machine.createPassConfig(pm);
  config->setDisableVerify(true);
  if (passes == MachinePasses::Lean)
    for (llvm::AnalysisID pass : {&llvm::MachineSchedulerID, &llvm::EarlyMachineLICMID, &llvm::MachineCSEID})
      config->disablePass(pass);
  pm.add(config);
  pm.add(info);
  bool failed = config->addISelPasses();
  if (!failed) {
    config->addMachinePasses();
    config->setInitialized();
    failed = machine.addAsmPrinter(pm, os, nullptr, llvm::CGFT_ObjectFile, info->getMMI().getContext());
  }
  if (failed) throw Error("program '" + program + "': cpu backend: this target cannot emit object files");
  pm.add(llvm::createFreeMachineFunctionPass());
}

std::string emit(llvm::Module& m, const llvm::orc::JITTargetMachineBuilder& builder, MachinePasses passes,
                 const std::string& program) {
  llvm::orc::JITTargetMachineBuilder own = builder;  // making a machine is not const
  auto machine = own.createTargetMachine();
  if (!machine)
    throw Error("program '" + program + "': cpu backend: creating the target machine: " + llvm::toString(machine.takeError()));
  llvm::SmallVector<char, 0> bytes;
  llvm::raw_svector_ostream os(bytes);
  llvm::legacy::PassManager pm;
  add_machine_passes(pm, static_cast<llvm::LLVMTargetMachine&>(**machine), passes, os, program);
  pm.run(m);
  return std::string(bytes.begin(), bytes.end());
}

// Part `k` of a module: the functions of other parts only declared.
std::string emit_part(llvm::Module& m, const std::map<std::string, unsigned>& part, unsigned k,
                      const llvm::orc::JITTargetMachineBuilder& builder, MachinePasses passes,
                      const std::string& program) {
  for (llvm::Function& f : m)
    if (!f.isDeclaration() && part.at(f.getName().str()) != k) f.deleteBody();
  return emit(m, builder, passes, program);
}

// Each part on a thread of its own, the first on the caller's; a context
// serves one thread, so the others read the module back from its bitcode.
void emit_parts(llvm::Module& module, const std::map<std::string, unsigned>& part,
                const llvm::orc::JITTargetMachineBuilder& builder, MachinePasses passes, const std::string& program,
                Objects& out) {
  std::atomic<double> elsewhere{0};
  std::thread::id caller = std::this_thread::get_id();
  tbb::task_group group;
  for (std::size_t k = 1; k < out.parts.size(); ++k)
    group.run([&, k] {
      double cpu0 = detail::thread_cpu_ms();
      llvm::LLVMContext context;
      auto m = llvm::parseBitcodeFile(llvm::MemoryBufferRef(out.module, program), context);
      if (!m) throw Error("program '" + program + "': cpu backend: reading a part back: " + llvm::toString(m.takeError()));
      out.parts[k] = emit_part(**m, part, static_cast<unsigned>(k), builder, passes, program);
      if (std::this_thread::get_id() != caller) elsewhere.fetch_add(detail::thread_cpu_ms() - cpu0);
    });
  std::exception_ptr failed;
  try {
    out.parts[0] = emit_part(module, part, 0, builder, passes, program);
  } catch (...) {
    failed = std::current_exception();
    group.cancel();
  }
  group.wait();  // rethrows another part's error
  if (failed) std::rethrow_exception(failed);
  out.cpu_ms_elsewhere = elsewhere;
}

// Every part keeps its own copy of the module's global variables: right
// for the lowering's constants, wrong for anything a part could change or
// another module could name.
bool globals_copyable(const llvm::Module& m) {
  return std::all_of(m.global_begin(), m.global_end(),
                     [](const llvm::GlobalVariable& g) { return g.isConstant() && g.hasLocalLinkage(); });
}

}  // namespace

Objects compile_objects(llvm::Module& module, const llvm::orc::JITTargetMachineBuilder& builder, MachinePasses passes,
                        unsigned split_above, unsigned threads, const std::string& program) {
  unsigned parts = std::min(threads, kMostParts);
  if (module.getInstructionCount() <= split_above || !globals_copyable(module)) parts = 1;
  std::map<std::string, unsigned> part;
  if (parts > 1) {
    std::vector<llvm::Function*> large;  // before outlining adds functions
    for (llvm::Function& f : module)
      if (!f.isDeclaration() && f.getInstructionCount() > module.getInstructionCount() / parts) large.push_back(&f);
    for (llvm::Function* f : large) outline(*f, loops_to_outline(*f, parts));
    // No more parts than functions, so that none is empty.
    auto functions = std::count_if(module.begin(), module.end(), [](const llvm::Function& f) { return !f.isDeclaration(); });
    parts = std::min(parts, static_cast<unsigned>(functions));
  }
  if (parts > 1) part = assign_parts(module, parts);
  Objects out;
  llvm::raw_string_ostream os(out.module);
  llvm::WriteBitcodeToFile(module, os);
  os.flush();
  out.parts.resize(std::max(parts, 1u));
  if (parts > 1)
    emit_parts(module, part, builder, passes, program, out);
  else
    out.parts[0] = emit(module, builder, passes, program);
  return out;
}

}  // namespace sh::cpu
