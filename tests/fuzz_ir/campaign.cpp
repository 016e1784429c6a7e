#include "campaign.hpp"

#include <algorithm>
#include <iostream>

#include <sh/error.hpp>
#include <sh/ir/printer.hpp>
#include <sh/ir/verifier.hpp>

#include "exactness.hpp"
#include "minimize.hpp"
#include "report.hpp"
#include "rng.hpp"
#include "runner.hpp"

namespace fuzz_ir {
namespace {

struct Finding {
  const Mode* mode;
  std::vector<Mismatch> mismatches;
};

// Where the worker is, for its supervisor (fuzz_ir.cpp): a crash or hang
// is blamed on the last program and mode named.
class Control {
 public:
  explicit Control(std::FILE* out) : out_(out) {}
  void running(std::size_t k, const std::string& mode) {
    if (out_) std::fprintf(out_, "run %zu %s\n", k, mode.c_str()), std::fflush(out_);
  }
  void done(std::size_t k, const Tally& t) {
    std::fflush(stdout);
    if (out_) std::fprintf(out_, "done %zu %s\n", k, t.line().c_str()), std::fflush(out_);
  }
  std::size_t program = 0;

 private:
  std::FILE* out_;
};

Mode reference_mode(sh::Precision p) { return Mode{"interp", {}, p}; }

std::vector<Finding> run_everywhere(const Case& c, const std::vector<Mode>& modes, Result (&reference)[2], Control& control) {
  std::vector<Finding> findings;
  for (const Mode& m : modes) {
    const Result& ref = reference[m.precision == sh::Precision::F64];
    control.running(control.program, m.name());
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
void minimise_and_print(const Case& c, const Finding& first, const std::vector<Mode>& modes, bool listings, Control& control,
                        Tally& tally) {
  const Mode& mode = *first.mode;
  const Mismatch& m = first.mismatches[0];
  auto fails = [&](const Case& candidate) {
    control.running(control.program, mode.name() + " (minimising)");
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
  std::vector<Finding> findings = run_everywhere(small, modes, reference, control);
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
              int& minimise_budget, bool listings, Control& control, Tally& tally) {
  Case c = generate(seed, options);
  control.running(control.program, "interp");
  ++tally.programs;
  Result reference[2];
  std::string why;
  if (!references(c, reference, why)) {
    ++tally.invalid;
    std::cout << "=== invalid program, seed " << seed << " (" << replay_command(seed, options) << "): " << why << "\n"
              << sh::ir::print(c.program);
    return;
  }
  std::vector<Finding> findings = run_everywhere(c, modes, reference, control);
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
  std::fflush(stdout);  // before a minimisation that may crash
  if (minimise_budget > 0) {
    --minimise_budget;
    minimise_and_print(c, findings[0], all, listings, control, tally);
  }
  std::cout.flush();
}

}  // namespace

std::string replay_command(std::uint64_t seed, const GeneratorOptions& options) {
  return std::string("fuzz_ir ") + (options.accumulators ? "" : "--no-accumulators ") + "--replay " + std::to_string(seed);
}

std::vector<std::uint64_t> program_seeds(const Options& o) {
  std::vector<std::uint64_t> seeds = o.replay;
  for (std::size_t k = 0; o.replay.empty() && k < o.programs; ++k) seeds.push_back(program_seed(o.seed, k));
  return seeds;
}

Tally run_campaign(const Options& o, std::FILE* control_file) {
  std::vector<Mode> modes = all_modes(o.backends);
  if (o.start == 0) {
    std::cout << "fuzz_ir: " << modes.size() << " modes:";
    for (const Mode& m : modes) std::cout << " " << m.name();
    std::cout << std::endl;
  }
  int minimise_budget = o.replay.empty() ? o.minimize : std::max(o.minimize, 1);
  Tally tally;
  Control control(control_file);
  std::vector<std::uint64_t> seeds = program_seeds(o);
  std::size_t per_program = o.modes_per_program == 0 || !o.replay.empty() ? modes.size() : std::min(o.modes_per_program, modes.size());
  std::size_t end = o.end == 0 ? seeds.size() : std::min(o.end, seeds.size());
  for (std::size_t k = o.start; k < end; ++k) {
    std::vector<Mode> these;
    for (std::size_t j = 0; j < per_program; ++j) these.push_back(modes[(k * per_program + j) % modes.size()]);
    control.program = k;
    fuzz_one(seeds[k], o.generator, these, modes, minimise_budget, o.listing, control, tally);
    control.done(k, tally);
  }
  return tally;
}

}  // namespace fuzz_ir
