#include "place_planner/penetration.h"

#include <algorithm>

namespace place_planner {

double penetrationDepth(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth) {
  const BvhView bvh = view(area.triangle_bvh);
  const V3 up = v3(0, 0, 1);
  double deepest = 0;
  for (const V3& v_O : object.vertices) {
    const V3 v = apply(X_GO, v_O);
    int hit_tri = -1;
    double best = max_depth;
    bvhRay(bvh, v, up, max_depth, [&](int k) {
      const auto& t = area.triangles[k];
      const double d = rayTriangle(v, up, area.vertices[t[0]], area.vertices[t[1]], area.vertices[t[2]]);
      if (d < best) {
        best = d;
        hit_tri = k;
      }
      return d;
    });
    if (hit_tri >= 0 && dot(area.triangle_normals[hit_tri], up) > 0) deepest = std::max(deepest, best);
  }
  return deepest;
}

}  // namespace place_planner
