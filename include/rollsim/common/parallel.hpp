// Independent jobs on a few threads: each index runs once, the first exception is rethrown after all joined.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace rollsim {

/// Calls `job(i)` for every i in [0, count) on `threads` threads (0: the hardware's concurrency), the calling
/// thread among them. Jobs are taken one at a time from a shared counter, so uneven jobs balance themselves.
/// After all threads have joined, the first exception a job threw is rethrown.
template <class Job>
void parallel_for(std::size_t count, unsigned threads, Job&& job) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&] {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        job(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  const unsigned wanted = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  const auto n = static_cast<unsigned>(std::min<std::size_t>(wanted, std::max<std::size_t>(count, 1)));
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace rollsim
