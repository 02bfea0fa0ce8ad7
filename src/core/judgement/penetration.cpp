#include "place_planner/judgement/penetration.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "place_planner/kernels/placement_kernels.h"

namespace place_planner {

namespace {

// Each probe's depth (kInf: outside) and the normal of the surface it is deepest in; the
// deepest below a surface straight above in *up_out where given.
void probeDepths(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO, double max_depth, bool dense,
                 std::vector<double>& depth, std::vector<V3>& normal, double* up_out) {
  dense = dense && !object.probes.empty();  // none added: the vertices
  const std::vector<V3>& probes = dense ? object.probes : object.vertices;
  const BvhView obj = view(dense ? object.probe_bvh : object.vertex_bvh), tris = view(area.triangle_bvh);
  // Rays against gravity and along the four horizontal axes of G: a vertex inside a floor is
  // seen from below it, a vertex inside a wall or a post only sideways (straight up it meets
  // the post's top, far off, or nothing).
  const V3 dirs[5] = {v3(0, 0, 1), v3(1, 0, 0), v3(-1, 0, 0), v3(0, 1, 0), v3(0, -1, 0)};
  // Each vertex's nearest area triangle along each ray, within max_depth. One walk over the
  // object's vertex tree (posed, swept by max_depth) and the area's triangle tree
  // (dualTraverse) per ray instead of one ray from the root per vertex: about 3x faster.
  thread_local std::vector<double> nearest;
  thread_local std::vector<int> hit;
  depth.assign(probes.size(), kInf);
  normal.assign(probes.size(), v3(0, 0, 1));
  double up = 0;  // the deepest below a surface straight above
  for (int k = 0; k < 5; ++k) {
    const V3 dir = dirs[k];
    nearest.assign(probes.size(), max_depth);
    hit.assign(probes.size(), -1);
    dualTraverse(
        obj, tris, [&](const BvhNode& n) { return sweepBox(transformBox(X_GO, n.box), dir, max_depth); },
        [&](int vi) { return apply(X_GO, probes[vi]); },
        [&](const V3& v, int vi, int t) {
          const auto& tri = area.triangles[t];
          const double d = rayTriangle(v, dir, area.vertices[tri[0]], area.vertices[tri[1]], area.vertices[tri[2]]);
          if (d < nearest[vi]) {
            nearest[vi] = d;
            hit[vi] = t;
          }
        });
    // A ray whose first hit is a triangle's back (its normal along the ray) starts inside that
    // surface, by the hit distance times the normal's part along the ray: the depth along the
    // normal (the same on a floor; on a steep wall, a vertex a millimetre inside lies far below
    // the wall's surface straight above it). A vertex's depth is its least over the rays that
    // start inside: inside a post, the nearest side.
    for (size_t vi = 0; vi < hit.size(); ++vi) {
      if (hit[vi] < 0) continue;
      const V3& n = area.triangle_normals[hit[vi]];
      const double along = dot(n, dir) / std::max(1e-12, norm(n));
      if (k == 0 && along > 0) up = std::max(up, nearest[vi] * along);
      if (along > 0 && nearest[vi] * along < depth[vi]) {
        depth[vi] = nearest[vi] * along;
        normal[vi] = normalized(n);
      }
    }
  }
  if (up_out) *up_out = up;
}

}  // namespace

Penetration penetration(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth, bool dense) {
  thread_local std::vector<double> depth;
  thread_local std::vector<V3> normal;
  Penetration deepest;
  probeDepths(object, area, X_GO, max_depth, dense, depth, normal, &deepest.below);
  for (const double d : depth)
    if (d < kInf) deepest.depth = std::max(deepest.depth, d);
  return deepest;
}

std::optional<V3> clearingShift(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO, double gap,
                                 double max_shift, int max_steps) {
  constexpr double kInside = 1e-5;  // m: a probe this deep or less is on the surface, not in it
  thread_local std::vector<double> depth;
  thread_local std::vector<V3> normal;
  V3 shift = v3(0, 0, 0);
  for (int step = 0; step < max_steps; ++step) {
    Rigid X = X_GO;
    X.t = X.t + shift;
    probeDepths(object, area, X, 0.03, true, depth, normal, nullptr);
    size_t deepest = depth.size();
    for (size_t i = 0; i < depth.size(); ++i)
      if (depth[i] < kInf && depth[i] > kInside && (deepest == depth.size() || depth[i] > depth[deepest])) deepest = i;
    if (deepest == depth.size()) return shift;  // clear
    // Out of the deepest probe's surface along its normal, and `gap` beyond it.
    shift = shift + (depth[deepest] + gap) * normal[deepest];
    if (norm(shift) > max_shift) break;
  }
  return std::nullopt;
}

std::optional<Rigid> clearedPose(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                                 const V3& pivot, double gap, double max_shift) {
  auto shifted = [](Rigid X, const V3& s) {
    X.t = X.t + s;
    return X;
  };
  if (const std::optional<V3> s = clearingShift(object, area, X_GO, gap, max_shift)) return shifted(X_GO, *s);
  for (const double deg : {1.0, 2.0, 4.0})
    for (int a = 0; a < 6; ++a) {
      const Rigid Y = rotatedAbout(X_GO, toEigen(pivot), (a % 2 ? -1.0 : 1.0) * Eigen::Vector3d::Unit(a / 2), deg * M_PI / 180.0);
      if (const std::optional<V3> s = clearingShift(object, area, Y, gap, max_shift)) return shifted(Y, *s);
    }
  return std::nullopt;
}

double penetrationDepth(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth, bool dense) {
  return penetration(object, area, X_GO, max_depth, dense).depth;
}

}  // namespace place_planner
