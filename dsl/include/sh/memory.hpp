#pragma once
// Host memory that channels and tables are built on (Sh's ShHostMemory).
// A HostMemory either allocates its own bytes or wraps the user's, which
// the user keeps alive and in place for as long as any channel or table
// uses it.  Channels and tables on it read and write it in place on the
// backends that can (interp, cpu; opencl on a device that shares host
// memory) and copy at the run's edges elsewhere: see docs/sh-compat.md for
// when results land in it on each backend.
//
// A table on host memory is the memory: a backend that keeps a copy of a
// table between runs (opencl on the device, mpi on the other ranks) sends
// it again only when its version changes, so after writing the memory
// through data() the host calls dirty() (Sh's spelling too).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sh/detail/words.hpp"
#include "sh/ir/type.hpp"

namespace sh {

class HostMemory : public std::enable_shared_from_this<HostMemory> {
 public:
  // Allocates `bytes` zeroed bytes, starting a cache line (detail/words.hpp).
  explicit HostMemory(std::size_t bytes, ir::Scalar type = ir::Scalar::F32);
  // Wraps the user's `bytes` bytes at `data`; nothing is copied or freed.
  HostMemory(std::size_t bytes, void* data, ir::Scalar type = ir::Scalar::F32);
  HostMemory(const HostMemory&) = delete;
  HostMemory& operator=(const HostMemory&) = delete;

  std::size_t bytes() const { return bytes_; }
  void* data() { return data_; }
  const void* data() const { return data_; }
  // The type of the values it holds (bool channels use I32 memory).
  ir::Scalar value_type() const { return type_; }

  // The host wrote the bytes: tables on it are sent to devices and ranks
  // again at their next run.  Channels need no call: a run reads them whole.
  void dirty();
  // Process-wide and increasing: every dirty() gives a value never given before.
  std::uint64_t version() const { return version_; }

  // Sh's spellings: memory->hostStorage()->data(), ->length(), ->sync(),
  // and memory->findStorage("host").  This memory is its own host storage.
  HostMemory* hostStorage() { return this; }
  std::size_t length() const { return bytes_; }
  void sync() const {}  // results are in place when the run that wrote them returns
  HostMemory* findStorage(const std::string& id);

  // The storage of an owning channel or table, moved in without a copy, so
  // that memory() can hand it out (detail::Buffer uses this).
  static std::shared_ptr<HostMemory> adopt(detail::Words&& words, std::size_t bytes, ir::Scalar type);

 private:
  HostMemory(detail::Words&& words, std::size_t bytes, ir::Scalar type);

  detail::Words own_;  // empty where the bytes are the user's
  void* data_ = nullptr;
  std::size_t bytes_ = 0;
  ir::Scalar type_;
  std::uint64_t version_ = 0;
};

// A shared pointer to host memory (Sh's ShMemoryPtr / ShHostMemoryPtr).  Like
// Sh's reference-counted pointer it is made straight from `new HostMemory(…)`
// and may be made again from a raw pointer that one already holds: all of
// them share one count, and the memory goes when the last channel, table
// or pointer lets go.  Never make one from memory not allocated by new.
class MemoryPtr {
 public:
  MemoryPtr() = default;
  MemoryPtr(std::nullptr_t) {}
  MemoryPtr(HostMemory* memory);  // implicit, as Sh's pointer was
  MemoryPtr(std::shared_ptr<HostMemory> memory) : memory_(std::move(memory)) {}

  HostMemory* get() const { return memory_.get(); }
  HostMemory* operator->() const { return memory_.get(); }
  HostMemory& operator*() const { return *memory_; }
  explicit operator bool() const { return memory_ != nullptr; }
  const std::shared_ptr<HostMemory>& shared() const { return memory_; }
  long use_count() const { return memory_.use_count(); }
  friend bool operator==(const MemoryPtr& a, const MemoryPtr& b) { return a.memory_ == b.memory_; }

 private:
  std::shared_ptr<HostMemory> memory_;
};

namespace detail {
// The next value of the process-wide counter that versions host memory and
// tables: never the same value twice.
std::uint64_t next_version();
}  // namespace detail

}  // namespace sh
