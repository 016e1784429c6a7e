// fuzz_ir: differential fuzzing of the language's IR.  Generates random,
// well-typed programs with data at the extremes (generator.hpp), runs each
// on every backend mode built (every variant, f32 and f64 precision,
// precise math) and compares with the interpreter running the program
// unoptimised, under the ULP contract (exactness.hpp says why inexact
// values stay away from conditions).  Prints every disagreement (the
// program, the data, each side's values) and a summary line.
//
//   fuzz_ir [--programs N] [--seed S] [--backends cpu,opencl,...]
//           [--modes-per-program M] [--minimize K] [--no-accumulators]
//           [--replay PROGRAM_SEED]... [--listing]
//
// Each program runs on every mode, or with --modes-per-program on M of
// them in turn (CI's budget: a kernel takes 20-150 ms to compile, and a
// program has 18 modes where every backend is built).
// Programs are a deterministic function of --seed; each disagreement names
// its program's own seed, which --replay regenerates alone.  --minimize
// shrinks the first K disagreeing programs to a few statements and one
// element, and counts them by the operations they keep; --listing adds
// what each disagreeing mode was given and made of the minimised program.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <sh/error.hpp>
#include <sh/ir/printer.hpp>
#include <sh/ir/verifier.hpp>
#include <sh/sh.hpp>

#include "exactness.hpp"
#include "generator.hpp"
#include "minimize.hpp"
#include "report.hpp"
#include "rng.hpp"
#include "runner.hpp"

namespace {

using namespace fuzz_ir;
using Clock = std::chrono::steady_clock;

struct Options {
  std::size_t programs = 300;
  std::uint64_t seed = 1;
  std::vector<std::string> backends;
  int minimize = 0;
  bool listing = false;
  std::size_t modes_per_program = 0;  // 0: all
  std::vector<std::uint64_t> replay;
  GeneratorOptions generator;
};

struct Tally {
  std::size_t programs = 0, runs = 0, disagreements = 0, failing_programs = 0, invalid = 0;
  std::size_t accumulator_only = 0;  // disagreements in accumulator sums alone
  std::map<std::string, std::size_t> by_mode, by_backend, by_operations;
};

struct Finding {
  const Mode* mode;
  std::vector<Mismatch> mismatches;
};

std::string replay_command(std::uint64_t seed, const GeneratorOptions& options) {
  return std::string("fuzz_ir ") + (options.accumulators ? "" : "--no-accumulators ") + "--replay " + std::to_string(seed);
}

// The program and mode running now, for a crash's last words: a backend
// that crashes takes the process with it, and the seed is what replays it.
char g_program[160] = "";
char g_mode[64] = "";

void say_what_crashed(int signal) {
  auto say = [](const char* text) {
    ssize_t ignored = write(2, text, std::strlen(text));
    (void)ignored;
  };
  say("\nfuzz_ir: crashed while running ");
  say(g_program);
  say(" on ");
  say(g_mode);
  say("\n");
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

void now_running(const std::string& mode) { std::snprintf(g_mode, sizeof g_mode, "%s", mode.c_str()); }

[[noreturn]] void usage(const std::string& why) {
  std::cerr << "fuzz_ir: " << why
            << "\nusage: fuzz_ir [--programs N] [--seed S] [--backends a,b] [--modes-per-program M] [--minimize K]\n"
               "               [--no-accumulators] [--replay PROGRAM_SEED]... [--listing]\n";
  std::exit(2);
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::uint64_t number(const std::string& flag, const char* text) {
  char* end = nullptr;
  unsigned long long v = std::strtoull(text, &end, 0);
  if (!*text || *end) usage(flag + " takes a number, not '" + text + "'");
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--help") usage("differential fuzzing of the IR");
    if (a == "--no-accumulators" || a == "--listing") {
      (a == "--listing" ? o.listing : o.generator.accumulators) = a == "--listing";
      continue;
    }
    if (i + 1 >= argc) usage("missing a value after " + a);
    const char* v = argv[++i];
    if (a == "--programs") o.programs = number(a, v);
    else if (a == "--seed") o.seed = number(a, v);
    else if (a == "--backends") o.backends = split(v);
    else if (a == "--minimize") o.minimize = static_cast<int>(number(a, v));
    else if (a == "--modes-per-program") o.modes_per_program = number(a, v);
    else if (a == "--replay") o.replay.push_back(number(a, v));
    else usage("unknown option " + a);
  }
  return o;
}

Mode reference_mode(sh::Precision p) { return Mode{"interp", {}, p}; }

std::vector<Finding> run_everywhere(const Case& c, const std::vector<Mode>& modes, Result (&reference)[2]) {
  std::vector<Finding> findings;
  for (const Mode& m : modes) {
    const Result& ref = reference[m.precision == sh::Precision::F64];
    now_running(m.name());
    std::vector<Mismatch> mm = compare(c, ref, run(c, m, true));
    if (!mm.empty()) findings.push_back({&m, std::move(mm)});
  }
  return findings;
}

void print_findings(const Case& c, const std::vector<Finding>& findings) {
  std::size_t shown_element = SIZE_MAX;
  for (const Finding& f : findings) {
    std::cout << f.mode->name() << ": " << f.mismatches.size() << " component(s) differ\n";
    for (std::size_t k = 0; k < f.mismatches.size() && k < 4; ++k)
      std::cout << describe(f.mismatches[k], slot_scalar(c, f.mismatches[k].slot), f.mode->name()) << "\n";
    std::size_t e = f.mismatches[0].element;
    if (f.mismatches[0].stream && e != shown_element) {
      std::cout << "data of element " << e << ":\n" << describe_data(c, e);
      shown_element = e;
    }
  }
}

bool references(const Case& c, Result (&reference)[2], std::string& why) {
  try {
    sh::ir::verify(c.program);
  } catch (const sh::Error& e) {
    why = e.what();
    return false;
  }
  why = inexact_leak(c.program);
  if (!why.empty()) return false;
  for (int k = 0; k < 2; ++k) {
    reference[k] = run(c, reference_mode(k ? sh::Precision::F64 : sh::Precision::F32), false);
    if (!reference[k].error.empty()) {
      why = "the interpreter threw: " + reference[k].error;
      return false;
    }
  }
  return true;
}

// Shrinks the case on the first finding's mode while that mode still
// differs at the same output component; prints the result run everywhere.
void minimise_and_print(const Case& c, const Finding& first, const std::vector<Mode>& modes, bool listings, Tally& tally) {
  const Mode& mode = *first.mode;
  const Mismatch& m = first.mismatches[0];
  auto fails = [&](const Case& candidate) {
    Result ref = run(candidate, reference_mode(mode.precision), false);
    if (!ref.error.empty()) return false;
    for (const Mismatch& x : compare(candidate, ref, run(candidate, mode, true)))
      if (x.name == m.name && x.component == m.component) return true;
    return false;
  };
  Case small = minimize(c, m.stream ? m.element : 0, m.name, fails);
  Result reference[2];
  std::string why;
  std::cout << "minimised on " << mode.name() << ":\n" << sh::ir::print(small.program);
  if (!references(small, reference, why)) {
    std::cout << "(the minimised program is unusable: " << why << ")\n";
    return;
  }
  std::vector<Finding> findings = run_everywhere(small, modes, reference);
  std::cout << "data:\n" << describe_data(small, 0) << "the minimised program disagrees on:";
  for (const Finding& f : findings) std::cout << " " << f.mode->name();
  std::cout << "\n";
  print_findings(small, findings);
  for (std::size_t k = 0; listings && k < findings.size(); ++k)
    std::cout << "--- listing, " << findings[k].mode->name() << ":\n" << listing(small, *findings[k].mode) << "\n";
  ++tally.by_operations[operations_used(small)];
}

bool only_accumulators(const Finding& f) {
  for (const Mismatch& m : f.mismatches)
    if (m.stream) return false;
  return true;
}

// Runs one program on `modes`; a minimised disagreement runs on `all`.
void fuzz_one(std::uint64_t seed, const GeneratorOptions& options, const std::vector<Mode>& modes, const std::vector<Mode>& all,
              int& minimise_budget, bool listings, Tally& tally) {
  Case c = generate(seed, options);
  std::snprintf(g_program, sizeof g_program, "%s", replay_command(seed, options).c_str());
  now_running("interp (the reference)");
  ++tally.programs;
  Result reference[2];
  std::string why;
  if (!references(c, reference, why)) {
    ++tally.invalid;
    std::cout << "=== invalid program, seed " << seed << " (" << replay_command(seed, options) << "): " << why << "\n"
              << sh::ir::print(c.program);
    return;
  }
  std::vector<Finding> findings = run_everywhere(c, modes, reference);
  tally.runs += modes.size();
  if (findings.empty()) return;
  ++tally.failing_programs;
  tally.disagreements += findings.size();
  std::cout << "=== disagreement: program seed " << seed << " (" << replay_command(seed, options) << "), " << c.count
            << " elements, on";
  for (const Finding& f : findings) {
    std::cout << " " << f.mode->name();
    tally.accumulator_only += only_accumulators(f);
    ++tally.by_mode[f.mode->name()];
    ++tally.by_backend[f.mode->backend];
  }
  std::cout << "\n" << sh::ir::print(c.program);
  print_findings(c, findings);
  if (minimise_budget > 0) {
    --minimise_budget;
    minimise_and_print(c, findings[0], all, listings, tally);
  }
  std::cout.flush();
}

std::string counts(const std::map<std::string, std::size_t>& m) {
  std::string out;
  for (const auto& [name, n] : m) out += (out.empty() ? "" : ", ") + name + " " + std::to_string(n);
  return out.empty() ? "none" : out;
}

void summary(const Tally& t, const Options& o, double seconds) {
  std::printf("fuzz_ir: %zu programs, %zu runs, %zu disagreements in %zu programs, %zu invalid programs; seed %llu; %.0f s\n",
              t.programs, t.runs, t.disagreements, t.failing_programs, t.invalid, static_cast<unsigned long long>(o.seed),
              seconds);
  std::printf("  in accumulator sums only: %zu of the disagreements\n", t.accumulator_only);
  std::printf("  by backend: %s\n  by mode: %s\n", counts(t.by_backend).c_str(), counts(t.by_mode).c_str());
  if (!t.by_operations.empty()) std::printf("  minimised, by operations kept: %s\n", counts(t.by_operations).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  // Tens of thousands of kernels compiled once each: none belongs in the
  // cpu backend's or pocl's on-disk cache.
  setenv("SH_CACHE_DIR", "off", 1);
  setenv("POCL_KERNEL_CACHE", "0", 1);
  for (int signal : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(signal, say_what_crashed);
  Options o = parse(argc, argv);
  std::vector<Mode> modes;
  try {
    modes = all_modes(o.backends);
  } catch (const sh::Error& e) {
    usage(e.what());
  }
  std::cout << "fuzz_ir: " << modes.size() << " modes:";
  for (const Mode& m : modes) std::cout << " " << m.name();
  std::cout << std::endl;
  int minimise_budget = o.replay.empty() ? o.minimize : std::max(o.minimize, 1);
  Tally tally;
  auto t0 = Clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  std::vector<std::uint64_t> seeds = o.replay;
  for (std::size_t k = 0; o.replay.empty() && k < o.programs; ++k) seeds.push_back(program_seed(o.seed, k));
  std::size_t per_program = o.modes_per_program == 0 || !o.replay.empty() ? modes.size() : std::min(o.modes_per_program, modes.size());
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    std::vector<Mode> these;
    for (std::size_t j = 0; j < per_program; ++j) these.push_back(modes[(k * per_program + j) % modes.size()]);
    fuzz_one(seeds[k], o.generator, these, modes, minimise_budget, o.listing, tally);
    if ((k + 1) % 1000 == 0)
      std::printf("progress: %zu of %zu programs, %zu disagreements in %zu programs, %zu invalid, %.0f s\n", k + 1, seeds.size(),
                  tally.disagreements, tally.failing_programs, tally.invalid, seconds());
    std::fflush(stdout);
  }
  summary(tally, o, seconds());
  return tally.disagreements == 0 && tally.invalid == 0 ? 0 : 1;
}
