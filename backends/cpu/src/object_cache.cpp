#include "object_cache.hpp"

#include <filesystem>

#include "sh/detail/disk_cache.hpp"

namespace sh::cpu {

std::optional<ObjectCache> ObjectCache::open(const std::string& key) {
  std::optional<std::string> path = detail::cache_path("cpu", key);
  if (!path) return std::nullopt;
  return ObjectCache(*path);
}

// The first part's file is the entry's: its other parts are written before
// it, so an entry whose first part is there is whole.
std::string ObjectCache::object_path(std::size_t part) const {
  return part == 0 ? path_ + ".o" : path_ + "." + std::to_string(part) + ".o";
}

void ObjectCache::store(const std::vector<std::string>& objects) const {
  std::error_code ignored;
  for (std::size_t part = objects.size(); std::filesystem::remove(object_path(part), ignored); ++part) {
  }
  for (std::size_t part = objects.size(); part-- > 0;) detail::write_cache_file(object_path(part), objects[part]);
}

std::vector<std::unique_ptr<llvm::MemoryBuffer>> ObjectCache::objects() {
  std::vector<std::unique_ptr<llvm::MemoryBuffer>> out;
  for (std::size_t part = 0;; ++part) {
    auto buffer = llvm::MemoryBuffer::getFile(object_path(part));
    if (!buffer) break;
    out.push_back(std::move(*buffer));
  }
  hit_ = !out.empty();
  return out;
}

bool ObjectCache::has_object() const {
  std::error_code ignored;
  return std::filesystem::exists(object_path(0), ignored);
}

void ObjectCache::forget() const {
  std::error_code ignored;
  for (std::size_t part = 0; std::filesystem::remove(object_path(part), ignored); ++part) {
  }
  std::filesystem::remove(path_ + ".bc", ignored);
}

std::optional<std::string> ObjectCache::module() const { return detail::read_cache_file(path_ + ".bc"); }

void ObjectCache::store_module(const std::string& bitcode) const { detail::write_cache_file(path_ + ".bc", bitcode); }

}  // namespace sh::cpu
