// side_by_side.hpp (internal to the comparison report): independent jobs on
// a few threads, the calling thread one of them.
//
// run_side_by_side(count, threads, job): job(i) for every i in [0, count),
// each once, on at most `threads` threads. The calling thread is one of them,
// so an interrupt check that acts on the main thread only (Python's) is made
// there too. The first exception a job throws stops every thread from
// starting another job and is rethrown once they have all stopped.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace puncture::validation::comparison_report_detail {

inline void run_side_by_side(std::size_t count, int threads, const std::function<void(std::size_t)>& job) {
  std::atomic<std::size_t> next{0};
  std::mutex failure_mutex;
  std::exception_ptr failure;
  const auto worker = [&]() {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        job(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = count;
      }
    }
  };
  std::vector<std::thread> others;
  for (std::size_t t = 1; t < std::min(static_cast<std::size_t>(std::max(threads, 1)), count); ++t)
    others.emplace_back(worker);
  worker();
  for (std::thread& t : others) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace puncture::validation::comparison_report_detail
