#include "place_planner/judgement/stability.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "place_planner/judgement/quality.h"

namespace place_planner {
namespace {

const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();  // -d_g in G

// Least-squares plane of points: their centroid and the eigen decomposition of their scatter
// (smallest eigenvector first: the normal).
struct PlaneFit {
  Eigen::Vector3d centroid;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
};
PlaneFit fitPlane(const std::vector<Eigen::Vector3d>& pts) {
  PlaneFit f;
  f.centroid = Eigen::Vector3d::Zero();
  for (const auto& p : pts) f.centroid += p;
  f.centroid /= static_cast<double>(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) cov += (p - f.centroid) * (p - f.centroid).transpose();
  f.eigen.compute(cov);
  return f;
}

// 2D analysis of a support polygon in the plane through `origin` with normal `n` (unit),
// centre of mass projected along gravity (-z).
struct Support {
  bool valid = false;
  std::vector<Eigen::Vector2d> hull2;
  std::vector<Eigen::Vector3d> hull3;
  Eigen::Vector2d c_hat_O, c_omega;
  double inside = 0, h = 0, quality = -1, tip = 0;
  Eigen::Vector3d u, w, origin, n;
};

// The 2D hull of pts in the plane through `origin` with normal n (basis u, w); false when it is
// degenerate (fewer than 3 points off one line).
bool projectHull(Support& s, const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& n) {
  s.origin = origin;
  s.n = n;
  s.u = n.unitOrthogonal();
  s.w = n.cross(s.u);
  std::vector<Eigen::Vector2d> p2;
  for (const auto& p : pts) p2.emplace_back((p - origin).dot(s.u), (p - origin).dot(s.w));
  s.hull2 = convexHull2d(p2);
  return s.hull2.size() >= 3 && std::abs(polygonArea(s.hull2)) >= 1e-10;
}

Support analyse(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& origin,
                const Eigen::Vector3d& n, const Eigen::Vector3d& com) {
  Support s;
  if (!projectHull(s, pts, origin, n)) return s;
  // c^_O: the centre of mass projected along gravity onto P.
  const double den = -kUp.dot(n);
  if (std::abs(den) < 1e-9) return s;
  const double t = (origin - com).dot(n) / den;
  const Eigen::Vector3d proj = com - t * kUp;
  s.c_hat_O = Eigen::Vector2d((proj - origin).dot(s.u), (proj - origin).dot(s.w));
  s.c_omega = polygonCentroid(s.hull2);
  s.h = std::abs((com - origin).dot(n));
  s.inside = signedBoundaryDistance(s.hull2, s.c_hat_O);
  s.tip = std::atan2(s.inside, std::max(s.h, 1e-9));
  s.quality = quality(s.hull2, s.c_hat_O, s.h);
  for (const auto& q : s.hull2) s.hull3.push_back(origin + q.x() * s.u + q.y() * s.w);
  s.valid = true;
  return s;
}

// Failure direction in 3D from a support: away from the hull centre, or (centred but too close
// to an edge) outward through the nearest edge.
Eigen::Vector3d tipDirection(const Support& s) {
  Eigen::Vector2d d = s.c_hat_O - s.c_omega;
  if (d.norm() < 1e-6) {
    double best = 1e300;
    for (size_t i = 0; i < s.hull2.size(); ++i) {
      const Eigen::Vector2d a = s.hull2[i], e = s.hull2[(i + 1) % s.hull2.size()] - a;
      const Eigen::Vector2d outward(e.y(), -e.x());
      const double dist = (a - s.c_hat_O).dot(outward.normalized());
      if (dist < best) {
        best = dist;
        d = outward;
      }
    }
  }
  const Eigen::Vector3d d3 = d.x() * s.u + d.y() * s.w;
  Eigen::Vector3d h = d3 - d3.dot(kUp) * kUp;  // rotations tip about horizontal axes
  if (h.norm() < 1e-9) h = d3;
  return h.normalized();
}

// The hull edge crossed by the ray from c_Omega through c^_O (or the nearest edge when they
// coincide), in 3D.
void tipEdge(const Support& s, Eigen::Vector3d* point, Eigen::Vector3d* dir) {
  const size_t n = s.hull2.size();
  if (n < 3) return;
  Eigen::Vector2d d = s.c_hat_O - s.c_omega;
  size_t best_i = 0;
  double best = 1e300;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d a = s.hull2[i], e = s.hull2[(i + 1) % n] - a;
    double key;
    if (d.norm() > 1e-9) {
      const double den = d.x() * e.y() - d.y() * e.x();
      if (std::abs(den) < 1e-18) continue;
      const Eigen::Vector2d r = a - s.c_omega;
      const double t = (r.x() * e.y() - r.y() * e.x()) / den;
      const double u = (r.x() * d.y() - r.y() * d.x()) / den;
      if (t < 0 || u < -1e-9 || u > 1 + 1e-9) continue;
      key = t;
    } else {
      key = std::abs((a - s.c_hat_O).x() * e.y() - (a - s.c_hat_O).y() * e.x()) / e.norm();
    }
    if (key < best) {
      best = key;
      best_i = i;
    }
  }
  *point = s.hull3[best_i];
  *dir = (s.hull3[(best_i + 1) % n] - s.hull3[best_i]).normalized();
}

Eigen::Vector3d farthest(const std::vector<ContactPoint>& c, const Eigen::Vector3d& d) {
  Eigen::Vector3d best = c.front().p_W;
  for (const auto& p : c)
    if (p.p_W.dot(d) > best.dot(d)) best = p.p_W;
  return best;
}

}  // namespace

double nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd* xout) {
  const int n = static_cast<int>(A.cols());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(n, false);
  const double tol = 1e-10 * (1.0 + A.cwiseAbs().maxCoeff());
  for (int outer = 0; outer < 3 * n + 10; ++outer) {
    Eigen::VectorXd w = A.transpose() * (b - A * x);
    int t = -1;
    double wmax = tol;
    for (int j = 0; j < n; ++j)
      if (!passive[j] && w[j] > wmax) {
        wmax = w[j];
        t = j;
      }
    if (t < 0) break;
    passive[t] = true;
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      std::vector<int> P;
      for (int j = 0; j < n; ++j)
        if (passive[j]) P.push_back(j);
      Eigen::MatrixXd Ap(A.rows(), P.size());
      for (size_t k = 0; k < P.size(); ++k) Ap.col(k) = A.col(P[k]);
      const Eigen::VectorXd zp = Ap.colPivHouseholderQr().solve(b);
      Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
      bool ok = true;
      for (size_t k = 0; k < P.size(); ++k) {
        z[P[k]] = zp[k];
        if (zp[k] <= 0) ok = false;
      }
      if (ok) {
        x = z;
        break;
      }
      double alpha = 1.0;
      for (int j : P)
        if (z[j] <= 0) alpha = std::min(alpha, x[j] / (x[j] - z[j]));
      x += alpha * (z - x);
      for (int j : P)
        if (x[j] <= tol) {
          passive[j] = false;
          x[j] = 0;
        }
    }
  }
  if (xout) *xout = x;
  return (A * x - b).norm();
}

bool equilibrium(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                 const Eigen::Vector3d& f_ext, double friction, double L, double max_load) {
  if (contacts.empty()) return false;
  // Inscribed 4-edge pyramid: conservative against the true cone.
  const double mu = friction / std::sqrt(2.0);
  const int m = static_cast<int>(4 * contacts.size());
  // Rows: force (3), torque (3), and a small weight on the total normal force, so that of all
  // balancing forces the least loaded is found (a wedge's squeeze is not free).
  constexpr double kLoadWeight = 1e-3;
  Eigen::MatrixXd A(7, m);
  for (size_t i = 0; i < contacts.size(); ++i) {
    const Eigen::Vector3d n = contacts[i].n_W.normalized();
    const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const Eigen::Vector3d r = contacts[i].p_W - com;
    const Eigen::Vector3d e[4] = {n + mu * (t1 + t2), n + mu * (t1 - t2), n - mu * (t1 + t2),
                                  n - mu * (t1 - t2)};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d f = e[k].normalized();
      A.block<3, 1>(0, 4 * i + k) = f;
      A.block<3, 1>(3, 4 * i + k) = r.cross(f) / L;  // torques in units of force
      A(6, 4 * i + k) = kLoadWeight * f.dot(n);
    }
  }
  Eigen::VectorXd b = Eigen::VectorXd::Zero(7), x;
  b.head<3>() = -f_ext;
  nnls(A, b, &x);
  const double residual = (A.topRows(6) * x - b.head<6>()).norm();
  const double load = A.row(6).dot(x) / kLoadWeight;  // sum of normal forces
  return residual < 1e-4 * f_ext.norm() && load <= max_load * f_ext.norm();
}

// Support polygon of `pts` seen along `dir` (a plane through the centre of mass with normal
// dir), with the centre of mass inside-test; the 2D analysis of analyse() without gravity.
Support analyse2(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& dir,
                 const Eigen::Vector3d& com) {
  Support s;
  if (!projectHull(s, pts, com, dir)) return s;
  s.c_hat_O = Eigen::Vector2d::Zero();
  s.inside = signedBoundaryDistance(s.hull2, s.c_hat_O);
  s.valid = true;
  return s;
}

Stability evaluateStability(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                            const StabilityParams& prm) {
  Stability r;
  if (contacts.empty()) return r;
  const double cone = std::atan(prm.friction);
  // ---------------------------------------------------------------- planar case
  std::vector<Eigen::Vector3d> pts;
  for (const auto& p : contacts) pts.push_back(p.p_W);
  const PlaneFit fit = fitPlane(pts);
  const Eigen::Vector3d& c = fit.centroid;
  const auto& es = fit.eigen;
  Eigen::Vector3d n = es.eigenvectors().col(0).normalized();
  if (n.dot(kUp) < 0) n = -n;
  double off = 0, spread2 = 0;
  const Eigen::Vector3d second = es.eigenvectors().col(1).normalized();
  for (const auto& p : pts) {
    off = std::max(off, std::abs((p - c).dot(n)));
    spread2 = std::max(spread2, std::abs((p - c).dot(second)));
  }
  // Planar: on one plane and spanning it (contacts on a line lie on every plane through it).
  // The contacts must push the object up: their mean normal (pointing at the object) against
  // gravity. Contacts from above (an object pressed under a table) never support it.
  Eigen::Vector3d nbar = Eigen::Vector3d::Zero();
  for (const auto& p : contacts) nbar += p.n_W;
  const bool from_below = nbar.dot(kUp) > 0;
  if (off <= prm.tol && spread2 > prm.tol && n.dot(kUp) > 1e-3) {
    r.planar = true;
    r.plane_normal = n;
    const Support s = analyse(pts, c, n, com);
    if (!s.valid) return r;  // collinear: the tree rotates further
    r.hull = s.hull3;
    r.quality = s.quality;
    r.tipping_angle = s.tip;
    r.com_inside = s.inside >= 0;
    r.friction_ok = std::acos(std::clamp(n.dot(kUp), -1.0, 1.0)) < cone;  // angle(P, -d_g) < atan(mu)
    r.stable = from_below && r.friction_ok && r.com_inside && s.tip >= prm.min_tipping_angle && s.quality >= 0.3 &&
               polygonWidth(s.hull2) >= prm.min_support_width;
    if (r.stable) {
      r.failure = Failure::kNone;
    } else if (!r.friction_ok) {
      r.failure = Failure::kSlide;
      const Eigen::Vector3d down = -kUp - (-kUp).dot(n) * n;  // d_g projected onto P
      r.d_f = down.normalized();
    } else {
      r.failure = Failure::kTip;
      r.d_f = tipDirection(s);
      tipEdge(s, &r.tip_edge_point, &r.tip_edge_dir);
    }
    r.pivot = farthest(contacts, r.d_f);
    return r;
  }
  // ---------------------------------------------------------------- non-planar case
  // Paper's heuristic, first step: contacts whose normal lies in the friction cone about -d_g
  // support like a floor; their support polygon Omega' is tested as in the planar case.
  std::vector<Eigen::Vector3d> below;
  double zmin = 1e300;
  for (const auto& p : contacts) {
    zmin = std::min(zmin, p.p_W.z());
    if (std::acos(std::clamp(p.n_W.dot(kUp), -1.0, 1.0)) < cone) below.push_back(p.p_W);
  }
  Support s1;
  if (below.size() >= 3) {
    Eigen::Vector3d cb = Eigen::Vector3d::Zero();
    for (const auto& p : below) cb += p;
    cb /= static_cast<double>(below.size());
    s1 = analyse(below, cb, kUp, com);
  }
  // The projected support of all contacts ranks non-planar poses.
  const Support all = analyse(pts, Eigen::Vector3d(c.x(), c.y(), zmin), kUp, com);
  const Support& ref = s1.valid ? s1 : all;
  if (ref.valid) {
    r.hull = ref.hull3;
    r.tipping_angle = ref.tip;
    r.quality = ref.quality;
    r.com_inside = ref.inside >= 0;
  }
  bool stable = s1.valid && s1.inside >= 0 && s1.tip >= prm.min_tipping_angle && s1.quality >= 0.3 &&
                polygonWidth(s1.hull2) >= prm.min_support_width;
  if (!stable && !below.empty()) {
    // Paper's heuristic, second step: the object would move along d'_f = c_O - c(Omega')
    // (horizontal); contacts whose normal opposes d'_f catch it. With gravity replaced by
    // d'_f, the supporting contacts (below and opposing) form Omega''; the centre of mass
    // must project into it along d'_f (a pen leaning from a cup's floor against its rim).
    Eigen::Vector3d cb = Eigen::Vector3d::Zero();
    for (const auto& p : below) cb += p;
    cb /= static_cast<double>(below.size());
    Eigen::Vector3d df = com - cb;
    df.z() = 0;
    if (df.norm() > 1e-6) {
      df.normalize();
      // Opposing contacts: normal within the friction cone about -d'_f (the paper's condition).
      std::vector<Eigen::Vector3d> support = below;
      int opposing = 0;
      for (const auto& p : contacts)
        if (p.n_W.dot(-df) > std::cos(cone)) {
          support.push_back(p.p_W);
          ++opposing;
        }
      if (opposing > 0) {
        const Support s2 = analyse2(support, df, com);
        // Omega'' must face d'_f or the floor within the friction angle (the paper's test):
        // the normal of the plane through its contacts.
        const auto& es2 = fitPlane(support).eigen;
        const Eigen::Vector3d n2 = es2.eigenvectors().col(0);
        const bool spans = es2.eigenvalues()(1) > prm.tol * prm.tol;
        const double to_df = std::acos(std::min(1.0, std::abs(n2.dot(df))));
        const double to_up = std::acos(std::min(1.0, std::abs(n2.dot(kUp))));
        stable = s2.valid && s2.inside >= 0 && spans && std::min(to_df, to_up) < cone;
      }
    }
  }
  if (!stable) {
    // Equilibrium: forces within the friction cones balance gravity, also with gravity tilted
    // by half the friction angle in four directions (a margin against sliding and tipping).
    const double L = std::max(1e-3, (com - c).norm());
    const double tilt = 0.5 * cone;
    stable = equilibrium(contacts, com, -kUp, prm.friction, L);
    for (int k = 0; k < 4 && stable; ++k) {
      const double phi = k * M_PI / 2;
      const Eigen::Vector3d g(std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi),
                              -std::cos(tilt));
      stable = equilibrium(contacts, com, g, prm.friction, L);
    }
  }
  // One contact or a line of contacts never holds (a ball rolls, a cylinder turns about it).
  if (spread2 <= 0.1 * prm.tol) stable = false;
  r.friction_ok = stable;
  r.stable = stable;
  if (stable) {
    r.failure = Failure::kNone;
    r.quality = std::max(r.quality, 0.3);  // Q is a ranking here; equilibrium decided stability
  } else {
    r.failure = Failure::kTip;
    r.d_f = ref.valid ? tipDirection(ref) : Eigen::Vector3d::UnitX();
    if (ref.valid) tipEdge(ref, &r.tip_edge_point, &r.tip_edge_dir);
  }
  r.pivot = farthest(contacts, r.d_f);
  return r;
}

}  // namespace place_planner
