// Local optimisation of unstable poses (Section VI). Frame G (gravity -z).
#pragma once
#include <Eigen/Core>

#include "place_planner/judgement/stability.h"

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
// failure direction: about the edge of Omega the centre of mass `com` lies beyond, turning so
// that it descends (a whole edge, where the paper pivots about the farthest contact of Omega
// with d_A = d_f x d_g: on curved rims a single pivot needs many small turns); without such an
// edge, the paper's axis.
LocalStep localOptimisationStep(const Stability& s, const Eigen::Vector3d& com, double lift);

}  // namespace place_planner
