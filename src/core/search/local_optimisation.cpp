#include "place_planner/search/local_optimisation.h"

namespace place_planner {

LocalStep localOptimisationStep(const Stability& s, const Eigen::Vector3d& com, double lift) {
  LocalStep step;
  if (s.stable || s.d_f.norm() < 1e-9) return step;
  const Eigen::Vector3d d_g = -Eigen::Vector3d::UnitZ();
  if (s.failure == Failure::kSlide) {
    step.kind = LocalStep::kSlide;
    // A slip found by the contact forces is horizontal: lifted straight up, clear of the floor.
    step.lift = lift * (std::abs(s.d_f.z()) < 1e-9 ? Eigen::Vector3d(Eigen::Vector3d::UnitZ()) : s.plane_normal);
    step.slide = s.d_f;
    return step;
  }
  Eigen::Vector3d axis = s.d_f.cross(d_g);
  step.s_A = s.pivot;
  if (s.tip_edge_dir.norm() > 0.5 && std::abs(s.tip_edge_dir.z()) < 0.9) {
    axis = s.tip_edge_dir;
    step.s_A = s.tip_edge_point;
    // +angle must lower the centre of mass: d(com.z)/d(angle) = (d_A x (com - s_A)).z < 0.
    if (axis.cross(com - step.s_A).z() > 0) axis = -axis;
  }
  if (axis.norm() < 1e-6) return step;  // d_f along gravity: nothing to rotate about
  step.kind = LocalStep::kRotate;
  step.d_A = axis.normalized();
  return step;
}

}  // namespace place_planner
