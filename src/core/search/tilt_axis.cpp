#include "place_planner/search/tilt_axis.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace place_planner {

TiltAxis tiltAxis(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                  const Eigen::Vector3d& k1, const Eigen::Vector3d& d_g, double tol,
                  unsigned seed) {
  TiltAxis a;
  if (contacts.empty()) return a;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : contacts) c += p.p_W;
  c /= static_cast<double>(contacts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double spread = 0;
  for (const auto& p : contacts) {
    cov += (p.p_W - c) * (p.p_W - c).transpose();
    spread = std::max(spread, (p.p_W - c).norm());
  }
  a.s_A = c;
  // The centre of mass's offset from the contacts' middle, across gravity.
  const Eigen::Vector3d off_h = (com - c) - (com - c).dot(d_g) * d_g;
  constexpr double kLineAspect = 0.1;  // half-width / length of a line contact
  // Parallel test: sin of the angle below ~0.6 degrees.
  constexpr double kParallel = 1e-2;
  if (spread <= tol) {
    a.layout = ContactLayout::kSingle;
    // Hanging from one point (the centre of mass below it): it swings across its offset.
    if ((com - c).dot(d_g) > tol && off_h.norm() > 1e-6) {
      a.d_A = off_h.cross(d_g).normalized();
      return a;
    }
    Eigen::Vector3d axis = k1.cross(d_g);
    if (axis.norm() < kParallel) axis = (c - com).cross(d_g);
    if (axis.norm() < kParallel * std::max(1e-9, (c - com).norm())) {
      // Reproducible "random" axis perpendicular to d_g.
      const double phi = 2.0 * M_PI * ((seed * 2654435761u) % 1000u) / 1000.0;
      const Eigen::Vector3d u = d_g.unitOrthogonal(), w = d_g.cross(u).normalized();
      axis = std::cos(phi) * u + std::sin(phi) * w;
    }
    a.d_A = axis.normalized();
    return a;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  const Eigen::Vector3d dir = es.eigenvectors().col(2).normalized();
  double off = 0, lo = 0, hi = 0;
  for (const auto& p : contacts) {
    const Eigen::Vector3d r = p.p_W - c;
    off = std::max(off, (r - r.dot(dir) * dir).norm());
    lo = std::min(lo, r.dot(dir));
    hi = std::max(hi, r.dot(dir));
  }
  // A band of contacts much longer than wide is a line contact (a cylinder on its side): its
  // width comes from the contact tolerance on a curved surface, not from a support.
  if (off <= std::max(tol, kLineAspect * (hi - lo))) {
    a.layout = ContactLayout::kCollinear;
    a.d_A = dir;
    // The centre of mass beyond an end of the line, along it (a pen's foot in a cup's corner,
    // the cluster running towards its lean): it tips over that end, about the horizontal axis
    // across its offset, as from one point.
    const Eigen::Vector3d dir_h = dir - dir.dot(d_g) * d_g;
    const double along = off_h.dot(dir_h.normalized());
    if (dir_h.norm() > 0.5 && off_h.norm() > tol && std::abs(along) > std::cos(M_PI / 4) * off_h.norm() &&
        std::abs(along) > std::max(-lo, hi) * dir_h.norm() + tol) {
      a.layout = ContactLayout::kSingle;
      a.s_A = c + (along > 0 ? hi : lo) * dir;
      a.d_A = off_h.cross(d_g).normalized();
    }
    return a;
  }
  a.layout = ContactLayout::kIndependent;
  return a;
}

}  // namespace place_planner
