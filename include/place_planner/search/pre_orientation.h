// Object orientation before placing (Section IV-A).
#pragma once
#include <Eigen/Core>
#include <vector>

#include "place_planner/config.h"
#include "place_planner/model/mesh.h"

namespace place_planner {

// Rotations R_GO of the object (frame O into G) to try. principal_axis: the smallest rotation of
// R_start that makes k1 parallel to d_vis (k1 or -k1, whichever is closer); keep: R_start;
// all_axes: +-k1, +-k2, +-k3 along d_vis, each by the smallest rotation from R_start.
std::vector<Eigen::Matrix3d> preOrientations(const MeshProperties& object,
                                             const Eigen::Matrix3d& R_start,
                                             const Eigen::Vector3d& d_vis, OrientationMode mode);

}  // namespace place_planner
