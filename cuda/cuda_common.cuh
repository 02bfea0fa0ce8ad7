#pragma once
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

#include "place_planner/infra/cuda_backend.h"

// A failed CUDA call throws (the goal fails with INTERNAL_ERROR) and marks the device
// unusable for backend auto until cuda::resetDevice() (cuda_backend.h).
#define PP_CUDA_CHECK(call)                                                                   \
  do {                                                                                        \
    const cudaError_t pp_err = (call);                                                        \
    if (pp_err != cudaSuccess) {                                                              \
      const std::string pp_msg = std::string("CUDA error in ") + #call + ": " +              \
                                 cudaGetErrorString(pp_err);                                  \
      ::place_planner::cuda::markUnusable(pp_msg);                                            \
      throw std::runtime_error(pp_msg);                                                       \
    }                                                                                         \
  } while (0)

namespace place_planner {
namespace cuda {

// RAII device buffer.
template <typename T>
class DeviceBuffer {
 public:
  explicit DeviceBuffer(size_t n) : n_(n) {
    if (n_) PP_CUDA_CHECK(cudaMalloc(&ptr_, n_ * sizeof(T)));
  }
  ~DeviceBuffer() {
    if (ptr_) cudaFree(ptr_);
  }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  T* get() const { return ptr_; }
  void upload(const T* h) { if (n_) PP_CUDA_CHECK(cudaMemcpy(ptr_, h, n_ * sizeof(T), cudaMemcpyHostToDevice)); }
  void download(T* h) const { if (n_) PP_CUDA_CHECK(cudaMemcpy(h, ptr_, n_ * sizeof(T), cudaMemcpyDeviceToHost)); }

 private:
  T* ptr_ = nullptr;
  size_t n_;
};

// Drops what lives in the device context (the areas' device copies, the stack limit), before
// cudaDeviceReset frees it: a plan after cuda::resetDevice() uploads again.
void forgetDeviceState();

inline unsigned blocksFor(size_t n, unsigned threads = 256) {
  return static_cast<unsigned>((n + threads - 1) / threads);
}

}  // namespace cuda
}  // namespace place_planner
