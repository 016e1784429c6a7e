#pragma once
// A recorded program: its IR and the host objects it reads at run time (the
// uniforms, whose current values are passed at every run, and the tables).
// Programs compose (Sh's shader algebra): the result is one program whose
// seams the passes see through.
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "sh/detail/buffer.hpp"
#include "sh/detail/value.hpp"
#include "sh/ir/program.hpp"

namespace sh {

class Program {
 public:
  Program() = default;
  Program(ir::Program ir, std::vector<std::shared_ptr<detail::VarNode>> uniforms,
          std::vector<std::shared_ptr<detail::TableStorage>> tables);

  bool empty() const { return !ir_; }
  const ir::Program& ir() const;
  const std::string& name() const { return ir().name; }
  // Structural hash of the IR (names and uniform values left out).
  std::uint64_t hash() const { return hash_; }
  // The same with every name in: what the process's kernels are keyed by,
  // since a kernel's errors name its program, tables and variables.
  std::uint64_t hash_with_names() const { return hash_with_names_; }
  // Parallel to ir().uniforms and ir().tables.
  const std::vector<std::shared_ptr<detail::VarNode>>& uniforms() const { return uniforms_; }
  const std::vector<std::shared_ptr<detail::TableStorage>>& tables() const { return tables_; }

  // The same host objects with another body (what passes produce).
  Program with_ir(ir::Program ir) const { return Program(std::move(ir), uniforms_, tables_); }

 private:
  std::shared_ptr<const ir::Program> ir_;
  std::uint64_t hash_ = 0, hash_with_names_ = 0;
  std::vector<std::shared_ptr<detail::VarNode>> uniforms_;
  std::vector<std::shared_ptr<detail::TableStorage>> tables_;
};

// p << q: q's outputs feed p's inputs, in order (types must match).
Program operator<<(const Program& p, const Program& q);
// p & q: side by side; inputs and outputs are p's followed by q's.
Program operator&(const Program& p, const Program& q);
// Turns p's first input into a read of `value` (a uniform stays a run-time
// parameter; a constant is folded in by the passes).
Program bind(const Program& p, const detail::Value& value);
// Makes `uniform` a constant with its current value; the passes then remove
// the branches it decides.  The program is recompiled; changes to the
// uniform no longer reach it.
Program freeze(const Program& p, const detail::Value& uniform);

namespace detail {

// What SH_BEGIN_PROGRAM(name) { ... } SH_END expands to: the body runs
// once, recorded.
struct ProgramDefinition {
  std::string name;
};

Program record(const std::string& name, void (*body)(void*), void* context);

template <class Body>
Program operator->*(ProgramDefinition definition, Body&& body) {
  return record(
      definition.name, [](void* ctx) { (*static_cast<std::remove_reference_t<Body>*>(ctx))(); },
      static_cast<void*>(&body));
}

}  // namespace detail
}  // namespace sh

#define SH_BEGIN_PROGRAM(name) ::sh::detail::ProgramDefinition{name}->*[&]()
#define SH_END
