// The CPU device of the one launcher (kernels/batched_steps.h): the worker pool over the work
// items, host memory for the buffers; the views point into the host models.
#include <algorithm>
#include <cstring>
#include <memory>

#include "place_planner/infra/backend.h"
#include "place_planner/kernels/batched_steps.h"
#include "place_planner/infra/parallel_for.h"

namespace place_planner {

namespace {

struct HostMemory {  // the array where it is: the kernels read the host models directly
  template <typename T>
  const T* operator()(const std::vector<T>& v) const {
    return v.empty() ? nullptr : v.data();
  }
};

class CpuDevice {
 public:
  CpuDevice(const ObjectModel& o, const AreaModel& a, int threads)
      : obj_(makeObjectView(o, HostMemory{})), area_(makeAreaView(a, HostMemory{})), threads_(threads) {}
  std::string name() const { return "cpu"; }
  // 32 poses per thread, so that poses of very different cost even out between the threads
  // (books_stack, 1k mug, 2 threads, run in turns: 187-221 -> 165-187 ms against 12 per thread,
  // the first robust pose as early), as far as 256 MiB of contact slots allow; never under 16.
  size_t preferredBatch(size_t spheres) const {
    const size_t by_memory = (size_t(1) << 28) / (std::max<size_t>(spheres, 1) * sizeof(SphereContact));
    return std::max<size_t>(16, std::min<size_t>(32 * resolveThreads(threads_), by_memory));
  }
  // One work item per answer: a few workers, and a whole tree prunes best (batched_steps.h).
  int splitLevels() const { return 0; }
  int contactSplitLevels() const { return 0; }
  const ObjectView& object() const { return obj_; }
  const AreaView& area() const { return area_; }
  template <typename F>
  void parallelFor(size_t n, const F& f) {
    place_planner::parallelFor(n, threads_, f);
  }
  // Not zeroed: the contact slots are sized for every sphere of every pose, but a pose writes
  // only its few contacts, so only those pages are ever touched (zeroing them all tripled the
  // robustness check's time).
  template <typename T>
  T* scratch(int slot, size_t n) {
    Buffer& b = buffers_[slot];
    if (b.bytes < n * sizeof(T)) {
      b.bytes = n * sizeof(T) + n * sizeof(T) / 2;
      b.data.reset(new unsigned char[b.bytes]);
    }
    return reinterpret_cast<T*>(b.data.get());
  }
  template <typename T>
  const T* upload(int, const std::vector<T>& host) {
    return host.data();
  }
  template <typename T>
  void download(const T* src, size_t n, T* host) {
    std::copy(src, src + n, host);
  }
  void finish() {}

 private:
  ObjectView obj_;
  AreaView area_;
  int threads_;
  struct Buffer {
    std::unique_ptr<unsigned char[]> data;  // operator new[] aligns for any scalar
    size_t bytes = 0;
  };
  Buffer buffers_[8];  // by slot
};

}  // namespace

ObjectView view(const ObjectModel& o) { return makeObjectView(o, HostMemory{}); }
AreaView view(const AreaModel& a) { return makeAreaView(a, HostMemory{}); }

std::unique_ptr<Backend> makeCpuBackend(const ObjectModel& object, const AreaModel& area,
                                        const TiltParams& tilt, int threads) {
  return std::make_unique<BatchedBackend<CpuDevice>>(tilt, object, area, threads);
}

}  // namespace place_planner
