#include "sh/backend.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <future>
#include <map>
#include <mutex>
#include <optional>

#include "../interp/interp.hpp"
#include "running.hpp"
#include "sh/detail/cpu_time.hpp"
#include "sh/detail/disk_cache.hpp"
#include "sh/error.hpp"
#include "sh/ir/printer.hpp"
#include "sh/ir/serialize.hpp"
#include "sh/ir/visitor.hpp"
#include "sh/passes.hpp"
#include "sh/waves.hpp"

namespace sh {
namespace {

struct Registered {
  BackendFactory factory;
  int preference = 0;
};

struct Registry {
  std::mutex mutex;
  std::map<std::string, Registered> factories;
  std::map<std::string, std::unique_ptr<Backend>> instances;
  std::map<std::string, std::shared_ptr<Kernel>> kernels;
  // Kernels being compiled: a thread asking for one waits for it.
  std::map<std::string, std::shared_future<std::shared_ptr<Kernel>>> compiling;
  std::string chosen;  // use_backend()
};

Registry& registry() {
  static Registry r;
  static bool builtin = [] {
    r.factories["interp"] = {interp::make_backend, 1};
    return true;
  }();
  (void)builtin;
  return r;
}

}  // namespace

namespace detail {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string resolve(const BackendChoice& choice) { return choice.name.empty() ? default_backend_name() : choice.name; }

// The program as backends get it: optimised (where the options ask) and
// legalised.  The passes' result is kept on disk under the program as
// recorded, the options and the build of these passes, so that a later
// process skips them: a kernel from a backend's cache then costs no pass.
ir::Program legal_program(const Program& program, const Options& options) {
  static const int anchor = 0;
  static const std::string passes_build = detail::build_id(&anchor);
  std::optional<std::string> path;
  if (!passes_build.empty())
    path = detail::cache_path("passes", ir::serialize(program.ir()) + "|" + options.key() + "|" + passes_build);
  if (path)
    if (std::optional<std::string> bytes = detail::read_cache_file(*path)) try {
        return ir::deserialize(*bytes);
      } catch (const Error&) {
        // a damaged file: the passes run again and replace it
      }
  ir::Program legal = passes::legalize(options.optimize ? optimize(program.ir(), options.precision) : program.ir());
  if (path) detail::write_cache_file(*path, ir::serialize(legal));
  return legal;
}

std::shared_ptr<Kernel> cached_kernel(const Program& program, const std::string& name, const Options& options,
                                      RunStats& stats) {
  Backend& b = find_backend(name);
  // Names too: a kernel's errors name its program, tables and variables,
  // so a program of the same structure under other names is another's.
  std::string around = b.environment_key(options);
  std::string key = name + "|" + std::to_string(program.hash_with_names()) + "|" + std::to_string(around.size()) + ":" +
                    around + "|" + options.key();
  Registry& r = registry();
  // A promise (and its shared state) only where this thread compiles: a
  // kernel found costs a lookup.
  std::optional<std::promise<std::shared_ptr<Kernel>>> made;
  std::shared_future<std::shared_ptr<Kernel>> another;
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    auto it = r.kernels.find(key);
    if (it != r.kernels.end()) return it->second;
    auto being = r.compiling.find(key);
    if (being != r.compiling.end()) {
      another = being->second;
    } else {
      made.emplace();
      r.compiling.emplace(key, made->get_future().share());
    }
  }
  // Another thread compiles it: this one waits (and meets its error, if any).
  if (another.valid()) return another.get();
  auto done = [&](auto&& answer) {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.compiling.erase(key);
    answer();
  };
  try {
    if (options.threads < 0 || options.threads > kMostThreads)
      throw Error("program '" + program.name() + "': Options::threads = " + std::to_string(options.threads) +
                  ": must be 0 (every core) to " + std::to_string(kMostThreads));
    auto t0 = std::chrono::steady_clock::now();
    double cpu0 = detail::thread_cpu_ms();
    ir::Program ir = legal_program(program, options);
    stats.compile_phases = {{"passes", ms_since(t0)}};
    std::shared_ptr<Kernel> kernel = b.compile(ir, options);
    for (const CompilePhase& phase : kernel->compile_phases()) stats.compile_phases.push_back(phase);
    stats.compiled = true;
    stats.from_disk = kernel->loaded_from_disk();
    stats.compile_ms = ms_since(t0);
    stats.compile_cpu_ms = detail::thread_cpu_ms() - cpu0 + kernel->compile_cpu_ms_elsewhere();
    done([&] {
      kernel = r.kernels.emplace(key, std::move(kernel)).first->second;
      made->set_value(kernel);
    });
    return kernel;
  } catch (...) {
    done([&] { made->set_exception(std::current_exception()); });
    throw;
  }
}

std::string describe_slot(const ir::Program& p, const char* what, std::size_t k) {
  return "program '" + p.name + "': " + what + " " + std::to_string(k);
}

BufferView view_of(detail::Buffer& b) { return BufferView{b.type(), b.size(), b.data()}; }

// An output in the memory of a table its program reads: the run would read
// elements it had already written, in whatever order its backend runs them
// (the interpreter's cascade, the cpu backend's batches of lanes).
void refuse_outputs_over_tables(const ir::Program& p, const RunArgs& args) {
  for (std::size_t k = 0; k < args.outputs.size(); ++k) {
    const BufferView& out = args.outputs[k];
    Bytes written = byte_range(out.data, out.count * ir::element_bytes(out.type));
    for (std::size_t t = 0; t < args.tables.size(); ++t) {
      const TableView& table = args.tables[t];
      if (!table.data || !overlap(written, byte_range(table.data, table.bytes()))) continue;
      const std::string& name = p.tables[t].name;
      throw Error(describe_slot(p, "output channel", k) + " lies in the memory of table " + std::to_string(t) +
                  (name.empty() ? "" : " '" + name + "'") + ", which the program reads (or adds into): it would " +
                  "read elements the run had already written, in an order each backend chooses; give the output " +
                  "memory of its own (an InOut channel updates a stream in place)");
    }
  }
}

std::string describe_shape(const std::array<std::size_t, 3>& e) {
  return std::to_string(e[0]) + " x " + std::to_string(e[1]) + " x " + std::to_string(e[2]);
}

// The grid of the channels that have a shape (outputs first); they must
// agree.  Without one the domain is a single row.
LaunchDomain launch_domain(const ir::Program& p, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
                           const std::vector<std::shared_ptr<detail::Buffer>>& outputs) {
  LaunchDomain domain;
  std::string from;
  auto consider = [&](const detail::Buffer& b, const std::string& which) {
    std::array<std::size_t, 3> shape = b.shape();
    if (shape[0] == 0) return;
    if (from.empty()) {
      domain.extent = shape;
      from = which;
    } else if (shape != domain.extent) {
      throw Error("program '" + p.name + "': " + which + " is shaped " +
                  describe_shape(shape) + " but " + from + " is shaped " + describe_shape(domain.extent));
    }
  };
  for (std::size_t k = 0; k < outputs.size(); ++k) consider(*outputs[k], "output channel " + std::to_string(k));
  for (std::size_t k = 0; k < inputs.size(); ++k) consider(*inputs[k], "input channel " + std::to_string(k));
  return domain;
}

RunArgs bind_arguments(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
                       const std::vector<std::shared_ptr<detail::Buffer>>& outputs) {
  const ir::Program& p = program.ir();
  if (inputs.size() != p.inputs.size())
    throw Error("program '" + p.name + "' takes " + std::to_string(p.inputs.size()) + " input channels; " +
                std::to_string(inputs.size()) + " were given");
  if (outputs.size() != p.outputs.size())
    throw Error("program '" + p.name + "' gives " + std::to_string(p.outputs.size()) + " output channels; " +
                std::to_string(outputs.size()) + " were given");
  RunArgs args;
  args.count = inputs.empty() ? (outputs.empty() || !outputs[0] ? 0 : outputs[0]->size()) : (inputs[0] ? inputs[0]->size() : 0);
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    if (!inputs[k]) throw Error(describe_slot(p, "input channel", k) + " is missing");
    if (inputs[k]->type() != p.type_of(p.inputs[k]))
      throw Error(describe_slot(p, "input", k) + " is " + ir::type_name(p.type_of(p.inputs[k])) + " but its channel holds " +
                  ir::type_name(inputs[k]->type()));
    if (inputs[k]->size() != args.count)
      throw Error(describe_slot(p, "input channel", k) + " holds " + std::to_string(inputs[k]->size()) +
                  " elements but input channel 0 holds " + std::to_string(args.count));
    args.inputs.push_back(view_of(*inputs[k]));
  }
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    if (!outputs[k]) throw Error(describe_slot(p, "output channel", k) + " is missing");
    if (outputs[k]->type() != p.type_of(p.outputs[k]))
      throw Error(describe_slot(p, "output", k) + " is " + ir::type_name(p.type_of(p.outputs[k])) +
                  " but its channel holds " + ir::type_name(outputs[k]->type()));
    {
      // Two runs given one empty channel size it once: a second resize
      // would free the storage the first run writes.
      static std::mutex sizing;
      std::lock_guard lock(sizing);
      if (outputs[k]->size() == 0) outputs[k]->resize(args.count);
    }
    if (outputs[k]->size() != args.count)
      throw Error(describe_slot(p, "output channel", k) + " holds " + std::to_string(outputs[k]->size()) +
                  " elements but the stream has " + std::to_string(args.count));
    args.outputs.push_back(view_of(*outputs[k]));
  }
  args.domain = launch_domain(p, inputs, outputs);
  if (args.domain.extent[0] == 0 && args.count > static_cast<std::size_t>(INT32_MAX) && ir::uses(p, ir::Op::Position))
    throw Error("program '" + p.name + "' reads position(), whose x holds at most 2^31 - 1, but runs over a stream " +
                "of " + std::to_string(args.count) + " elements in one row: give its channels a shape (Channel::shape)");
  for (const auto& u : program.uniforms()) args.uniforms.push_back(u->value);
  for (std::size_t t = 0; t < program.tables().size(); ++t) {
    detail::TableStorage& s = *program.tables()[t];
    // Filled by assign() or set(), on memory given to it, or through its
    // memory() marked dirty().
    if (!s.filled && s.buffer.memory_version() == 0)
      throw Error("program '" + p.name + "': table " + std::to_string(t) +
                  (s.decl.name.empty() ? "" : " '" + s.decl.name + "'") + " was never filled");
    void* sums = s.decl.accumulator ? s.buffer.data() : nullptr;
    args.tables.push_back(TableView{s.decl.element, s.decl.rank, s.dims, s.buffer.data(), sums, s.id, s.current_version(),
                                    nullptr, program.tables()[t]});
  }
  refuse_outputs_over_tables(p, args);
  return args;
}

}  // namespace detail

using detail::bind_arguments;
using detail::cached_kernel;
using detail::describe_slot;
using detail::ms_since;
using detail::resolve;

void add_compiled(bool& compiled, bool& from_disk, const RunStats& one) {
  if (!one.compiled) return;
  from_disk = (compiled ? from_disk : true) && one.from_disk;
  compiled = true;
}

void add_phases(std::vector<CompilePhase>& total, const std::vector<CompilePhase>& more) {
  for (const CompilePhase& phase : more) {
    auto same = std::find_if(total.begin(), total.end(), [&](const CompilePhase& p) { return p.name == phase.name; });
    if (same == total.end())
      total.push_back(phase);
    else
      same->ms += phase.ms;
  }
}

void add_details(std::shared_ptr<RunDetails>& total, const std::shared_ptr<RunDetails>& more) {
  if (!more) return;
  if (total)
    total->add(*more);
  else
    total = more->clone();
}

Error runaway_loop(const ir::Program& p, const ir::Stmt& loop, std::uint64_t element, std::uint64_t cap) {
  return Error("program '" + p.name + "': element " + std::to_string(element) + " ran a loop more than " +
               std::to_string(cap) + " iterations (`" + ir::print(p, loop) +
               "`); raise Options::max_loop_iterations if that is intended");
}

void register_backend(const std::string& name, BackendFactory factory, int preference) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.factories[name] = {std::move(factory), preference};
}

std::vector<std::string> backend_names() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, f] : r.factories) names.push_back(name);
  return names;
}

Backend& find_backend(const std::string& name) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto inst = r.instances.find(name);
  if (inst != r.instances.end()) return *inst->second;
  auto f = r.factories.find(name);
  if (f == r.factories.end()) {
    std::string known;
    for (const auto& [n, ignored] : r.factories) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown backend '" + name + "' (built: " + known + ")");
  }
  return *r.instances.emplace(name, f->second.factory()).first->second;
}

std::vector<BackendInfo> backends() {
  std::vector<BackendInfo> all;
  for (const std::string& name : backend_names()) {
    Backend& b = find_backend(name);
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    all.push_back({name, b.variants(), b.settings(), r.factories.at(name).preference});
  }
  return all;
}

std::string preferred_backend_name(const std::string& except) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const std::string* best = nullptr;
  int best_preference = 0;
  for (const auto& [name, registered] : r.factories)
    if (name != except && (!best || registered.preference > best_preference)) {
      best = &name;
      best_preference = registered.preference;
    }
  return best ? *best : "interp";
}

std::string default_backend_name() {
  Registry& r = registry();
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    if (!r.chosen.empty()) return r.chosen;
  }
  if (const char* env = std::getenv("SH_BACKEND"); env && *env) return env;
  return preferred_backend_name();
}

void use_backend(const std::string& name) {
  find_backend(name);  // fails now, not at the next run
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.chosen = name;
}

BackendChoice backend(const std::string& name, Options options) { return BackendChoice{name, std::move(options)}; }

int lanes_of(const BackendChoice& choice) { return find_backend(resolve(choice)).lanes(choice.options); }

std::shared_ptr<Kernel> kernel_for(const Program& program, const BackendChoice& choice) {
  RunStats ignored;
  return detail::checked(program, cached_kernel(program, resolve(choice), choice.options, ignored));
}

void detail::check_waves(const ir::Program& p, const Waves& w) {
  if (w.max_waves < 0)
    throw Error("program '" + p.name + "': waves: max_waves must be 0 or more, not " + std::to_string(w.max_waves));
  if (ir::uses(p, ir::Op::Position))
    throw Error("program '" + p.name + "' reads position(), which waves cannot keep: a later wave runs its elements "
                "gathered out of their places");
  auto output = [&](int k) {
    if (k < 0 || static_cast<std::size_t>(k) >= p.outputs.size())
      throw Error("program '" + p.name + "': output " + std::to_string(k) + " named for waves does not exist (" +
                  std::to_string(p.outputs.size()) + " outputs)");
    return p.type_of(p.outputs[k]);
  };
  if (output(w.request_output).scalar != ir::Scalar::I32)
    throw Error(describe_slot(p, "output", w.request_output) + " holds the requests of waves, so it must be int1..int4, not " +
                ir::type_name(output(w.request_output)));
  for (const auto& [out, in] : w.carried) {
    if (in < 0 || static_cast<std::size_t>(in) >= p.inputs.size())
      throw Error("program '" + p.name + "': input " + std::to_string(in) + " named as carried does not exist (" +
                  std::to_string(p.inputs.size()) + " inputs)");
    if (output(out) != p.type_of(p.inputs[in]))
      throw Error(describe_slot(p, "output", out) + " is carried into input " + std::to_string(in) + " of another type");
  }
}

namespace {

RunStats run_with(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
                  const std::vector<std::shared_ptr<detail::Buffer>>& outputs, const BackendChoice& choice,
                  const Waves* waves) {
  RunStats stats;
  stats.backend = resolve(choice);
  RunArgs args = bind_arguments(program, inputs, outputs);
  if (waves) detail::check_waves(program.ir(), *waves);
  std::shared_ptr<Kernel> kernel = cached_kernel(program, stats.backend, choice.options, stats);
  stats.elements = args.count;
  if (args.count == 0) return stats;
  auto t0 = std::chrono::steady_clock::now();
  if (waves)
    kernel->run_waves(args, *waves, stats);
  else
    kernel->run(args, stats);
  for (const auto& o : outputs) o->written();
  stats.run_ms = ms_since(t0);
  return stats;
}

}  // namespace

RunStats run(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
             const std::vector<std::shared_ptr<detail::Buffer>>& outputs, const BackendChoice& choice) {
  return run_with(program, inputs, outputs, choice, nullptr);
}

RunStats run(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
             const std::vector<std::shared_ptr<detail::Buffer>>& outputs, const Waves& waves, const BackendChoice& choice) {
  return run_with(program, inputs, outputs, choice, &waves);
}

}  // namespace sh
