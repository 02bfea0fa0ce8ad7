// Deterministic CPU parallel loop: [0, n) cut into one contiguous block per thread, so every
// element is computed by the same code whatever the thread count (results do not depend on it).
#pragma once
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace place_planner {

inline int resolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw ? static_cast<int>(hw) : 1;
}

template <typename F>
void parallelFor(size_t n, int threads, F&& f) {
  const size_t t = std::min(n, static_cast<size_t>(resolveThreads(threads)));
  if (t <= 1 || n < 2) {
    for (size_t i = 0; i < n; ++i) f(i);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(t - 1);
  const size_t chunk = (n + t - 1) / t;
  for (size_t k = 1; k < t; ++k) {
    const size_t b = k * chunk, e = std::min(n, b + chunk);
    if (b >= e) break;
    pool.emplace_back([&f, b, e] {
      for (size_t i = b; i < e; ++i) f(i);
    });
  }
  for (size_t i = 0; i < std::min(n, chunk); ++i) f(i);
  for (auto& th : pool) th.join();
}

}  // namespace place_planner
