// Resting faces: convex hull, coplanar facets, centre-of-mass margin (resting_faces.h).
#include "place_planner/search/resting_faces.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "place_planner/judgement/quality.h"

namespace place_planner {
namespace {

uint64_t edgeKey(int a, int b) { return (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b); }

// Extreme points along 26 directions; the points inside their hull cannot be hull vertices.
std::vector<int> extremeIndices(const std::vector<Eigen::Vector3d>& p) {
  std::vector<int> idx;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        if (!x && !y && !z) continue;
        const Eigen::Vector3d d(x, y, z);
        int best = 0;
        for (size_t i = 1; i < p.size(); ++i)
          if (p[i].dot(d) > p[best].dot(d)) best = static_cast<int>(i);
        idx.push_back(best);
      }
  std::sort(idx.begin(), idx.end());
  idx.erase(std::unique(idx.begin(), idx.end()), idx.end());
  return idx;
}

struct HullBuilder {
  const std::vector<Eigen::Vector3d>& p;
  double eps;
  std::vector<std::array<int, 3>> f;
  std::vector<Eigen::Vector3d> n;
  std::vector<double> off;
  std::vector<char> alive;
  std::unordered_map<uint64_t, int> edge_face;  // directed edge a->b of a live face

  void add(int a, int b, int c) {
    const Eigen::Vector3d nn = (p[b] - p[a]).cross(p[c] - p[a]);
    const int id = static_cast<int>(f.size());
    f.push_back({a, b, c});
    n.push_back(nn.norm() > 0 ? Eigen::Vector3d(nn.normalized()) : Eigen::Vector3d::Zero());
    off.push_back(n.back().dot(p[a]));
    alive.push_back(1);
    edge_face[edgeKey(a, b)] = id;
    edge_face[edgeKey(b, c)] = id;
    edge_face[edgeKey(c, a)] = id;
  }
  bool visible(int fi, int q) const { return n[fi].dot(p[q]) - off[fi] > eps; }

  // Inserts point q: removes the faces it sees, closes the horizon with new faces.
  void insert(int q) {
    std::vector<int> vis;
    for (size_t i = 0; i < f.size(); ++i)
      if (alive[i] && visible(static_cast<int>(i), q)) vis.push_back(static_cast<int>(i));
    if (vis.empty()) return;
    std::vector<std::array<int, 2>> horizon;
    for (int fi : vis) alive[fi] = 2;  // marked visible
    for (int fi : vis)
      for (int k = 0; k < 3; ++k) {
        const int a = f[fi][k], b = f[fi][(k + 1) % 3];
        auto it = edge_face.find(edgeKey(b, a));
        if (it == edge_face.end() || alive[it->second] != 2) horizon.push_back({a, b});
      }
    for (int fi : vis) {
      alive[fi] = 0;
      for (int k = 0; k < 3; ++k) {
        auto it = edge_face.find(edgeKey(f[fi][k], f[fi][(k + 1) % 3]));
        if (it != edge_face.end() && it->second == fi) edge_face.erase(it);
      }
    }
    for (const auto& e : horizon) add(e[0], e[1], q);
  }
};

}  // namespace

ConvexHull3 convexHull3d(const std::vector<Eigen::Vector3d>& points, const StopSignal* stop) {
  ConvexHull3 h;
  h.points = points;
  if (points.size() < 4) return h;
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const auto& q : points) {
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const double scale = std::max(1e-12, (hi - lo).norm());
  const std::vector<int> ext = extremeIndices(points);
  // Initial tetrahedron from the extremes: farthest pair, then off the line, then off the plane.
  int i0 = ext[0], i1 = ext[0];
  for (int a : ext)
    for (int b : ext)
      if ((points[a] - points[b]).norm() > (points[i0] - points[i1]).norm()) i0 = a, i1 = b;
  auto farthestFrom = [&](auto dist) {
    int best = -1;
    double bd = 1e-9 * scale;
    for (size_t i = 0; i < points.size(); ++i)
      if (dist(points[i]) > bd) bd = dist(points[i]), best = static_cast<int>(i);
    return best;
  };
  const Eigen::Vector3d u = (points[i1] - points[i0]).normalized();
  const int i2 = farthestFrom([&](const Eigen::Vector3d& q) {
    const Eigen::Vector3d r = q - points[i0];
    return (r - r.dot(u) * u).norm();
  });
  if (i2 < 0) return h;
  const Eigen::Vector3d nrm = (points[i1] - points[i0]).cross(points[i2] - points[i0]).normalized();
  const int i3 = farthestFrom([&](const Eigen::Vector3d& q) { return std::abs((q - points[i0]).dot(nrm)); });
  if (i3 < 0) return h;
  HullBuilder b{points, 1e-9 * scale, {}, {}, {}, {}, {}};
  if ((points[i3] - points[i0]).dot(nrm) > 0) {
    b.add(i0, i2, i1), b.add(i0, i1, i3), b.add(i1, i2, i3), b.add(i2, i0, i3);
  } else {
    b.add(i0, i1, i2), b.add(i0, i3, i1), b.add(i1, i3, i2), b.add(i2, i3, i0);
  }
  // Extremes first, then the rest that lies outside the extremes' hull.
  for (int e : ext) b.insert(e);
  std::vector<int> outside;
  for (size_t i = 0; i < points.size(); ++i) {
    pollStop(stop, i, 1024);
    bool out = false;
    for (size_t fi = 0; fi < b.f.size() && !out; ++fi) out = b.alive[fi] && b.visible(static_cast<int>(fi), static_cast<int>(i));
    if (out) outside.push_back(static_cast<int>(i));
  }
  for (size_t k = 0; k < outside.size(); ++k) {
    pollStop(stop, k, 64);
    b.insert(outside[k]);
  }
  for (size_t fi = 0; fi < b.f.size(); ++fi)
    if (b.alive[fi] && b.n[fi].norm() > 0) {
      h.faces.push_back(b.f[fi]);
      h.normals.push_back(b.n[fi]);
    }
  return h;
}

std::vector<RestingFace> restingFaces(const Mesh& object, double min_tipping_angle, double merge_deg,
                                      const StopSignal* stop) {
  const ConvexHull3 hull = convexHull3d(object.vertices, stop);
  const Eigen::Vector3d com = object.properties.center_of_mass;
  const size_t nf = hull.faces.size();
  std::vector<double> area(nf);
  std::unordered_map<uint64_t, int> edge_face;
  for (size_t i = 0; i < nf; ++i) {
    const auto& t = hull.faces[i];
    area[i] = 0.5 * (hull.points[t[1]] - hull.points[t[0]]).cross(hull.points[t[2]] - hull.points[t[0]]).norm();
    for (int k = 0; k < 3; ++k) edge_face[edgeKey(t[k], t[(k + 1) % 3])] = static_cast<int>(i);
  }
  // Facets: region growing from the largest faces over neighbours within merge_deg of the seed.
  std::vector<int> order(nf);
  for (size_t i = 0; i < nf; ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return area[a] > area[b]; });
  std::vector<int> facet(nf, -1);
  const double cos_merge = std::cos(merge_deg * M_PI / 180.0);
  std::vector<RestingFace> out;
  for (int seed : order) {
    if (facet[seed] >= 0) continue;
    const int id = seed;
    std::vector<int> stack{seed}, members;
    facet[seed] = id;
    Eigen::Vector3d nsum = Eigen::Vector3d::Zero();
    while (!stack.empty()) {
      const int fi = stack.back();
      stack.pop_back();
      members.push_back(fi);
      nsum += area[fi] * hull.normals[fi];
      for (int k = 0; k < 3; ++k) {
        auto it = edge_face.find(edgeKey(hull.faces[fi][(k + 1) % 3], hull.faces[fi][k]));
        if (it == edge_face.end() || facet[it->second] >= 0) continue;
        if (hull.normals[it->second].dot(hull.normals[seed]) < cos_merge) continue;
        facet[it->second] = id;
        stack.push_back(it->second);
      }
    }
    if (nsum.norm() <= 0) continue;
    // The object rests on one hull triangle of the facet: the one the centre of mass projects
    // into along its own normal (a scanned base is not quite flat); else the mean plane.
    Eigen::Vector3d nrm = nsum.normalized();
    for (int fi : members) {
      const auto& t = hull.faces[fi];
      const Eigen::Vector3d& nf = hull.normals[fi];
      const Eigen::Vector3d q = com - (com - hull.points[t[0]]).dot(nf) * nf;
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k) {
        const Eigen::Vector3d& a = hull.points[t[k]];
        const Eigen::Vector3d& b = hull.points[t[(k + 1) % 3]];
        inside = (b - a).cross(q - a).dot(nf) >= 0;
      }
      if (inside) {
        nrm = nf;
        break;
      }
    }
    // Support polygon on the facet's outermost plane; the centre of mass projected along nrm.
    double plane = -1e300;
    for (int fi : members)
      for (int k = 0; k < 3; ++k) plane = std::max(plane, hull.points[hull.faces[fi][k]].dot(nrm));
    const Eigen::Vector3d u = nrm.unitOrthogonal(), w = nrm.cross(u);
    std::vector<Eigen::Vector2d> p2;
    for (int fi : members)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d& q = hull.points[hull.faces[fi][k]];
        p2.emplace_back(q.dot(u), q.dot(w));
      }
    const std::vector<Eigen::Vector2d> poly = convexHull2d(p2);
    if (poly.size() < 3) continue;
    const double margin = signedBoundaryDistance(poly, Eigen::Vector2d(com.dot(u), com.dot(w)));
    const double height = std::max(1e-9, plane - com.dot(nrm));
    const double tip = std::atan2(margin, height);
    if (tip < min_tipping_angle) continue;
    out.push_back(RestingFace{nrm, tip, margin, std::abs(polygonArea(poly))});
  }
  std::sort(out.begin(), out.end(),
            [](const RestingFace& a, const RestingFace& b) { return a.tipping_angle > b.tipping_angle; });
  return out;
}

}  // namespace place_planner
