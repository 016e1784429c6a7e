#pragma once
// Machine code kept on disk, so that a kernel compiled once is loaded, not
// compiled, by later processes.  Keyed by the program the backend is given,
// the options, the host CPU, the LLVM version and the backend's build
// (jit.cpp); where and how files are written: sh/detail/disk_cache.hpp.  A
// cache that cannot be written is skipped, never an error.  An entry holds
// a kernel's object files (one per part compiled, codegen.hpp) in one file,
// written whole or not at all, and beside it the optimised module's
// bitcode for its listing.
#include <llvm/Support/MemoryBuffer.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sh::cpu {

class ObjectCache {
 public:
  // The cache for `key`, or none when caching is off.
  static std::optional<ObjectCache> open(const std::string& key);

  void store(const std::vector<std::string>& objects) const;
  // The stored objects (none where nothing readable is stored); a hit
  // wherever an entry was there, readable or not.
  std::vector<std::unique_ptr<llvm::MemoryBuffer>> objects();

  bool hit() const { return hit_; }
  bool has_object() const;
  void forget() const;  // removes the stored objects and module
  // The optimised module, as bitcode, stored beside the objects (listings
  // on a hit).
  std::optional<std::string> module() const;
  void store_module(const std::string& bitcode) const;

 private:
  explicit ObjectCache(std::string path) : path_(std::move(path)) {}
  std::string path_;  // without extension
  bool hit_ = false;
};

}  // namespace sh::cpu
