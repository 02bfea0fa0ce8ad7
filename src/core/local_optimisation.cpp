#include "place_planner/local_optimisation.h"

namespace place_planner {

LocalStep localOptimisationStep(const Stability& s, double lift) {
  LocalStep step;
  if (s.stable || s.d_f.norm() < 1e-9) return step;
  const Eigen::Vector3d d_g = -Eigen::Vector3d::UnitZ();
  if (s.failure == Failure::kSlide) {
    step.kind = LocalStep::kSlide;
    step.lift = lift * s.plane_normal;
    step.slide = s.d_f;
    return step;
  }
  const Eigen::Vector3d axis = s.d_f.cross(d_g);
  if (axis.norm() < 1e-6) return step;  // d_f along gravity: nothing to rotate about
  step.kind = LocalStep::kRotate;
  step.d_A = axis.normalized();
  step.s_A = s.pivot;
  return step;
}

}  // namespace place_planner
