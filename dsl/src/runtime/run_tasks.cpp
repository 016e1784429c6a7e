// Kernel::run_tasks's default: threads started for the call take the tasks in
// turn with the caller's.
#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

#include "sh/backend.hpp"

namespace sh {

void Kernel::run_tasks(std::size_t count, int threads, const std::function<void(std::size_t)>& task) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  auto work = [&] {
    try {
      for (std::size_t k = next++; k < count && !failed; k = next++) task(k);
    } catch (...) {
      if (!failed.exchange(true)) error = std::current_exception();
    }
  };
  std::vector<std::thread> others;
  try {
    for (std::size_t t = 1; t < std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)), count); ++t)
      others.emplace_back(work);
  } catch (...) {  // no thread to be had: the ones there are do the tasks
  }
  work();
  for (std::thread& t : others) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace sh
