#include "object_cache.hpp"

#include <llvm/Support/MemoryBuffer.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sh::cpu {
namespace {

std::optional<std::string> directory() {
  if (const char* dir = std::getenv("SH_CACHE_DIR")) {
    if (std::string(dir) == "off") return std::nullopt;
    if (*dir) return std::string(dir);
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/sh";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/sh";
  return std::nullopt;
}

// Writes through a temporary renamed into place; failures are ignored.
void write_file(const std::string& path, const char* data, std::size_t size) {
  std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out.write(data, static_cast<std::streamsize>(size))) return;
  }
  std::error_code ignored;
  std::filesystem::rename(tmp, path, ignored);
  if (ignored) std::filesystem::remove(tmp, ignored);
}

}  // namespace

std::optional<ObjectCache> ObjectCache::open(const std::string& key) {
  std::optional<std::string> dir = directory();
  if (!dir) return std::nullopt;
  std::error_code ignored;
  std::filesystem::create_directories(*dir, ignored);
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the key
  for (unsigned char c : key) {
    h ^= c;
    h *= 1099511628211ull;
  }
  std::ostringstream name;
  name << *dir << "/cpu-" << std::hex << h;
  return ObjectCache(name.str());
}

void ObjectCache::notifyObjectCompiled(const llvm::Module*, llvm::MemoryBufferRef object) {
  write_file(path_ + ".o", object.getBufferStart(), object.getBufferSize());
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

std::optional<std::string> ObjectCache::listing() const {
  std::ifstream in(path_ + ".ll");
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void ObjectCache::store_listing(const std::string& ir) const { write_file(path_ + ".ll", ir.data(), ir.size()); }

}  // namespace sh::cpu
