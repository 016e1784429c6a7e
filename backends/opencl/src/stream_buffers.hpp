#pragma once
// Device buffers for copied streams, lent to runs and given back.  A buffer
// used before costs no page faults (a new one's first touch cost a copied
// run of 48 MiB 145 ms), and an idle one is any kernel's to reuse.  Idle
// buffers are kept under a quarter of the device's memory, those idle
// longest let go first.  (Each kernel kept its last run's buffers for as
// long as it lived, which is as long as the process: programs made and
// dropped one after another each left theirs on the device.)
#include <cstdint>
#include <functional>
#include <list>
#include <mutex>

#include "runtime.hpp"

namespace sh::opencl {

class StreamBuffers {
 public:
  explicit StreamBuffers(std::uint64_t idle_budget) : budget_(idle_budget) {}
  // A buffer of `size` bytes made with `flags`: an idle one, or a new one
  // from `make`.
  Buffer take(std::size_t size, cl_mem_flags flags, const std::function<Buffer()>& make);
  void give_back(Buffer buffer, std::size_t size, cl_mem_flags flags);
  std::size_t idle_bytes() const;

 private:
  struct Idle {
    Buffer buffer;
    std::size_t size;
    cl_mem_flags flags;
  };
  mutable std::mutex mutex_;
  std::list<Idle> idle_;  // given back longest ago first
  std::size_t idle_bytes_ = 0;
  std::uint64_t budget_;
};

// The device's buffers, one pool for each device opened.
StreamBuffers& stream_buffers_on(const Device& device);

// The buffers one run borrowed, given back when it ends (however it ends:
// by then the queues are done with them).
class Borrowed {
 public:
  Borrowed(StreamBuffers& pool) : pool_(pool) {}
  Borrowed(const Borrowed&) = delete;
  Borrowed& operator=(const Borrowed&) = delete;
  ~Borrowed();
  cl_mem take(std::size_t size, cl_mem_flags flags, const std::function<Buffer()>& make);

 private:
  struct Loan {
    Buffer buffer;
    std::size_t size;
    cl_mem_flags flags;
  };
  StreamBuffers& pool_;
  std::list<Loan> loans_;  // a list: cl_mem handles stay where they are
};

}  // namespace sh::opencl
