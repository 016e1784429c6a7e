#include "sh/program.hpp"

#include "../fnv1a.hpp"
#include "recorder.hpp"
#include "sh/error.hpp"
#include "sh/ir/serialize.hpp"

namespace sh {

Program::Program(ir::Program ir, std::vector<std::shared_ptr<detail::VarNode>> uniforms,
                 std::vector<std::shared_ptr<detail::TableStorage>> tables)
    : ir_(std::make_shared<const ir::Program>(std::move(ir))),
      uniforms_(std::move(uniforms)),
      tables_(std::move(tables)) {
  hash_ = ir::structural_hash(*ir_);
  hash_with_names_ = detail::fnv1a(ir::serialize(*ir_));
}

const ir::Program& Program::ir() const {
  if (!ir_) throw Error("an empty sh::Program was used; record one with SH_BEGIN_PROGRAM");
  return *ir_;
}

namespace detail {

Program record(const std::string& name, void (*body)(void*), void* context) {
  RecordingScope scope(name);
  body(context);
  return scope.recorder().finish();
}

}  // namespace detail
}  // namespace sh
