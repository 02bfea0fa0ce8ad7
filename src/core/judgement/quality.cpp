#include "place_planner/judgement/quality.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace place_planner {
namespace {
double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}
}  // namespace

PlaneFit fitPlane(const std::vector<Eigen::Vector3d>& pts) {
  PlaneFit f;
  if (pts.empty()) return f;
  for (const auto& p : pts) f.centroid += p;
  f.centroid /= static_cast<double>(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) cov += (p - f.centroid) * (p - f.centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  f.normal = es.eigenvectors().col(0).normalized();
  f.second = es.eigenvectors().col(1).normalized();
  for (const auto& p : pts) {
    f.off = std::max(f.off, std::abs((p - f.centroid).dot(f.normal)));
    f.spread = std::max(f.spread, std::abs((p - f.centroid).dot(f.second)));
  }
  return f;
}

std::vector<Eigen::Vector2d> convexHull2d(std::vector<Eigen::Vector2d> p) {
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  std::vector<Eigen::Vector2d> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross2(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

double polygonArea(const std::vector<Eigen::Vector2d>& h) {
  double a = 0;
  for (size_t i = 0; i < h.size(); ++i) {
    const auto& p = h[i];
    const auto& q = h[(i + 1) % h.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

Eigen::Vector2d polygonCentroid(const std::vector<Eigen::Vector2d>& h) {
  const double a = polygonArea(h);
  if (h.size() < 3 || std::abs(a) < 1e-18) {
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const auto& p : h) c += p;
    return h.empty() ? c : Eigen::Vector2d(c / static_cast<double>(h.size()));
  }
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < h.size(); ++i) {
    const auto& p = h[i];
    const auto& q = h[(i + 1) % h.size()];
    const double w = p.x() * q.y() - q.x() * p.y();
    c += (p + q) * w;
  }
  return c / (6.0 * a);
}

double signedBoundaryDistance(const std::vector<Eigen::Vector2d>& h, const Eigen::Vector2d& p) {
  if (h.size() < 3) return -std::numeric_limits<double>::infinity();
  double inside = std::numeric_limits<double>::infinity();
  double outside = 0;
  bool out = false;
  for (size_t i = 0; i < h.size(); ++i) {
    const Eigen::Vector2d& a = h[i];
    const Eigen::Vector2d& b = h[(i + 1) % h.size()];
    const Eigen::Vector2d e = b - a;
    const double len = e.norm();
    const double d = cross2(a, b, p) / len;  // > 0: left of a CCW edge = inside
    inside = std::min(inside, d);
    if (d < 0) {
      out = true;
      const double t = std::clamp((p - a).dot(e) / (len * len), 0.0, 1.0);
      const double dist = (p - (a + t * e)).norm();
      outside = outside == 0 ? dist : std::min(outside, dist);
    }
  }
  return out ? -outside : inside;
}

double polygonWidth(const std::vector<Eigen::Vector2d>& h) {
  if (h.size() < 3) return 0.0;
  double width = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < h.size(); ++i) {
    const Eigen::Vector2d a = h[i], e = (h[(i + 1) % h.size()] - a).normalized();
    double far = 0;
    for (const auto& p : h) far = std::max(far, std::abs(e.x() * (p - a).y() - e.y() * (p - a).x()));
    width = std::min(width, far);
  }
  return width;
}

double boundaryDistanceAlong(const std::vector<Eigen::Vector2d>& h, const Eigen::Vector2d& from,
                             const Eigen::Vector2d& dir) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < h.size(); ++i) {
    const Eigen::Vector2d a = h[i], e = h[(i + 1) % h.size()] - h[i];
    // from + t dir = a + s e
    const double den = dir.x() * e.y() - dir.y() * e.x();
    if (std::abs(den) < 1e-18) continue;
    const Eigen::Vector2d r = a - from;
    const double t = (r.x() * e.y() - r.y() * e.x()) / den;
    const double s = (r.x() * dir.y() - r.y() * dir.x()) / den;
    if (t >= 0 && s >= -1e-12 && s <= 1 + 1e-12) best = std::min(best, t);
  }
  return best;
}

double quality(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& c_hat_O, double h) {
  const double area = std::abs(polygonArea(hull));
  if (hull.size() < 3 || area < 1e-12) return -1.0;
  const Eigen::Vector2d c = polygonCentroid(hull);
  const Eigen::Vector2d off = c_hat_O - c;
  double term1 = 0;
  if (off.norm() > 1e-12) {
    const double l = boundaryDistanceAlong(hull, c, off.normalized());  // l^_Omega
    term1 = off.norm() / std::max(l, 1e-12);
  }
  const double ratio = std::max(0.0, h) / std::sqrt(area);
  const double s = ratio * ratio / 16.0;
  return 1.0 - term1 - s / (1.0 + s);
}

}  // namespace place_planner
