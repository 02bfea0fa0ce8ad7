// CPU parallel loop on a persistent pool of worker threads. Elements are handed out one at a
// time from an atomic counter (poses differ a lot in cost, so fixed blocks would leave a core
// idle), and each element is computed by the same code whatever the thread count, so results do
// not depend on it. Nested or concurrent calls from other threads run serially on the caller.
#pragma once
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace place_planner {

inline int resolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw ? static_cast<int>(hw) : 1;
}

namespace detail {

class WorkerPool {
 public:
  static WorkerPool& instance() {
    static WorkerPool pool;
    return pool;
  }

  // Runs f(i) for i in [0, n) on up to `threads` threads (the caller included). Returns false
  // without running anything when the pool is busy (the caller then runs serially).
  bool run(size_t n, int threads, const std::function<void(size_t)>& f) {
    std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
    if (!busy.owns_lock()) return false;
    const int helpers = std::min<int>(threads - 1, static_cast<int>(n) - 1);
    ensureWorkers(helpers);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &f;
      n_ = n;
      next_.store(0);
      active_ = helpers;
      wanted_ = helpers;
      ++generation_;
    }
    wake_.notify_all();
    work();
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return active_ == 0; });
    job_ = nullptr;
    return true;
  }

  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      ++generation_;
    }
    wake_.notify_all();
    for (auto& t : workers_) t.join();
  }

 private:
  void work() {
    for (size_t i = next_.fetch_add(1); i < n_; i = next_.fetch_add(1)) (*job_)(i);
  }

  void ensureWorkers(int count) {
    while (static_cast<int>(workers_.size()) < count) {
      const int id = static_cast<int>(workers_.size());
      workers_.emplace_back([this, id] { loop(id); });
    }
  }

  void loop(int id) {
    unsigned long seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        if (id >= wanted_) continue;  // not needed for this job
      }
      work();
      std::lock_guard<std::mutex> lock(mutex_);
      if (--active_ == 0) done_.notify_one();
    }
  }

  std::mutex busy_, mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> workers_;
  const std::function<void(size_t)>* job_ = nullptr;
  size_t n_ = 0;
  std::atomic<size_t> next_{0};
  int active_ = 0, wanted_ = 0;
  unsigned long generation_ = 0;
  bool stop_ = false;
};

}  // namespace detail

template <typename F>
void parallelFor(size_t n, int threads, F&& f) {
  const int t = resolveThreads(threads);
  if (t <= 1 || n < 2) {
    for (size_t i = 0; i < n; ++i) f(i);
    return;
  }
  const std::function<void(size_t)> job = [&f](size_t i) { f(i); };
  if (!detail::WorkerPool::instance().run(n, t, job))
    for (size_t i = 0; i < n; ++i) f(i);
}

}  // namespace place_planner
