// CUDA launchers. Each calls the same per-element __host__ __device__ function as its CPU twin
// (include/place_planner/kernels/*.h). Every CUDA call is checked; a failure becomes a
// std::runtime_error so a long-running node aborts one goal instead of dying.
#pragma once
#include <cstddef>
#include <string>

#include "place_planner/model/hd_math.h"

namespace place_planner {
namespace cuda {

// True when the library was built with CUDA and a device answers. `why` (optional) receives
// the reason when false ("built without CUDA", "cudaGetDeviceCount: no CUDA-capable device").
// After a fault (any failed CUDA call, e.g. an illegal address in a kernel) it is false with
// the fault as `why`, so backend auto uses the CPU instead of failing every goal.
bool available(std::string* why = nullptr);

// Records the first fault (called by the launchers).
void markUnusable(const std::string& why);

// Clears the fault and resets the device (cudaDeviceReset): call it with no plan running,
// e.g. from a maintenance step; restarting the node does the same.
void resetDevice();

// out[i] = T(in[i]) on the GPU.
void transformVertices(const Rigid& T, const V3* in, V3* out, size_t n);

}  // namespace cuda
}  // namespace place_planner
