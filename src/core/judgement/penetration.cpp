#include "place_planner/judgement/penetration.h"

#include <algorithm>
#include <vector>

#include "place_planner/kernels/placement_kernels.h"

namespace place_planner {

Penetration penetration(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth, bool dense) {
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
  thread_local std::vector<double> nearest, depth;
  thread_local std::vector<int> hit;
  depth.assign(probes.size(), kInf);
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
      if (along > 0) depth[vi] = std::min(depth[vi], nearest[vi] * along);
    }
  }
  Penetration deepest;
  deepest.below = up;
  for (const double d : depth)
    if (d < kInf) deepest.depth = std::max(deepest.depth, d);
  return deepest;
}

double penetrationDepth(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth, bool dense) {
  return penetration(object, area, X_GO, max_depth, dense).depth;
}

}  // namespace place_planner
