// Up direction of an area from its largest flat region (see area_up.h).
#include "place_planner/model/area_up.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

namespace place_planner {
namespace {

struct Facet {
  Eigen::Vector3d n;  // unit normal, sign not trusted
  Eigen::Vector3d c;  // centroid
  double area;
};

std::vector<Facet> facets(const Mesh& m) {
  std::vector<Facet> out;
  out.reserve(m.triangles.size());
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double nn = n.norm();
    if (!(nn > 0)) continue;
    out.push_back({n / nn, (a + b + c) / 3.0, 0.5 * nn});
  }
  return out;
}

}  // namespace

double upFacingShare(const Mesh& area, const Eigen::Vector3d& up, double max_deg) {
  const Eigen::Vector3d u = up.normalized();
  const double c = std::cos(max_deg * M_PI / 180.0);
  double in = 0, total = 0;
  for (const Facet& f : facets(area)) {
    total += f.area;
    if (std::abs(f.n.dot(u)) >= c) in += f.area;
  }
  return total > 0 ? in / total : 0.0;
}

UpEstimate estimateUp(const Mesh& area, const Eigen::Vector3d& hint_up) {
  const Eigen::Vector3d hint = hint_up.normalized();
  UpEstimate e;
  const std::vector<Facet> fs = facets(area);
  if (fs.empty()) return e;
  // Seed: the heaviest bin of sign-normalised normals (a coarse sphere of directions).
  auto canonical = [](Eigen::Vector3d n) {
    if (n.z() < 0 || (n.z() == 0 && (n.y() < 0 || (n.y() == 0 && n.x() < 0)))) n = -n;
    return n;
  };
  std::map<std::tuple<long, long, long>, double> bins;
  for (const Facet& f : fs) {
    const Eigen::Vector3d n = canonical(f.n);
    bins[{std::lround(4 * n.x()), std::lround(4 * n.y()), std::lround(4 * n.z())}] += f.area;
  }
  const auto seed = std::max_element(bins.begin(), bins.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  Eigen::Vector3d u(std::get<0>(seed->first), std::get<1>(seed->first), std::get<2>(seed->first));
  u.normalize();
  // Mean shift: the area-weighted mean of the normals within 10 degrees, a few times.
  const double c10 = std::cos(10.0 * M_PI / 180.0);
  double share = 0, total = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), all = Eigen::Vector3d::Zero();
  for (const Facet& f : fs) {
    total += f.area;
    all += f.area * f.c;
  }
  for (int it = 0; it < 8; ++it) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double w = 0;
    centre.setZero();
    for (const Facet& f : fs) {
      const double d = f.n.dot(u);
      if (std::abs(d) < c10) continue;
      sum += (d < 0 ? -f.area : f.area) * f.n;
      centre += f.area * f.c;
      w += f.area;
    }
    if (w <= 0) break;
    u = sum.normalized();
    centre /= w;
    share = w / total;
  }
  // Which side is up: the one nearer the caller's up (a scan tilted by its camera still has
  // the table's normal within 80 degrees of it); only when the region stands nearly at right
  // angles to that, the side the rest of the mesh is on (things stand on a table, not under it).
  if (std::abs(u.dot(hint)) >= 0.17) {
    if (u.dot(hint) < 0) u = -u;
  } else {
    all /= total;
    if ((all - centre).dot(u) < 0) u = -u;
  }
  e.up = u;
  e.share = share;
  return e;
}

}  // namespace place_planner
