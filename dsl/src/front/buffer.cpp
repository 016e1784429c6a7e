#include "sh/detail/buffer.hpp"

#include <atomic>

namespace sh::detail {

TableStorage::TableStorage() {
  static std::atomic<std::uint64_t> next{1};
  id = next++;
}

void Buffer::resize(std::size_t count) {
  count_ = count;
  words_.assign((bytes() + 7) / 8, 0);
}

double Buffer::get(std::size_t i, int c) const {
  std::size_t k = i * type_.width + c;
  switch (type_.scalar) {
    case ir::Scalar::F32: return static_cast<const float*>(data())[k];
    case ir::Scalar::F64: return static_cast<const double*>(data())[k];
    case ir::Scalar::I32: case ir::Scalar::Bool: return static_cast<const std::int32_t*>(data())[k];
  }
  return 0;
}

void Buffer::set(std::size_t i, int c, double v) {
  std::size_t k = i * type_.width + c;
  switch (type_.scalar) {
    case ir::Scalar::F32: static_cast<float*>(data())[k] = static_cast<float>(v); break;
    case ir::Scalar::F64: static_cast<double*>(data())[k] = v; break;
    case ir::Scalar::I32: static_cast<std::int32_t*>(data())[k] = static_cast<std::int32_t>(v); break;
    case ir::Scalar::Bool: static_cast<std::int32_t*>(data())[k] = v > 0 ? 1 : 0; break;
  }
}

}  // namespace sh::detail
