#include "stream_buffers.hpp"

#include <new>

#include "sh/error.hpp"

namespace sh::opencl {

Buffer StreamBuffers::take(std::size_t size, cl_mem_flags flags, const std::function<Buffer()>& make) {
  {
    std::lock_guard lock(mutex_);
    for (auto it = idle_.begin(); it != idle_.end(); ++it)
      if (it->size == size && it->flags == flags) {
        Buffer found = std::move(it->buffer);
        idle_bytes_ -= size;
        idle_.erase(it);
        return found;
      }
  }
  try {
    return make();
  } catch (const Error&) {  // the device's memory is short: what lies idle goes first
    std::list<Idle> let_go;  // released outside the lock
    {
      std::lock_guard lock(mutex_);
      let_go.swap(idle_);
      idle_bytes_ = 0;
    }
    if (let_go.empty()) throw;
    let_go.clear();
    return make();
  }
}

void StreamBuffers::give_back(Buffer buffer, std::size_t size, cl_mem_flags flags) {
  if (size > budget_) return;  // released here: it would push every idle one out and then go itself
  std::list<Idle> let_go;      // released outside the lock
  std::lock_guard lock(mutex_);
  idle_.push_back({std::move(buffer), size, flags});
  idle_bytes_ += size;
  while (idle_bytes_ > budget_) {
    idle_bytes_ -= idle_.front().size;
    let_go.splice(let_go.end(), idle_, idle_.begin());
  }
}

std::size_t StreamBuffers::idle_bytes() const {
  std::lock_guard lock(mutex_);
  return idle_bytes_;
}

StreamBuffers& stream_buffers_on(const Device& device) {
  return one_per_device<StreamBuffers>(device, device.global_memory / 4);
}

Borrowed::~Borrowed() {
  for (Loan& loan : loans_) try {
      pool_.give_back(std::move(loan.buffer), loan.size, loan.flags);
    } catch (const std::bad_alloc&) {  // no room to keep it idle: it is released instead
    }
}

cl_mem Borrowed::take(std::size_t size, cl_mem_flags flags, const std::function<Buffer()>& make) {
  loans_.push_back({pool_.take(size, flags, make), size, flags});
  return loans_.back().buffer.mem;
}

}  // namespace sh::opencl
