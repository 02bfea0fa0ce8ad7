// Local optimisation of unstable poses (Section VI). Frame G (gravity -z).
#pragma once
#include <Eigen/Core>

#include "place_planner/stability.h"

namespace place_planner {

struct LocalStep {
  enum Kind { kNone, kSlide, kRotate } kind = kNone;
  Eigen::Vector3d lift = Eigen::Vector3d::Zero();   // slide: first move off the plane P
  Eigen::Vector3d slide = Eigen::Vector3d::Zero();  // slide: the new translation direction d_f
  Eigen::Vector3d s_A = Eigen::Vector3d::Zero();    // rotate: axis through the farthest contact
  Eigen::Vector3d d_A = Eigen::Vector3d::UnitX();   // rotate: d_f x d_g; +angle tips along d_f
};

// Friction violated on a slope: slide along d_f down the plane P (after lifting by `lift`
// along P's normal so the contact being left is not hit again). Otherwise rotate into the
// failure direction about d_A = d_f x d_g through the farthest contact of Omega along d_f.
LocalStep localOptimisationStep(const Stability& s, double lift);

}  // namespace place_planner
