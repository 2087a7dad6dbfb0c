// The renderer's one way to spread work over threads: `threads` workers, the calling thread one
// of them, share the indices [0, count) through one atomic counter, each keeping its own totals
// until it runs out. The passes over tiles, the caustic light paths and the error estimate's
// blocks all run through it.
#pragma once

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstddef>
#include <thread>
#include <vector>

namespace pt {

// Runs `worker(take)` on min(threads, count) threads (at least one: the caller) and returns once
// all have. `take(i)` hands out the next index in i and says whether there was one.
template <class Worker>
void parallel_indices(size_t count, int threads, Worker&& worker) {
  std::atomic<size_t> next{0};
  auto take = [&](size_t& i) {
    i = next.fetch_add(1, std::memory_order_relaxed);
    return i < count;
  };
  const int n = std::max(1, int(std::min<size_t>(size_t(std::max(threads, 1)), std::min<size_t>(count, INT_MAX))));
  std::vector<std::thread> pool;
  pool.reserve(size_t(n - 1));
  for (int t = 1; t < n; ++t) pool.emplace_back([&] { worker(take); });
  worker(take);
  for (std::thread& t : pool) t.join();
}

}  // namespace pt
