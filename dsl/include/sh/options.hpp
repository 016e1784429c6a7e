#pragma once
// What a kernel is compiled for: the options every backend honours, and
// each backend's own options, typed by the backend that owns them.
//
// A backend's own options are a struct in its public header
// (sh::cpu::Options, sh::mpi::Options) that names its backend and has a
// string form.  sh::Options carries them type-erased, one per backend:
//
//   sh::Options o;
//   o.set(sh::cpu::Options{.width = sh::cpu::Width::Scalar});
//   o.get<sh::cpu::Options>().width;  // the defaults where none was set
//
// The string form serves command lines (shtrace --set width=scalar), the
// kernel key and the MPI wire; the backend that owns a setting parses it.
#include <concepts>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "sh/ir/eval.hpp"  // Precision

namespace sh {

using ir::Precision;
enum class MathMode : std::uint8_t { Precise, Fast };

// Settings by name in their string form, sorted.
using Settings = std::map<std::string, std::string>;

// A backend's typed options: a copyable struct with its backend's name,
// its settings that differ from the defaults in string form, and set(),
// which parses one (throwing sh::Error that names the setting, the value
// and the backend).
template <class T>
concept TypedBackendOptions = std::copy_constructible<T> && requires(T t, const T c, const std::string& s) {
  { T::backend_name } -> std::convertible_to<std::string_view>;
  { c.settings() } -> std::same_as<Settings>;
  t.set(s, s);
};

// One backend's typed options behind one type; empty: none.  Copies share
// the value, which set() never changes in place.
class BackendOptions {
 public:
  BackendOptions() = default;
  template <TypedBackendOptions T>
  BackendOptions(T typed) : held_(std::make_shared<const Model<T>>(std::move(typed))) {}  // NOLINT: implicit on purpose

  bool empty() const { return !held_; }
  std::string backend() const { return held_ ? held_->backend() : std::string(); }
  Settings settings() const { return held_ ? held_->settings() : Settings{}; }
  // One setting in its string form, parsed by the backend's options.
  void set(const std::string& name, const std::string& value);
  // The typed options, or null where these are another backend's (or none).
  template <class T>
  const T* as() const {
    auto* m = dynamic_cast<const Model<T>*>(held_.get());
    return m ? &m->value : nullptr;
  }

 private:
  struct Concept {
    virtual ~Concept() = default;
    virtual std::string backend() const = 0;
    virtual Settings settings() const = 0;
    virtual std::shared_ptr<const Concept> with(const std::string& name, const std::string& value) const = 0;
  };
  template <class T>
  struct Model final : Concept {
    explicit Model(T v) : value(std::move(v)) {}
    std::string backend() const override { return std::string(T::backend_name); }
    Settings settings() const override { return value.settings(); }
    std::shared_ptr<const Concept> with(const std::string& name, const std::string& v) const override {
      T changed = value;
      changed.set(name, v);
      return std::make_shared<const Model<T>>(std::move(changed));
    }
    T value;
  };
  std::shared_ptr<const Concept> held_;
};

// The most threads a run may ask for: a pool of more is a mistake (each
// thread's stack is reserved), and the thread library fails on millions.
inline constexpr int kMostThreads = 1024;

struct Options {
  Precision precision = Precision::F32;
  MathMode math = MathMode::Precise;
  int threads = 0;                        // 0: every core; at most kMostThreads
  std::uint64_t max_loop_iterations = 1u << 24;  // passes a loop may run, per loop and element
  bool checked = false;                   // interp: report first NaN / bad table read
  bool optimize = true;                   // run the passes before compiling
  // Each backend's own options, by backend name.  A backend that runs
  // another (mpi runs a local backend) passes these on, so one Options
  // holds both: o.set(mpi::Options{...}).set(cpu::Options{...}).
  std::map<std::string, BackendOptions> backends;

  // Sets a backend's options (replacing any it had); empty: nothing.
  Options& set(BackendOptions options);
  // One setting in its string form: "name" for the one linked backend that
  // has a setting of that name, or "backend.name".  The owning backend
  // parses the value.  Throws sh::Error naming an unknown or ambiguous
  // setting (with the settings there are) or a bad value.
  Options& set(const std::string& name, const std::string& value);
  // A backend's options: what was set, else its defaults.
  template <TypedBackendOptions T>
  T get() const {
    auto it = backends.find(std::string(T::backend_name));
    const T* typed = it == backends.end() ? nullptr : it->second.as<T>();
    return typed ? *typed : T{};
  }

  std::string key() const;  // what a compiled kernel depends on
};

}  // namespace sh
