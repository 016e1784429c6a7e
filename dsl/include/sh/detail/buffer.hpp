#pragma once
// Host memory behind channels and tables: `count` elements of one IR type,
// components contiguous per element.  Bools are stored as int32 0/1.  A
// buffer owns its storage, or views a HostMemory (the user's, or its own
// storage handed out by memory()) that it shares ownership of.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "sh/detail/words.hpp"
#include "sh/ir/program.hpp"
#include "sh/memory.hpp"

namespace sh::detail {

class Buffer {
 public:
  Buffer() = default;
  Buffer(ir::Type type, std::size_t count) : type_(type) { resize(count); }

  ir::Type type() const { return type_; }
  std::size_t size() const { return count_; }
  std::size_t bytes() const { return bytes_for(count_); }
  // Throws sh::Error where the bytes would pass what a size_t counts (a
  // product that wrapped would pass every check after it).
  std::size_t bytes_for(std::size_t count) const;
  // Owned storage is reallocated and zeroed; a view keeps its bytes and
  // only checks that `count` elements fit in them.
  void resize(std::size_t count);
  void* data() { return memory_ ? memory_->data() : words_.data(); }
  const void* data() const { return memory_ ? memory_->data() : words_.data(); }

  // Views `count` elements at the start of `memory` from now on.  Throws
  // sh::Error naming `what` (the channel or table) where the memory is
  // missing, of another value type, misaligned or too small.
  void view(MemoryPtr memory, std::size_t count, const std::string& what);
  // The memory the data lie in; owned storage is moved into a HostMemory
  // first (the data stay where they are).
  MemoryPtr memory();
  // A run wrote the elements: memory a table views too has changed, so a
  // backend that keeps a copy of the table (opencl, mpi) reads it again.
  void written() {
    if (memory_) memory_->dirty();
  }
  // The viewed memory's version (HostMemory::dirty), 0 for owned storage.
  std::uint64_t memory_version() const { return memory_ ? memory_->version() : 0; }

  // The grid the elements form, row-major (LaunchDomain::extent): set by
  // shape(), which resizes to the grid's count (zeros) unless the count is
  // already that (the elements kept); one row ({0, 1, 1}) where none was
  // set or the count changed since.
  std::array<std::size_t, 3> shape() const;
  void shape(const std::array<std::size_t, 3>& extent);

  // Component c of element i, as a double (exact for every stored type).
  double get(std::size_t i, int c) const;
  void set(std::size_t i, int c, double v);

 private:
  void check_fits(std::size_t count, const std::string& what) const;

  ir::Type type_;
  std::size_t count_ = 0;
  std::array<std::size_t, 3> shape_{0, 1, 1};
  Words words_;  // owned storage; empty for a view
  std::shared_ptr<HostMemory> memory_;
};

struct TableStorage {
  TableStorage();
  std::uint64_t id;  // unique in the process, never reused
  ir::TableDecl decl;
  std::array<int, 3> dims{1, 1, 1};
  Buffer buffer;
  bool filled = false;
  std::uint64_t version = 0;  // raised at every host write
  // A host write: a version never given before (shared with HostMemory's,
  // so that the larger of the two changes whenever either does).
  void touch();
  // What backends key their copies of the table by.
  std::uint64_t current_version() const { return std::max(version, buffer.memory_version()); }
};

}  // namespace sh::detail
