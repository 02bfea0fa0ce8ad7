#include "place_planner/search/floor_points.h"

#include <algorithm>
#include <cmath>

namespace place_planner {
namespace {

// The rays' frame: d_vis and two directions across it, the area's extent across the rays and
// the start height before every vertex.
struct RayFrame {
  V3 d, u, w;
  double umin = kInf, umax = -kInf, wmin = kInf, wmax = -kInf, hmin = kInf;
  explicit RayFrame(const AreaModel& area, const V3& d_vis) : d(d_vis) {
    u = toV3(toEigen(d).unitOrthogonal());
    w = cross(d, u);
    for (const V3& v : area.vertices) {
      umin = std::min(umin, dot(v, u));
      umax = std::max(umax, dot(v, u));
      wmin = std::min(wmin, dot(v, w));
      wmax = std::max(wmax, dot(v, w));
      hmin = std::min(hmin, dot(v, d));
    }
  }
  int nu(double spacing) const { return std::max(1, static_cast<int>(std::floor((umax - umin) / spacing)) + 1); }
  int nw(double spacing) const { return std::max(1, static_cast<int>(std::floor((wmax - wmin) / spacing)) + 1); }
  double rays(double spacing) const { return static_cast<double>(nu(spacing)) * nw(spacing); }
};

std::vector<V3> castGrid(const AreaModel& area, const FloorPointParams& p, const RayFrame& f, double spacing,
                         const StopSignal* stop) {
  const V3 d = f.d;
  const BvhView tris = view(area.triangle_bvh);
  const int nu = f.nu(spacing), nw = f.nw(spacing);
  // Centre the grid on the area.
  const double u0 = 0.5 * (f.umin + f.umax) - 0.5 * (nu - 1) * spacing;
  const double w0 = 0.5 * (f.wmin + f.wmax) - 0.5 * (nw - 1) * spacing;
  std::vector<V3> out;
  for (int j = 0; j < nw; ++j) {
    if (stop) stop->throwIfRequested();
    for (int i = 0; i < nu; ++i) {
      const V3 o = (u0 + i * spacing) * f.u + (w0 + j * spacing) * f.w + (f.hmin - 0.01) * d;
      const double t = bvhRay(tris, o, d, kInf, [&](int k) {
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

FloorPoints floorPoints(const AreaModel& area, const FloorPointParams& p, const StopSignal* stop) {
  FloorPoints fp;
  const RayFrame frame(area, p.d_vis);
  // Bounded work: a spacing that would cast more than max_rays is coarsened before casting.
  double spacing = p.spacing;
  while (frame.rays(spacing) > p.max_rays) spacing *= 1.05;
  fp.coarsened = spacing > p.spacing;
  for (int refine = 0; refine <= 6; ++refine, spacing *= 0.5) {
    fp.points = castGrid(area, p, frame, spacing, stop);
    fp.spacing = spacing;
    if (static_cast<int>(fp.points.size()) >= p.min_points || frame.rays(0.5 * spacing) > p.max_rays) break;
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
