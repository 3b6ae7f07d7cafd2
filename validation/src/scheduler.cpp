#include "physval/validation/scheduler.hpp"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <numeric>
#include <thread>

namespace physval {

std::size_t default_jobs() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::sched_getaffinity(0, sizeof set, &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return static_cast<std::size_t>(n);
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

void run_tasks(const std::vector<double>& costs, std::size_t jobs, const std::function<void(std::size_t)>& task) {
  const std::size_t n = costs.size();
#if defined(__SANITIZE_ADDRESS__)
  // Each task forks an engine child. In the sanitizer build a child forked while another
  // thread is inside the AddressSanitizer runtime can inherit its locks held and hang
  // (seen with GCC 12's libasan), so that build runs tasks one at a time. Release builds,
  // whose glibc makes fork safe for malloc and stdio, keep the threads.
  jobs = 1;
#endif
  if (jobs <= 1 || n <= 1) {
    for (std::size_t i = 0; i < n; ++i) task(i);
    return;
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= n || failed.load()) return;
      try {
        task(order[k]);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> threads;
  const std::size_t count = std::min(jobs, n);
  threads.reserve(count);
  for (std::size_t t = 0; t < count; ++t) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace physval
