#pragma once
// Machine code kept on disk, so that a kernel compiled once is loaded, not
// compiled, by later processes.  Keyed by the program the backend is given,
// the options, the host CPU, the LLVM version and the backend's build
// (jit.cpp); where and how files are written: sh/detail/disk_cache.hpp.  A
// cache that cannot be written is skipped, never an error.
#include <llvm/ExecutionEngine/ObjectCache.h>

#include <optional>
#include <string>

namespace sh::cpu {

class ObjectCache : public llvm::ObjectCache {
 public:
  // The cache for `key`, or none when caching is off.
  static std::optional<ObjectCache> open(const std::string& key);

  void notifyObjectCompiled(const llvm::Module* m, llvm::MemoryBufferRef object) override;
  std::unique_ptr<llvm::MemoryBuffer> getObject(const llvm::Module* m) override;

  bool hit() const { return hit_; }
  bool has_object() const;
  void forget() const;  // removes the stored object and listing
  // The optimised LLVM IR stored beside the object (listings on a hit).
  std::optional<std::string> listing() const;
  void store_listing(const std::string& ir) const;

 private:
  explicit ObjectCache(std::string path) : path_(std::move(path)) {}
  std::string path_;  // without extension
  bool hit_ = false;
};

}  // namespace sh::cpu
