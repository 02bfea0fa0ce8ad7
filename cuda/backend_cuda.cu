// The CUDA device of the one launcher (kernels/batched_steps.h): a grid-stride kernel over the
// same work items the CPU pool runs, device memory from a pool that grows and is reused, one
// stream per backend (per plan). The area's model is uploaded once per build and kept on the
// device beside the host cache (keyed by AreaModel::id); the object's per plan.
#include <algorithm>
#include <cstdlib>
#include <list>
#include <memory>
#include <mutex>
#include <vector>

#include "cuda_common.cuh"
#include "place_planner/infra/backend.h"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/kernels/batched_steps.h"

namespace place_planner {
namespace {

template <typename F>
__global__ void gridStride(F f, size_t n) {
  for (size_t i = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<size_t>(blockDim.x) * gridDim.x)
    f(i);
}

// Device copies of a model's arrays, freed with it.
struct DeviceArrays {
  std::vector<std::shared_ptr<void>> blocks;
  template <typename T>
  const T* operator()(const std::vector<T>& h) {
    if (h.empty()) return nullptr;
    void* p = nullptr;
    PP_CUDA_CHECK(cudaMalloc(&p, h.size() * sizeof(T)));
    blocks.emplace_back(p, [](void* q) { cudaFree(q); });
    PP_CUDA_CHECK(cudaMemcpy(p, h.data(), h.size() * sizeof(T), cudaMemcpyHostToDevice));
    return static_cast<const T*>(p);
  }
};

struct DeviceArea {
  uint64_t id;
  DeviceArrays arrays;
  AreaView view;
};

// The last few areas' device copies (the host cache holds four models too), and whether this
// device has the rotation kernels' deep stacks. Neither survives cudaDeviceReset.
std::mutex g_device_state_mutex;
std::list<std::shared_ptr<DeviceArea>> g_area_cache;
bool g_stack_limit_set = false;

std::shared_ptr<DeviceArea> deviceArea(const AreaModel& a) {
  std::lock_guard<std::mutex> lock(g_device_state_mutex);
  for (const auto& d : g_area_cache)
    if (d->id == a.id) return d;
  auto d = std::make_shared<DeviceArea>();
  d->id = a.id;
  d->view = makeAreaView(a, d->arrays);
  g_area_cache.push_front(d);
  if (g_area_cache.size() > 4) g_area_cache.pop_back();
  return d;
}

// Deep per-thread traversal stacks for the rotation kernels: once per device context.
void ensureStackLimit() {
  std::lock_guard<std::mutex> lock(g_device_state_mutex);
  if (g_stack_limit_set) return;
  PP_CUDA_CHECK(cudaDeviceSetLimit(cudaLimitStackSize, 16384));
  g_stack_limit_set = true;
}

// Measured on an H200 (books_stack, 1k mug, cold; doc/gpu.md): distance and tilts fastest at
// 11-12 levels, contact points at 10 (their slots and counts grow with the parts).
constexpr int kSplitLevels = 11;

class CudaDevice {
 public:
  CudaDevice(const ObjectModel& o, const AreaModel& a) {
    ensureStackLimit();
    PP_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking));
    obj_ = makeObjectView(o, obj_arrays_);
    area_ = deviceArea(a);
  }
  ~CudaDevice() {
    cudaStreamSynchronize(stream_);
    for (auto& b : pool_)
      if (b.ptr) cudaFree(b.ptr);
    cudaStreamDestroy(stream_);
  }
  CudaDevice(const CudaDevice&) = delete;
  CudaDevice& operator=(const CudaDevice&) = delete;

  std::string name() const { return "cuda"; }
  // Every pending pose in one launch, as far as 1 GiB of contact slots allows.
  size_t preferredBatch(size_t spheres) const {
    const size_t by_memory = (size_t(1) << 30) / (std::max<size_t>(spheres, 1) * sizeof(SphereContact));
    return std::clamp<size_t>(by_memory, 64, 8192);
  }
  // Each distance and tilt answer split into 2^levels work items over the subtrees of its BVHs
  // (batched_steps.h): a step's few hundred poses are otherwise a few warps on the whole GPU.
  // PLACE_PLANNER_CUDA_SPLIT_LEVELS (0-14) overrides it, to measure (doc/gpu.md).
  int contactSplitLevels() const { return std::max(0, splitLevels() - 1); }
  int splitLevels() const {
    static const int levels = [] {
      const char* e = std::getenv("PLACE_PLANNER_CUDA_SPLIT_LEVELS");
      return e ? std::clamp(std::atoi(e), 0, 14) : kSplitLevels;
    }();
    return levels;
  }
  const ObjectView& object() const { return obj_; }
  const AreaView& area() const { return area_->view; }

  template <typename F>
  void parallelFor(size_t n, const F& f) {
    if (n == 0) return;
    const unsigned blocks = static_cast<unsigned>(std::min<size_t>((n + 127) / 128, 65535));
    gridStride<<<blocks, 128, 0, stream_>>>(f, n);
    PP_CUDA_CHECK(cudaGetLastError());
  }
  template <typename T>
  T* scratch(int slot, size_t n) {
    return static_cast<T*>(grow(slot, n * sizeof(T)));
  }
  template <typename T>
  const T* upload(int slot, const std::vector<T>& host) {
    T* d = static_cast<T*>(grow(kUploadSlots + slot, host.size() * sizeof(T)));
    if (!host.empty())
      PP_CUDA_CHECK(cudaMemcpyAsync(d, host.data(), host.size() * sizeof(T), cudaMemcpyHostToDevice, stream_));
    return d;
  }
  template <typename T>
  void download(const T* dev, size_t n, T* host) {
    if (n == 0) return;
    PP_CUDA_CHECK(cudaMemcpyAsync(host, dev, n * sizeof(T), cudaMemcpyDeviceToHost, stream_));
    PP_CUDA_CHECK(cudaStreamSynchronize(stream_));
  }
  void finish() {
    PP_CUDA_CHECK(cudaGetLastError());
    PP_CUDA_CHECK(cudaStreamSynchronize(stream_));
  }

 private:
  static constexpr int kUploadSlots = 8;
  struct Block {
    void* ptr = nullptr;
    size_t bytes = 0;
  };
  // Grow-only per slot: a plan allocates a few times, not once per step.
  void* grow(int slot, size_t bytes) {
    Block& b = pool_[slot];
    if (b.bytes < bytes) {
      PP_CUDA_CHECK(cudaStreamSynchronize(stream_));
      if (b.ptr) PP_CUDA_CHECK(cudaFree(b.ptr));
      b.ptr = nullptr;
      b.bytes = 0;
      const size_t want = std::max<size_t>(bytes + bytes / 2, 4096);
      PP_CUDA_CHECK(cudaMalloc(&b.ptr, want));
      b.bytes = want;
    }
    return b.ptr;
  }

  cudaStream_t stream_ = nullptr;
  DeviceArrays obj_arrays_;
  ObjectView obj_;
  std::shared_ptr<DeviceArea> area_;
  Block pool_[2 * kUploadSlots];
};

}  // namespace

namespace cuda {
void forgetDeviceState() {
  std::lock_guard<std::mutex> lock(g_device_state_mutex);
  g_area_cache.clear();
  g_stack_limit_set = false;
}
}  // namespace cuda

std::unique_ptr<Backend> makeCudaBackend(const ObjectModel& object, const AreaModel& area,
                                         const TiltParams& tilt) {
  std::string why;
  if (!cuda::available(&why)) throw std::runtime_error("CUDA backend unavailable: " + why);
  return std::make_unique<BatchedBackend<CudaDevice>>(tilt, object, area);
}

}  // namespace place_planner
