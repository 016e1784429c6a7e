#include "object_cache.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>

#include "sh/detail/disk_cache.hpp"

namespace sh::cpu {

std::optional<ObjectCache> ObjectCache::open(const std::string& key) {
  std::optional<std::string> path = detail::cache_path("cpu", key);
  if (!path) return std::nullopt;
  return ObjectCache(*path);
}

// One file of parts, each its size (8 bytes, this host's order) and its
// bytes: the parts of one compile are written together, so a reader never
// meets the parts of two compiles of different part counts.
void ObjectCache::store(const std::vector<std::string>& objects) const {
  std::string file;
  for (const std::string& object : objects) {
    std::uint64_t size = object.size();
    file.append(reinterpret_cast<const char*>(&size), sizeof size);
    file += object;
  }
  detail::write_cache_file(path_ + ".o", file);
}

std::vector<std::unique_ptr<llvm::MemoryBuffer>> ObjectCache::objects() {
  std::vector<std::unique_ptr<llvm::MemoryBuffer>> out;
  hit_ = true;  // an entry that does not read is forgotten by the caller, who compiles afresh
  std::optional<std::string> file = detail::read_cache_file(path_ + ".o");
  if (!file) return out;
  for (std::size_t at = 0; at < file->size();) {
    std::uint64_t size = 0;
    if (file->size() - at < sizeof size) return {};
    std::memcpy(&size, file->data() + at, sizeof size);
    at += sizeof size;
    if (size > file->size() - at) return {};
    out.push_back(llvm::MemoryBuffer::getMemBufferCopy(llvm::StringRef(file->data() + at, size), path_));
    at += size;
  }
  return out;
}

bool ObjectCache::has_object() const {
  std::error_code ignored;
  return std::filesystem::is_regular_file(path_ + ".o", ignored);
}

void ObjectCache::forget() const {
  std::error_code ignored;
  std::filesystem::remove(path_ + ".o", ignored);
  std::filesystem::remove(path_ + ".bc", ignored);
}

std::optional<std::string> ObjectCache::module() const { return detail::read_cache_file(path_ + ".bc"); }

void ObjectCache::store_module(const std::string& bitcode) const { detail::write_cache_file(path_ + ".bc", bitcode); }

}  // namespace sh::cpu
