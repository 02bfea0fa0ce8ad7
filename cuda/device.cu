#include <mutex>

#include "cuda_common.cuh"
#include "place_planner/infra/cuda_backend.h"

namespace place_planner {
namespace cuda {
namespace {
std::mutex g_fault_mutex;
std::string g_fault;  // empty: usable
}  // namespace

void markUnusable(const std::string& why) {
  std::lock_guard<std::mutex> lock(g_fault_mutex);
  if (g_fault.empty()) g_fault = why;
}

void resetDevice() {
  std::lock_guard<std::mutex> lock(g_fault_mutex);
  g_fault.clear();
  forgetDeviceState();
  cudaDeviceReset();
}

bool available(std::string* why) {
  {
    std::lock_guard<std::mutex> lock(g_fault_mutex);
    if (!g_fault.empty()) {
      if (why) *why = "device marked unusable after a fault (" + g_fault + "); cuda::resetDevice() clears it";
      return false;
    }
  }
  int n = 0;
  const cudaError_t err = cudaGetDeviceCount(&n);
  if (err != cudaSuccess) {
    if (why) *why = std::string("cudaGetDeviceCount: ") + cudaGetErrorString(err);
    cudaGetLastError();  // clear the sticky error
    return false;
  }
  if (n == 0) {
    if (why) *why = "no CUDA device";
    return false;
  }
  return true;
}

}  // namespace cuda
}  // namespace place_planner
