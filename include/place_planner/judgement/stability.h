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
};

enum class Failure { kNone, kSlide, kTip };

struct Stability {
  bool planar = false;     // all contacts on one plane P (the paper's planar case)
  bool stable = false;
  bool friction_ok = false;
  bool com_inside = false;
  double quality = -1.0;   // Q
  double tipping_angle = 0.0;                       // rad, tilt needed to tip over (planar)
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();  // of P, against gravity
  Failure failure = Failure::kTip;
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
// Non-planar case: the paper's heuristic (contacts whose normal lies in the friction cone about
// -d_g form Omega' and are tested like the planar case), then an equilibrium test: non-negative
// forces in the contacts' friction cones balance gravity, also with gravity tilted by half the
// friction angle (section "non-planar" in stability.cpp).
Stability evaluateStability(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                            const StabilityParams& params);

// Lawson-Hanson non-negative least squares: min |A x - b| with x >= 0. Returns the residual norm.
double nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd* x = nullptr);

// True when non-negative contact forces inside friction pyramids (4 edges, inscribed) balance
// the force `f_ext` applied at `com` (force and torque) with a total normal force of at most
// max_load |f_ext|: the least loaded balancing forces are found. Gravity alone loads a floor,
// a V-groove or a leaning support with about 1-1.5 times the weight; a wedge held between walls
// by squeeze needs at least |f_ext| / mu, so with the default bound of 2 (and mu <= 0.25) a
// statically indeterminate wedge is not accepted.
bool equilibrium(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                 const Eigen::Vector3d& f_ext, double friction, double length_scale,
                 double max_load = 2.0);

}  // namespace place_planner
