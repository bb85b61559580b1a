// The one way rollsim spreads independent tasks over threads (sweeps, diagnosis candidates, the scorecard).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace rollsim {

/// Threads for `tasks` tasks: `requested`, or every core when 0; at least 1 and never more than the tasks.
inline unsigned worker_count(unsigned requested, std::size_t tasks) {
  const unsigned want = requested ? requested : std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::max<std::size_t>(1, std::min<std::size_t>(want, tasks)));
}

/// Calls body(k) for every k in [0, tasks) on worker_count(threads, tasks) threads (the caller's included),
/// each taking the next k when it is free, so uneven tasks balance. The first exception a body throws is
/// rethrown here once every thread has stopped; after it, no new task starts.
template <class Body>
void parallel_for(std::size_t tasks, unsigned threads, Body&& body) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&] {
    for (std::size_t k = next++; k < tasks; k = next++) {
      try {
        body(k);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = tasks;
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < worker_count(threads, tasks); ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace rollsim
