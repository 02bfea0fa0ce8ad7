// Exact clearance between the gripper and the area (gripper.h): triangle against triangle,
// the area's triangles found through its BVH. Host code: a handful of gripper triangles per
// candidate pose, a few dozen poses per candidate.
#include <algorithm>
#include <cmath>

#include "place_planner/manipulation/gripper.h"

namespace place_planner {
namespace {

using E3 = Eigen::Vector3d;

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
E3 closestOnTriangle(const E3& p, const E3& a, const E3& b, const E3& c) {
  const E3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const E3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const E3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Squared distance between segments p1q1 and p2q2 (Ericson 5.1.9).
double segmentDistance2(const E3& p1, const E3& q1, const E3& p2, const E3& q2) {
  const E3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 1e-30 && e <= 1e-30) return r.squaredNorm();
  if (a <= 1e-30) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 1e-30) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-30 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) t = 0, s = std::clamp(-c / a, 0.0, 1.0);
      else if (t > 1) t = 1, s = std::clamp((b - c) / a, 0.0, 1.0);
    }
  }
  return (p1 + s * d1 - (p2 + t * d2)).squaredNorm();
}

// Does segment pq cross triangle abc (Moller-Trumbore on the segment's parameter range)?
bool segmentCrossesTriangle(const E3& p, const E3& q, const E3& a, const E3& b, const E3& c) {
  const E3 d = q - p, e1 = b - a, e2 = c - a, h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-30) return false;
  const double inv = 1.0 / det;
  const E3 s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0 || u > 1) return false;
  const E3 qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0 || u + v > 1) return false;
  const double t = inv * e2.dot(qv);
  return t >= 0 && t <= 1;
}

double triangleDistance(const E3 A[3], const E3 B[3]) {
  for (int i = 0; i < 3; ++i) {
    if (segmentCrossesTriangle(A[i], A[(i + 1) % 3], B[0], B[1], B[2])) return 0.0;
    if (segmentCrossesTriangle(B[i], B[(i + 1) % 3], A[0], A[1], A[2])) return 0.0;
  }
  double d2 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    d2 = std::min(d2, (A[i] - closestOnTriangle(A[i], B[0], B[1], B[2])).squaredNorm());
    d2 = std::min(d2, (B[i] - closestOnTriangle(B[i], A[0], A[1], A[2])).squaredNorm());
    for (int j = 0; j < 3; ++j) d2 = std::min(d2, segmentDistance2(A[i], A[(i + 1) % 3], B[j], B[(j + 1) % 3]));
  }
  return std::sqrt(d2);
}

}  // namespace

double gripperClearance(const GripperModel& g, const Eigen::Isometry3d& X_GF, const AreaModel& area, double cap) {
  const BvhView bvh = view(area.triangle_bvh);
  double best = cap;
  for (const auto& t : g.triangles) {
    const E3 A[3] = {X_GF * g.vertices_F[t[0]], X_GF * g.vertices_F[t[1]], X_GF * g.vertices_F[t[2]]};
    Aabb box = aabbEmpty();
    for (const E3& p : A) aabbAdd(box, toV3(p));
    // Only area triangles within the best distance so far can lower it.
    bvhQuery(bvh, aabbInflate(box, best), [&](int k) {
      if (best <= 0) return;
      const auto& f = area.triangles[k];
      const E3 B[3] = {toEigen(area.vertices[f[0]]), toEigen(area.vertices[f[1]]), toEigen(area.vertices[f[2]])};
      best = std::min(best, triangleDistance(A, B));
    });
    if (best <= 0) return 0.0;
  }
  return best;
}

}  // namespace place_planner
