#include "place_planner/search/pre_orientation.h"

#include <Eigen/Geometry>

namespace place_planner {
namespace {
// Smallest rotation R with R * (R_start * axis) = target, applied after R_start.
Eigen::Matrix3d align(const Eigen::Matrix3d& R_start, const Eigen::Vector3d& axis,
                      const Eigen::Vector3d& target) {
  const Eigen::Vector3d a = (R_start * axis).normalized();
  return Eigen::Quaterniond::FromTwoVectors(a, target.normalized()).toRotationMatrix() * R_start;
}
}  // namespace

std::vector<Eigen::Matrix3d> preOrientations(const MeshProperties& object,
                                             const Eigen::Matrix3d& R_start,
                                             const Eigen::Vector3d& d_vis, OrientationMode mode) {
  std::vector<Eigen::Matrix3d> out;
  switch (mode) {
    case OrientationMode::kKeep:
      out.push_back(R_start);
      break;
    case OrientationMode::kAuto:  // its principal-axis root (start_orientations.cpp adds the rest)
    case OrientationMode::kPrincipalAxis: {
      // k1 || d_vis: "reach the bottom of a box filled with pens or place a plate in a rack".
      const Eigen::Vector3d k1 = object.principal_axes.col(0);
      const double s = (R_start * k1).dot(d_vis) >= 0 ? 1.0 : -1.0;
      out.push_back(align(R_start, s * k1, d_vis));
      break;
    }
    case OrientationMode::kAllAxes:
      for (int i = 0; i < 3; ++i)
        for (double s : {1.0, -1.0}) out.push_back(align(R_start, s * object.principal_axes.col(i), d_vis));
      break;
  }
  return out;
}

}  // namespace place_planner
