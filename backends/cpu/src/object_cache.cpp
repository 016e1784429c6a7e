#include "object_cache.hpp"

#include <llvm/Support/MemoryBuffer.h>

#include <filesystem>

#include "sh/detail/disk_cache.hpp"

namespace sh::cpu {

std::optional<ObjectCache> ObjectCache::open(const std::string& key) {
  std::optional<std::string> path = detail::cache_path("cpu", key);
  if (!path) return std::nullopt;
  return ObjectCache(*path);
}

void ObjectCache::notifyObjectCompiled(const llvm::Module*, llvm::MemoryBufferRef object) {
  detail::write_cache_file(path_ + ".o", std::string(object.getBufferStart(), object.getBufferSize()));
}

std::unique_ptr<llvm::MemoryBuffer> ObjectCache::getObject(const llvm::Module*) {
  auto buffer = llvm::MemoryBuffer::getFile(path_ + ".o");
  if (!buffer) return nullptr;
  hit_ = true;
  return std::move(*buffer);
}

bool ObjectCache::has_object() const {
  std::error_code ignored;
  return std::filesystem::exists(path_ + ".o", ignored);
}

void ObjectCache::forget() const {
  std::error_code ignored;
  std::filesystem::remove(path_ + ".o", ignored);
  std::filesystem::remove(path_ + ".ll", ignored);
}

std::optional<std::string> ObjectCache::listing() const { return detail::read_cache_file(path_ + ".ll"); }

void ObjectCache::store_listing(const std::string& ir) const { detail::write_cache_file(path_ + ".ll", ir); }

}  // namespace sh::cpu
