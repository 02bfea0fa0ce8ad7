// Static stability (Section VI). Frame G: gravity is -z.
#pragma once
#include <Eigen/Core>
#include <vector>

#include "place_planner/planner.h"

namespace place_planner {

struct StabilityParams {
  double friction = 0.2;          // mu
  double tol = 0.003;             // m, contacts within tol of a plane are coplanar
  double min_tipping_angle = 0.2; // rad: a pose that tips over with less tilt is not stable
  double min_support_width = 0.0; // m: narrower support polygons (a wall top, a rim) do not hold
  double max_load = 3.0;          // contact forces: total normal force bound, in weights
};

enum class Failure { kNone, kSlide, kTip };

struct Stability {
  bool planar = false;     // all contacts on one plane P (the paper's planar case)
  bool stable = false;
  // Gravity alone is balanced by the contact forces (no margin): at rest if nothing lower is
  // near (the rock settle looks), though not stable.
  bool balanced = false;
  bool friction_ok = false;
  bool com_inside = false;
  double quality = -1.0;   // Q
  double tipping_angle = 0.0;                       // rad, tilt needed to tip over (planar)
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();  // of P, against gravity
  Failure failure = Failure::kTip;
  // Only friction fails (slipDirection, contact_forces.h): d_f is the horizontal slip. The tree
  // slides it before any turn: a marker's foot in a cup, a plate's on a rack's floor.
  bool slips = false;
  // ... down a surface steeper than the friction angle, on a line of contacts (d_f in the
  // surface, not horizontal): the tree slides it at most its own size at a time, and on past
  // where the surface ends (it falls from there), not only up to a contact.
  bool slips_downhill = false;
  // Every contact lies above the centre of mass: the object hangs (a ring on a peg, a mug by
  // its handle). Stable when the forces balance gravity and friction holds gravity tilted by
  // half the friction angle; a tilt's torque is taken by a swing (the tree's swing settle).
  bool hanging = false;
  // Hanging and not balanced: the rigid motion the unbalanced wrench starts
  // (ContactForces::unbalanced; the swing's settle move), translation v and rotation w about
  // the centre of mass, scaled so that a point at the contacts' reach moves 1 (|v| + |w| reach).
  Eigen::Vector3d settle_v = Eigen::Vector3d::Zero(), settle_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d d_f = Eigen::Vector3d::Zero();    // failure direction (unit)
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();  // farthest contact of Omega along d_f
  // Tipping: the edge of Omega that the centre of mass lies beyond (or is nearest to), as a
  // point and unit direction; zero direction when Omega is degenerate.
  Eigen::Vector3d tip_edge_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d tip_edge_dir = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> hull;                // Omega, on P
};

// Planar case: 2D convex hull Omega of the contacts on P, the centre of mass projected along
// gravity inside Omega, the angle between P's normal and -d_g below atan(mu), and (added for
// robustness) a tipping angle of at least min_tipping_angle and a support polygon at least
// min_support_width wide (checked in Bullet: objects balanced on 1 cm walls fall). Failure direction d_f =
// c^_O - c^_Omega (tipping) or down the slope (sliding).
// Non-planar case: the contact forces decide (contact_forces.h): non-negative forces in the
// contacts' friction cones balance gravity, also with gravity tilted by half the friction angle
// towards 4 directions; the paper's heuristic support polygon Omega' (contacts whose normal lies
// in the friction cone about -d_g) gives Q and the failure direction.
Stability evaluateStability(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                            const StabilityParams& params);

}  // namespace place_planner
