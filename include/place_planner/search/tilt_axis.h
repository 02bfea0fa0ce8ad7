// Tilt axis (Section V-C.1). Frame G (gravity d_g = -z unless stated).
#pragma once
#include <Eigen/Core>
#include <vector>

#include "place_planner/planner.h"

namespace place_planner {

enum class ContactLayout {
  kNone,         // no contact
  kSingle,       // all contacts within `tol` of one point
  kCollinear,    // all contacts within `tol` (or a tenth of their length) of one line
  kIndependent,  // at least three contacts not on one line: stop rotating (Section V-C)
};

struct TiltAxis {
  ContactLayout layout = ContactLayout::kNone;
  Eigen::Vector3d s_A = Eigen::Vector3d::Zero();  // point on the axis
  Eigen::Vector3d d_A = Eigen::Vector3d::UnitX(); // unit direction
};

// Classifies the contacts and, for one contact or collinear contacts, returns the rotation
// axis: one contact: k1 x d_g; when k1 is parallel to d_g, (contact - c_O) x d_g; when that is
// parallel too, an axis perpendicular to d_g chosen from `seed` (the paper's random axis,
// made reproducible). Collinear contacts: their line (through their centroid).
TiltAxis tiltAxis(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                  const Eigen::Vector3d& k1, const Eigen::Vector3d& d_g, double tol,
                  unsigned seed);

}  // namespace place_planner
