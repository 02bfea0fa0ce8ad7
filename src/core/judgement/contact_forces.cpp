// Contact forces (contact_forces.h).
#include "place_planner/judgement/contact_forces.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "place_planner/judgement/quality.h"

namespace place_planner {
namespace {

// A small weight on the total normal force: of all balancing forces NNLS finds the least
// loaded (a wedge's squeeze is not free), while the balance rows stay exact to ~1e-6.
constexpr double kLoadWeight = 1e-3;
constexpr int kBisections = 7;

// The contacts with the normal of their least-squares plane (turned like their mean normal) when
// all lie within tol of it and span it; else unchanged.
std::vector<ContactPoint> planarSupport(const std::vector<ContactPoint>& contacts, double tol) {
  if (contacts.size() < 3) return contacts;
  std::vector<Eigen::Vector3d> pts;
  Eigen::Vector3d nbar = Eigen::Vector3d::Zero();
  for (const ContactPoint& p : contacts) {
    pts.push_back(p.p_W);
    nbar += p.n_W;
  }
  const PlaneFit fit = fitPlane(pts);
  if (fit.off > tol || fit.spread <= tol) return contacts;
  const Eigen::Vector3d n = fit.normal.dot(nbar) < 0 ? Eigen::Vector3d(-fit.normal) : fit.normal;
  std::vector<ContactPoint> out = contacts;
  for (ContactPoint& p : out) p.n_W = n;
  return out;
}

// Lawson-Hanson NNLS on a matrix of R rows, the passive set's least squares on a fixed-capacity
// matrix (no heap allocation in the loop: the force model solves thousands per plan).
template <int R>
double nnlsRows(const Eigen::Ref<const Eigen::Matrix<double, R, Eigen::Dynamic>>& A,
                const Eigen::Matrix<double, R, 1>& b, Eigen::VectorXd* xout) {
  constexpr int kMaxPassive = 4 * R;
  const int n = static_cast<int>(A.cols());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<char> passive(n, 0);
  const double tol = 1e-10 * (1.0 + A.cwiseAbs().maxCoeff());
  Eigen::Matrix<double, R, Eigen::Dynamic, 0, R, kMaxPassive> Ap;
  std::array<int, kMaxPassive> P{};
  for (int outer = 0; outer < 3 * n + 10; ++outer) {
    const Eigen::Matrix<double, R, 1> r = b - A * x;
    int t = -1;
    double wmax = tol;
    for (int j = 0; j < n; ++j) {
      if (passive[j]) continue;
      const double w = A.col(j).dot(r);
      if (w > wmax) {
        wmax = w;
        t = j;
      }
    }
    if (t < 0) break;
    int np = 0;
    for (int j = 0; j < n; ++j) np += passive[j];
    if (np >= kMaxPassive) break;  // the basis is full: stop with the best so far
    passive[t] = 1;
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      np = 0;
      for (int j = 0; j < n; ++j)
        if (passive[j]) P[np++] = j;
      Ap.resize(R, np);
      for (int k = 0; k < np; ++k) Ap.col(k) = A.col(P[k]);
      const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxPassive, 1> zp = Ap.colPivHouseholderQr().solve(b);
      bool ok = true;
      for (int k = 0; k < np; ++k) ok = ok && zp[k] > 0;
      if (ok) {
        for (int k = 0; k < np; ++k) x[P[k]] = zp[k];
        break;
      }
      double alpha = 1.0;
      for (int k = 0; k < np; ++k)
        if (zp[k] <= 0) alpha = std::min(alpha, x[P[k]] / (x[P[k]] - zp[k]));
      for (int k = 0; k < np; ++k) {
        const int j = P[k];
        x[j] += alpha * (zp[k] - x[j]);
        if (x[j] <= tol) {
          passive[j] = 0;
          x[j] = 0;
        }
      }
    }
  }
  if (xout) *xout = x;
  return (A * x - b).norm();
}

}  // namespace

ContactForces::ContactForces(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                             const ForceModelParams& prm)
    : max_load_(prm.max_load), edges_(std::max(3, prm.cone_edges)) {
  const int edges = edges_;
  // Torques in units of force: divided by the contacts' reach from the centre of mass.
  double L = 1e-3;
  for (const ContactPoint& c : contacts) L = std::max(L, (c.p_W - com).norm());
  reach_ = L;
  A_.resize(7, edges * static_cast<long>(contacts.size()));
  for (size_t i = 0; i < contacts.size(); ++i) {
    const Eigen::Vector3d n = contacts[i].n_W.normalized();
    const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const Eigen::Vector3d r = contacts[i].p_W - com;
    for (int k = 0; k < edges; ++k) {
      const double phi = 2.0 * M_PI * k / edges;
      // Inscribed pyramid: its edges lie on the cone |f_t| = mu f_n.
      const Eigen::Vector3d f = (n + prm.friction * (std::cos(phi) * t1 + std::sin(phi) * t2)).normalized();
      const long col = edges * static_cast<long>(i) + k;
      A_.block<3, 1>(0, col) = f;
      A_.block<3, 1>(3, col) = r.cross(f) / L;
      A_(6, col) = kLoadWeight * f.dot(n);
    }
  }
}

bool ContactForces::balances(const Eigen::Vector3d& f_ext, Eigen::VectorXd* forces) const {
  if (A_.cols() == 0) return false;
  Eigen::Matrix<double, 7, 1> b = Eigen::Matrix<double, 7, 1>::Zero();
  Eigen::VectorXd x;
  b.head<3>() = -f_ext;
  nnlsRows<7>(A_, b, &x);
  if (forces) *forces = x;
  const double residual = (A_.topRows(6) * x - b.head<6>()).norm();
  const double load = A_.row(6).dot(x) / kLoadWeight;  // total normal force
  return residual < 1e-4 * f_ext.norm() && load <= max_load_ * f_ext.norm();
}

void ContactForces::unbalanced(const Eigen::Vector3d& f_ext, Eigen::Vector3d* v, Eigen::Vector3d* w,
                               const Eigen::VectorXd* forces) const {
  Eigen::Matrix<double, 7, 1> b = Eigen::Matrix<double, 7, 1>::Zero();
  b.head<3>() = -f_ext;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(A_.cols());
  if (forces && forces->size() == A_.cols()) x = *forces;
  else if (A_.cols() > 0) nnlsRows<7>(A_, b, &x);
  // The net wrench on the object: the contact forces plus f_ext (torque rows over reach_).
  const Eigen::Matrix<double, 6, 1> r = A_.topRows(6) * x - b.head<6>();
  const bool balanced = r.norm() < 1e-4 * f_ext.norm();
  *v = balanced ? Eigen::Vector3d::Zero() : Eigen::Vector3d(r.head<3>());
  *w = balanced ? Eigen::Vector3d::Zero() : Eigen::Vector3d(r.tail<3>() / reach_);
}

Eigen::Vector3d ContactForces::contactForce(const Eigen::VectorXd& forces, size_t i) const {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (int k = 0; k < edges_; ++k) {
    const long col = edges_ * static_cast<long>(i) + k;
    if (col < forces.size()) f += forces[col] * A_.block<3, 1>(0, col);
  }
  return f;
}

Eigen::Vector3d slipDirection(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                              const ForceModelParams& params, double mu_hold, bool known_unbalanced) {
  const Eigen::Vector3d g(0, 0, -1);
  if (!known_unbalanced && ContactForces(contacts, com, params).balances(g)) return Eigen::Vector3d::Zero();
  ForceModelParams wide = params;
  wide.friction = std::max(mu_hold, params.friction);
  const ContactForces held(contacts, com, wide);
  Eigen::VectorXd x;
  if (!held.balances(g, &x)) return Eigen::Vector3d::Zero();
  // Friction points against the motion it stops: the object slips against the excess.
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < contacts.size(); ++i) {
    const Eigen::Vector3d n = contacts[i].n_W.normalized();
    const Eigen::Vector3d f = held.contactForce(x, i);
    const double fn = f.dot(n);
    const Eigen::Vector3d t = f - fn * n;
    const double tn = t.norm();
    if (tn > params.friction * std::max(fn, 0.0) + 1e-9) d -= (1.0 - params.friction * std::max(fn, 0.0) / tn) * t;
  }
  d.z() = 0;
  return d.norm() > 1e-6 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::Zero();
}

double ContactForces::pushResistance(const Eigen::Vector3d& d, double cap) const {
  const Eigen::Vector3d g(0, 0, -1);
  if (!balances(g)) return 0.0;
  if (balances(g + cap * d)) return cap;
  double lo = 0.0, hi = cap;  // balanced at lo, not at hi
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    (balances(g + mid * d) ? lo : hi) = mid;
  }
  return lo;
}

PushResistance pushResistance(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                              const ForceModelParams& params, double cap, double plane_tol) {
  PushResistance r;
  const ContactForces forces(plane_tol > 0 ? planarSupport(contacts, plane_tol) : contacts, com, params);
  r.min = cap;
  for (int k = 0; k < kPushDirections; ++k) {
    const double phi = 2.0 * M_PI * k / kPushDirections;
    const Eigen::Vector3d d(std::cos(phi), std::sin(phi), 0.0);
    r.by_direction[k] = forces.pushResistance(d, cap);
    r.mean += r.by_direction[k] / kPushDirections;
    if (r.by_direction[k] < r.min) {
      r.min = r.by_direction[k];
      r.weakest = d;
    }
  }
  return r;
}

bool equilibrium(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                 const Eigen::Vector3d& f_ext, double friction, double max_load) {
  return ContactForces(contacts, com, ForceModelParams{friction, 8, max_load}).balances(f_ext);
}

}  // namespace place_planner
