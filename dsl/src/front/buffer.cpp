#include "sh/detail/buffer.hpp"

#include <atomic>
#include <cstdint>
#include <limits>
#include <mutex>
#include <new>
#include <utility>

#include "sh/error.hpp"

namespace sh::detail {
namespace {

// Bools are stored as int32, so memory of either serves channels of either.
ir::Scalar stored_as(ir::Scalar s) { return s == ir::Scalar::Bool ? ir::Scalar::I32 : s; }

}  // namespace

TableStorage::TableStorage() {
  static std::atomic<std::uint64_t> next{1};
  id = next++;
}

void TableStorage::touch() {
  filled = true;
  version = next_version();
}

std::size_t Buffer::bytes_for(std::size_t count) const {
  std::size_t element = ir::element_bytes(type_);
  if (count > std::numeric_limits<std::size_t>::max() / element)
    throw Error(std::to_string(count) + " elements of " + ir::type_name(type_) + " are more bytes than memory can hold");
  return count * element;
}

// Zeroes the elements (accumulators start from this); a new count forgets
// the shape, which named the old count's grid.
void Buffer::resize(std::size_t count) {
  if (count != count_) shape_ = {0, 1, 1};
  if (memory_) {
    check_fits(count, "a channel of " + ir::type_name(type_));
    count_ = count;
    return;
  }
  std::size_t bytes = bytes_for(count), words = bytes / 8 + (bytes % 8 != 0);
  auto too_large = [&] {
    return Error(std::to_string(count) + " elements of " + ir::type_name(type_) + " (" + std::to_string(bytes) +
                 " bytes) do not fit in this process's memory");
  };
  if (words > words_.max_size()) throw too_large();
  try {
    words_.assign(words, 0);
  } catch (const std::bad_alloc&) {
    throw too_large();
  }
  count_ = count;
}

std::array<std::size_t, 3> Buffer::shape() const {
  bool current = shape_[0] * shape_[1] * shape_[2] == count_ && shape_[0] > 0;
  return current ? shape_ : std::array<std::size_t, 3>{0, 1, 1};
}

void Buffer::shape(const std::array<std::size_t, 3>& extent) {
  std::string what = "a channel's shape " + std::to_string(extent[0]) + " x " + std::to_string(extent[1]) + " x " +
                     std::to_string(extent[2]);
  constexpr std::size_t kMostPerDimension = std::numeric_limits<std::int32_t>::max();
  for (std::size_t e : extent)
    if (e == 0 || e > kMostPerDimension) throw Error(what + " has an extent outside [1, 2^31 - 1]");
  if (extent[0] * extent[1] > kMostPerDimension * kMostPerDimension / extent[2])
    throw Error(what + " holds more elements than memory can");
  // Elements already given keep their places where the count stays: a
  // channel shaped after its data were given (a stencil's input) had run
  // on zeros.
  if (extent[0] * extent[1] * extent[2] != count_) resize(extent[0] * extent[1] * extent[2]);
  shape_ = extent;
}

void Buffer::check_fits(std::size_t count, const std::string& what) const {
  if (bytes_for(count) > memory_->bytes())
    throw Error(what + " on host memory: " + std::to_string(count) + " elements need " + std::to_string(bytes_for(count)) +
                " bytes; the memory holds " + std::to_string(memory_->bytes()));
}

void Buffer::view(MemoryPtr memory, std::size_t count, const std::string& what) {
  if (!memory) throw Error(what + " on host memory: the memory pointer is null");
  if (stored_as(memory->value_type()) != stored_as(type_.scalar))
    throw Error(what + " on host memory: the memory holds " + ir::scalar_name(memory->value_type()) +
                " values; the elements are " + ir::type_name(type_) + " (no conversion is made)");
  auto address = reinterpret_cast<std::uintptr_t>(memory->data());
  int align = ir::storage_bytes(type_.scalar);
  if (address % align != 0)
    throw Error(what + " on host memory: the data at byte address " + std::to_string(address) + " are not aligned to " +
                std::to_string(align) + " bytes, as " + ir::scalar_name(type_.scalar) + " values must be");
  std::shared_ptr<HostMemory> previous = std::exchange(memory_, memory.shared());
  try {
    check_fits(count, what);
  } catch (...) {
    memory_ = std::move(previous);
    throw;
  }
  words_.clear();
  words_.shrink_to_fit();
  count_ = count;
}

MemoryPtr Buffer::memory() {
  // Two threads asking at once (run_fused on one table from two threads)
  // adopt the storage once: a second move would hand out empty memory.
  static std::mutex adopting;
  std::lock_guard lock(adopting);
  // An empty owned buffer has no memory yet (as an empty channel had none
  // in Sh): adopting nothing would pin an output channel at 0 elements.
  if (!memory_ && count_ == 0) return {};
  if (!memory_) memory_ = HostMemory::adopt(std::move(words_), bytes(), type_.scalar);
  words_.clear();
  return memory_;
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
