// How a cancel or the time budget reaches a step that runs for long inside one call (building
// the models, casting floor points, the hull): the planner's thread sets the signal, the step
// polls it in its loops and throws Stopped, which the planner catches (planner.cpp).
#pragma once
#include <atomic>
#include <cstddef>
#include <exception>

namespace place_planner {

// A step that was asked to stop; caught by the planner, never seen by its callers.
struct Stopped : std::exception {
  const char* what() const noexcept override { return "stopped"; }
};

// Set by the planner's thread (a cancel, the budget); polled by the workers in their loops.
class StopSignal {
 public:
  void request() { flag_.store(true, std::memory_order_relaxed); }
  bool requested() const { return flag_.load(std::memory_order_relaxed); }
  void throwIfRequested() const {
    if (requested()) throw Stopped();
  }

 private:
  std::atomic<bool> flag_{false};
};

// Every `every` calls (a power of two), throws Stopped when `stop` (may be null) is set.
inline void pollStop(const StopSignal* stop, size_t i, size_t every = 1024) {
  if (stop && (i & (every - 1)) == 0) stop->throwIfRequested();
}

}  // namespace place_planner
