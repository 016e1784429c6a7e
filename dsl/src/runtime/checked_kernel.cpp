// What kernel_for hands out: the kernel, checking each run's arguments
// against its program first.  A backend's kernel trusts its RunArgs (sh::run
// builds them from channels and checks them there); a caller who builds
// them by hand got crashes for a missing input, a short view or a domain
// of no rows, and silently wrong results for a view of another type.
#include <memory>
#include <string>

#include "running.hpp"
#include "sh/error.hpp"
#include "sh/waves.hpp"

namespace sh::detail {
namespace {

class Checks {
 public:
  Checks(const ir::Program& p, const RunArgs& args) : p_(p), args_(args) {}

  void all() const {
    counts("input", args_.inputs.size(), p_.inputs.size());
    counts("output", args_.outputs.size(), p_.outputs.size());
    counts("uniform", args_.uniforms.size(), p_.uniforms.size());
    counts("table", args_.tables.size(), p_.tables.size());
    for (std::size_t k = 0; k < args_.inputs.size(); ++k) stream("input", k, args_.inputs[k], p_.inputs[k]);
    for (std::size_t k = 0; k < args_.outputs.size(); ++k) stream("output", k, args_.outputs[k], p_.outputs[k]);
    for (std::size_t k = 0; k < args_.tables.size(); ++k) table(k);
    if (args_.count > 0) domain();
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw Error("program '" + p_.name + "': Kernel::run: " + what);
  }

  void counts(const char* what, std::size_t given, std::size_t wanted) const {
    if (given != wanted)
      fail(std::to_string(given) + " " + what + "s given where the program has " + std::to_string(wanted));
  }

  void stream(const char* what, std::size_t k, const BufferView& view, ir::VarId var) const {
    std::string which = std::string(what) + " " + std::to_string(k);
    if (view.type != p_.type_of(var))
      fail(which + " is " + ir::type_name(view.type) + " where the program's is " + ir::type_name(p_.type_of(var)));
    if (view.count < args_.count)
      fail(which + " holds " + std::to_string(view.count) + " elements, fewer than the run's " +
           std::to_string(args_.count));
    if (!view.data && args_.count > 0) fail(which + " has no memory");
  }

  void table(std::size_t k) const {
    const ir::TableDecl& decl = p_.tables[k];
    const TableView& view = args_.tables[k];
    std::string which = "table " + std::to_string(k) + " ";
    if (std::string problem = table_problem(decl.element, decl.rank, view); !problem.empty()) fail(which + problem);
    // An accumulator's sums are its memory; a table read has none.
    if (decl.accumulator && view.sums != view.data)
      fail(which + "is an accumulator: its sums must be its memory (TableView::sums = data)");
    if (!decl.accumulator && view.sums) fail(which + "is read, not added into: it has no sums (TableView::sums null)");
  }

  // Every position a run reads lies in its grid: a domain of no rows (or no
  // layers) divided by zero.
  void domain() const {
    const LaunchDomain& d = args_.domain;
    if (d.extent[1] < 1 || d.extent[2] < 1)
      fail("the launch domain's extents " + std::to_string(d.extent[1]) + " and " + std::to_string(d.extent[2]) +
           " (rows, layers) must be 1 or more");
    if (d.extent[0] == 0) return;
    std::size_t grid = d.extent[0], limit = std::numeric_limits<std::size_t>::max();
    for (int k = 1; k < 3; ++k) grid = grid > limit / d.extent[k] ? limit : grid * d.extent[k];
    if (d.first > grid || args_.count > grid - d.first)
      fail("elements " + std::to_string(d.first) + " to " + std::to_string(d.first) + " + " +
           std::to_string(args_.count) + " run past the launch domain's " + std::to_string(grid) + " elements");
  }

  const ir::Program& p_;
  const RunArgs& args_;
};

// Holds the program (its IR shared, not copied: kernel_for is called
// often), and so its tables, as long as the kernel is held.
class CheckedKernel : public Kernel {
 public:
  CheckedKernel(Program program, std::shared_ptr<Kernel> kernel)
      : program_(std::move(program)), kernel_(std::move(kernel)) {}

  void run(const RunArgs& args, RunStats& stats) override {
    Checks(program_.ir(), args).all();
    kernel_->run(args, stats);
  }
  void run_waves(const RunArgs& args, const Waves& waves, RunStats& stats) override {
    Checks(program_.ir(), args).all();
    check_waves(program_.ir(), waves);
    kernel_->run_waves(args, waves, stats);
  }
  void run_tasks(std::size_t count, int threads, const std::function<void(std::size_t)>& task) override {
    kernel_->run_tasks(count, threads, task);
  }
  std::string listing() const override { return kernel_->listing(); }
  std::vector<CompilePhase> compile_phases() const override { return kernel_->compile_phases(); }
  double compile_cpu_ms_elsewhere() const override { return kernel_->compile_cpu_ms_elsewhere(); }

 private:
  Program program_;
  std::shared_ptr<Kernel> kernel_;
};

}  // namespace

std::string table_problem(ir::Type element, int rank, const TableView& view) {
  if (view.element != element || view.rank != rank)
    return "is " + ir::type_name(view.element) + " of rank " + std::to_string(view.rank) + " where the program reads " +
           ir::type_name(element) + " of rank " + std::to_string(rank);
  for (int k = 0; k < 3; ++k)
    if (int n = view.dims[static_cast<std::size_t>(k)]; k < rank ? n < 1 : n != 1)
      return "has " + std::to_string(n) + " elements along dimension " + std::to_string(k) +
             (k < rank ? "" : ", beyond its rank (1 there)");
  if (!view.data && !view.source) return "has no elements (no data and no source)";
  return "";
}

std::shared_ptr<Kernel> checked(const Program& program, std::shared_ptr<Kernel> kernel) {
  return std::make_shared<CheckedKernel>(program, std::move(kernel));
}

}  // namespace sh::detail
