// Contact forces (beyond the paper, which calls its Omega'/Omega'' test a heuristic "for want of
// contact forces"): static equilibrium of a rigid object on point contacts with Coulomb
// friction, and the largest horizontal push the contacts resist. Frame G: gravity is -z, the
// weight is 1 (forces are in weights).
//
// The model: each contact i at p_i with unit normal n_i (pointing at the object) carries a force
// f_i = sum_k lambda_ik e_ik, lambda_ik >= 0, where e_ik are the edges of the friction cone
// |f_t| <= mu f_n linearised by an inscribed pyramid of `cone_edges` edges (conservative: the
// pyramid's smallest friction is mu cos(pi / edges)). The forces balance an external force
// f_ext applied at the centre of mass c when
//     sum f_i = -f_ext   and   sum (p_i - c) x f_i = 0,
// found by non-negative least squares (Lawson-Hanson) on the 6 x (edges * contacts) wrench
// matrix with one row more that weighs the total normal force: of all balancing forces the
// least loaded is found. Its total normal force must stay within max_load |f_ext|: gravity loads a
// floor with the weight, a V-groove of walls at a from the horizontal with about 1 / cos(a)
// (2.9 at 70 degrees without friction, less with it), while forces that only a squeeze makes
// (a body held between parallel walls needs at least 1 / mu) have no such bound and are not
// relied on. Solver choice: see doc/method.md ("Contact forces").
#pragma once
#include <Eigen/Core>
#include <array>
#include <vector>

#include "place_planner/planner.h"

namespace place_planner {

struct ForceModelParams {
  double friction = 0.2;  // mu
  int cone_edges = 8;     // edges of the inscribed friction pyramid (>= 3)
  double max_load = 3.0;  // bound on the total normal force, in |f_ext|
};

class ContactForces {
 public:
  ContactForces(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                const ForceModelParams& params);
  // True when non-negative forces in the cones balance f_ext at the centre of mass within
  // max_load |f_ext|; `forces`: the cone-edge weights found (edges * contacts).
  bool balances(const Eigen::Vector3d& f_ext, Eigen::VectorXd* forces = nullptr) const;
  // The largest push alpha in [0, cap] (in weights) along the horizontal unit direction d that
  // the contacts resist together with gravity: balances(-z + alpha d), by bisection to cap / 2^7.
  // 0 when gravity alone is not balanced.
  double pushResistance(const Eigen::Vector3d& d, double cap = 1.0) const;
  // Where gravity (f_ext) is not balanced: the net wrench that is left when the contacts push
  // as well as they can (the NNLS residual), as the rigid motion it starts, frame G: a
  // translation direction v (weights) and a rotation w (rad per metre of v: a point at the
  // contacts' reach moves |w| reach). It never pushes a contact into its surface (the NNLS
  // optimality: every cone edge's velocity is >= 0) and gravity does work along it (the
  // centre of mass sinks), so it is the first-order settle. Zero when balanced.
  // `forces`: balances()'s cone-edge weights for the same f_ext, when solved already (not again).
  void unbalanced(const Eigen::Vector3d& f_ext, Eigen::Vector3d* v, Eigen::Vector3d* w,
                  const Eigen::VectorXd* forces = nullptr) const;
  bool empty() const { return A_.cols() == 0; }
  // The force on contact i (G, weights) of the cone-edge weights `forces` (balances()).
  Eigen::Vector3d contactForce(const Eigen::VectorXd& forces, size_t i) const;

 private:
  Eigen::Matrix<double, 7, Eigen::Dynamic> A_;  // rows: force (3), torque / L (3), load weight (1)
  double max_load_;
  double reach_ = 1e-3;  // m: torques are divided by it (A_'s rows 3-5)
  int edges_ = 8;
};

// Push resistance over kPushDirections horizontal directions of G, k * 45 degrees from +x.
constexpr int kPushDirections = 8;
struct PushResistance {
  double min = 0.0;   // weights: the smallest over the directions
  double mean = 0.0;  // weights: their mean
  std::array<double, kPushDirections> by_direction{};
  Eigen::Vector3d weakest = Eigen::Vector3d::UnitX();  // direction (G) of the smallest
};
// Contacts within plane_tol (m) of one plane are taken as a planar support: their normals are
// the plane's (the planner's contact normals blend the object's and the area's, and on a flat
// area an object's rounded edge would tilt them into a shallow V that seems to resist a push).
PushResistance pushResistance(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                              const ForceModelParams& params, double cap = 1.0, double plane_tol = 0.0);

// Slipping: when gravity is not balanced with the friction of `params` but is with friction
// mu_hold (wide cones: the geometry would hold the object, its friction does not), the
// horizontal unit direction (G) it slips in: against the friction the wide cones use beyond
// mu, summed over the contacts (a plate leaning on a peg, its foot kicking out). Zero when it
// does not slip so (balanced, or not even with mu_hold: it tips or falls).
// known_unbalanced: the caller found gravity not balanced with params already (skips that test).
Eigen::Vector3d slipDirection(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                              const ForceModelParams& params, double mu_hold = 1.0, bool known_unbalanced = false);

// One-call form of ContactForces::balances (kept for the tests of the earlier API): the default
// 8-edge cone, max_load as given.
bool equilibrium(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                 const Eigen::Vector3d& f_ext, double friction, double max_load = 3.0);

}  // namespace place_planner
