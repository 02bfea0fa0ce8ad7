// CPU parallel loop on a persistent pool of worker threads. Elements are handed out one at a
// time from an atomic counter (poses differ a lot in cost, so fixed blocks would leave a core
// idle), and each element is computed by the same code whatever the thread count, so results do
// not depend on it. Nested or concurrent calls from other threads run serially on the caller.
#pragma once
#include <algorithm>
#include <atomic>
#include <chrono>
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
      active_.store(helpers);
      wanted_ = helpers;
      generation_.fetch_add(1);
    }
    wake_.notify_all();  // no system call when every helper is still spinning
    work();
    spinUntil([&] { return active_.load() == 0; });
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return active_.load() == 0; });
    job_ = nullptr;
    return true;
  }

  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      generation_.fetch_add(1);
    }
    wake_.notify_all();
    for (auto& t : workers_) t.join();
  }

 private:
  // The batched steps call the pool hundreds of times per plan with a few hundred microseconds
  // of serial work between calls: a thread that waits a little before it sleeps is there for the
  // next call without a wake-up through the kernel (on books_stack, 1k mug, about 500 sleeps and
  // wakes per plan otherwise).
  template <typename Ready>
  static void spinUntil(const Ready& ready) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(kSpinUs);
    for (int k = 0; !ready(); ++k)
      if ((k & 63) == 63 && std::chrono::steady_clock::now() > until) return;
  }
  static constexpr int kSpinUs = 300;

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
      spinUntil([&] { return generation_.load() != seen; });
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_.load() != seen; });
        if (stop_) return;
        seen = generation_;
        if (id >= wanted_) continue;  // not needed for this job
      }
      work();
      std::lock_guard<std::mutex> lock(mutex_);
      if (active_.fetch_sub(1) == 1) done_.notify_one();
    }
  }

  std::mutex busy_, mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> workers_;
  const std::function<void(size_t)>* job_ = nullptr;
  size_t n_ = 0;
  std::atomic<size_t> next_{0};
  std::atomic<int> active_{0};
  int wanted_ = 0;
  std::atomic<unsigned long> generation_{0};
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
