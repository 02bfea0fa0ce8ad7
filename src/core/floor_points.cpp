#include "place_planner/floor_points.h"

#include <algorithm>
#include <cmath>

namespace place_planner {
namespace {

std::vector<V3> castGrid(const AreaModel& area, const FloorPointParams& p, double spacing) {
  const V3 d = p.d_vis;
  const Eigen::Vector3d de = toEigen(d);
  const V3 u = toV3(de.unitOrthogonal());
  const V3 w = cross(d, u);
  // Extent of the area across the rays, and the start height before every vertex.
  double umin = kInf, umax = -kInf, wmin = kInf, wmax = -kInf, hmin = kInf;
  for (const V3& v : area.vertices) {
    umin = std::min(umin, dot(v, u));
    umax = std::max(umax, dot(v, u));
    wmin = std::min(wmin, dot(v, w));
    wmax = std::max(wmax, dot(v, w));
    hmin = std::min(hmin, dot(v, d));
  }
  const auto view = area.triangle_bvh.nodes.empty() ? BvhView{nullptr, nullptr, 0}
                                                    : BvhView{area.triangle_bvh.nodes.data(),
                                                              area.triangle_bvh.order.data(),
                                                              static_cast<int>(area.triangle_bvh.nodes.size())};
  const int nu = std::max(1, static_cast<int>(std::floor((umax - umin) / spacing)) + 1);
  const int nw = std::max(1, static_cast<int>(std::floor((wmax - wmin) / spacing)) + 1);
  // Centre the grid on the area.
  const double u0 = 0.5 * (umin + umax) - 0.5 * (nu - 1) * spacing;
  const double w0 = 0.5 * (wmin + wmax) - 0.5 * (nw - 1) * spacing;
  std::vector<V3> out;
  for (int j = 0; j < nw; ++j) {
    for (int i = 0; i < nu; ++i) {
      const V3 o = (u0 + i * spacing) * u + (w0 + j * spacing) * w + (hmin - 0.01) * d;
      const double t = bvhRay(view, o, d, kInf, [&](int k) {
        const auto& tri = area.triangles[k];
        return rayTriangle(o, d, area.vertices[tri[0]], area.vertices[tri[1]], area.vertices[tri[2]]);
      });
      if (t >= kInf) continue;
      const V3 hit = o + t * d;
      if (p.has_region && (hit.x < p.region_lo.x || hit.y < p.region_lo.y || hit.z < p.region_lo.z ||
                           hit.x > p.region_hi.x || hit.y > p.region_hi.y || hit.z > p.region_hi.z))
        continue;
      out.push_back(hit);
    }
  }
  return out;
}

}  // namespace

FloorPoints floorPoints(const AreaModel& area, const FloorPointParams& p) {
  FloorPoints fp;
  double spacing = p.spacing;
  for (int refine = 0; refine <= 6; ++refine, spacing *= 0.5) {
    fp.points = castGrid(area, p, spacing);
    fp.spacing = spacing;
    if (static_cast<int>(fp.points.size()) >= p.min_points) break;
  }
  if (p.lowest_n > 0 && static_cast<int>(fp.points.size()) > p.lowest_n) {
    // Lowest along gravity (-z in G); stable sort keeps grid order among equals.
    std::vector<V3> pts = fp.points;
    std::stable_sort(pts.begin(), pts.end(), [](const V3& a, const V3& b) { return a.z < b.z; });
    pts.resize(p.lowest_n);
    fp.points = pts;
  }
  return fp;
}

}  // namespace place_planner
