// Compiled instead of cuda/*.cu when the build has no CUDA (-DPLACE_PLANNER_WITH_CUDA=OFF or no
// nvcc): the CPU backend is used and the launchers say why they cannot run.
#include <stdexcept>

#include "place_planner/infra/cuda_backend.h"

namespace place_planner {
namespace cuda {

bool available(std::string* why) {
  if (why) *why = "built without CUDA";
  return false;
}

void markUnusable(const std::string&) {}
void resetDevice() {}

void transformVertices(const Rigid&, const V3*, V3*, size_t) {
  throw std::runtime_error("place_planner was built without CUDA");
}

}  // namespace cuda
}  // namespace place_planner

#include "place_planner/infra/backend.h"

namespace place_planner {

std::unique_ptr<Backend> makeCudaBackend(const ObjectModel&, const AreaModel&, const TiltParams&) {
  throw std::runtime_error("CUDA backend unavailable: place_planner was built without CUDA");
}

}  // namespace place_planner
