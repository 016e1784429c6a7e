#include "sh/memory.hpp"

#include <atomic>

#include "sh/error.hpp"

namespace sh {

namespace detail {
std::uint64_t next_version() {
  static std::atomic<std::uint64_t> next{1};
  return next++;
}

namespace {
constexpr std::size_t kPage = 4096;
// Blocks of this many bytes or more are placed in their page in turn
// (words.hpp), this far apart.
constexpr std::size_t kPlacedFrom = 64 * 1024;
constexpr std::size_t kPlaceStep = 512;
}  // namespace

void* allocate_storage(std::size_t bytes) {
  if (bytes < kPlacedFrom) return ::operator new(bytes, std::align_val_t{kCacheLine});
  static std::atomic<std::size_t> placed{0};
  std::size_t offset = placed.fetch_add(1, std::memory_order_relaxed) % (kPage / kPlaceStep) * kPlaceStep;
  return static_cast<char*>(::operator new(bytes + kPage, std::align_val_t{kPage})) + offset;
}

void free_storage(void* p, std::size_t bytes) noexcept {
  if (bytes < kPlacedFrom) return ::operator delete(p, std::align_val_t{kCacheLine});
  auto at = reinterpret_cast<std::uintptr_t>(p);
  ::operator delete(reinterpret_cast<void*>(at - at % kPage), std::align_val_t{kPage});
}
}  // namespace detail

HostMemory::HostMemory(std::size_t bytes, ir::Scalar type)
    : HostMemory(detail::Words((bytes + 7) / 8, 0), bytes, type) {}

HostMemory::HostMemory(std::size_t bytes, void* data, ir::Scalar type) : data_(data), bytes_(bytes), type_(type) {
  if (!data && bytes > 0)
    throw Error("host memory of " + std::to_string(bytes) + " bytes wraps a null pointer");
}

HostMemory::HostMemory(detail::Words&& words, std::size_t bytes, ir::Scalar type)
    : own_(std::move(words)), data_(own_.data()), bytes_(bytes), type_(type) {}

std::shared_ptr<HostMemory> HostMemory::adopt(detail::Words&& words, std::size_t bytes, ir::Scalar type) {
  return std::shared_ptr<HostMemory>(new HostMemory(std::move(words), bytes, type));
}

void HostMemory::dirty() { version_ = detail::next_version(); }

HostMemory* HostMemory::findStorage(const std::string& id) {
  if (id != "host")
    throw Error("host memory has only the storage \"host\"; \"" + id + "\" was asked for (no device storage is kept here)");
  return this;
}

MemoryPtr::MemoryPtr(HostMemory* memory) {
  if (!memory) return;
  memory_ = memory->weak_from_this().lock();
  if (!memory_) memory_.reset(memory);
}

}  // namespace sh
