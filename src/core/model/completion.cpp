// Caps of open regions (completion.h).
#include "place_planner/model/completion.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>

namespace place_planner {

std::vector<std::array<int, 2>> openEdges(const Mesh& mesh) {
  // Every edge as (smaller index, larger index, direction in its triangle), sorted: an edge
  // seen once borders an open region (one sort, no map: a 300k-triangle mesh takes ~50 ms).
  struct Edge {
    int lo, hi;
    bool forward;  // runs lo -> hi in its triangle
    bool operator<(const Edge& o) const { return lo != o.lo ? lo < o.lo : hi < o.hi; }
  };
  std::vector<Edge> all;
  all.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (a != b) all.push_back({std::min(a, b), std::max(a, b), a < b});
    }
  std::sort(all.begin(), all.end());
  std::vector<std::array<int, 2>> open;
  size_t unique = 0;
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j].lo == all[i].lo && all[j].hi == all[i].hi) ++j;
    ++unique;
    if (j - i == 1) open.push_back(all[i].forward ? std::array<int, 2>{all[i].lo, all[i].hi}
                                                  : std::array<int, 2>{all[i].hi, all[i].lo});
    i = j;
  }
  if (open.size() * 2 > unique) open.clear();  // a soup: nothing is known to be open
  return open;
}

double segmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

Completion completeOpenRegions(const Mesh& object) {
  Completion c;
  c.source = &object;
  // Boundary half-edges a -> b as they run in their triangles, walked a -> b -> ...
  // (non-manifold edges, used three times or more, are left alone).
  const std::vector<std::array<int, 2>> open_edges = openEdges(object);
  if (open_edges.empty()) return c;  // closed, or a soup: planned on as it is, no copy
  const size_t open = open_edges.size();
  std::multimap<int, int> next;
  for (const auto& e : open_edges) next.emplace(e[0], e[1]);
  std::vector<std::vector<int>> polygons = object.patches;
  while (!next.empty()) {
    auto it = next.begin();
    std::vector<int> loop{it->first};
    int at = it->second;
    next.erase(it);
    for (size_t guard = 0; at != loop.front() && guard < open; ++guard) {
      loop.push_back(at);
      auto nx = next.find(at);
      if (nx == next.end()) break;
      at = nx->second;
      next.erase(nx);
    }
    if (at != loop.front() || loop.size() < 3) continue;  // an open chain (pinched): not a loop
    CompletionCap cap;
    for (int v : loop) cap.loop.push_back(object.vertices[static_cast<size_t>(v)]);
    for (const auto& p : cap.loop) cap.centroid += p;
    cap.centroid /= static_cast<double>(cap.loop.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : cap.loop) cov += (p - cap.centroid) * (p - cap.centroid).transpose();
    Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    // Out of the object: away from the object's centre (of the seen surface).
    if (n.dot(cap.centroid - object.properties.center_of_mass) < 0) n = -n;
    cap.normal = n;
    for (const auto& p : cap.loop) cap.flatness = std::max(cap.flatness, std::abs((p - cap.centroid).dot(n)));
    for (size_t i = 0; i < cap.loop.size(); ++i)
      c.open_perimeter += (cap.loop[(i + 1) % cap.loop.size()] - cap.loop[i]).norm();
    // The boundary half-edges run a -> b inside their triangles; the cap runs the other way.
    std::reverse(loop.begin(), loop.end());
    polygons.push_back(loop);
    c.caps.push_back(std::move(cap));
  }
  if (c.caps.empty()) return c;
  try {
    c.capped = buildMesh(object.vertices, polygons, "completed object mesh");
  } catch (const std::exception&) {
    c.caps.clear();  // a cap that cannot be built: plan on the scan as it is
  }
  return c;
}

bool onCompletedSurface(const Completion& completion, const Eigen::Vector3d& p, double margin) {
  for (const CompletionCap& cap : completion.caps) {
    const double off = (p - cap.centroid).dot(cap.normal);
    if (std::abs(off) > std::max(margin, cap.flatness + margin)) continue;
    // Inside the loop: the loop's winding number about p, in the cap's plane.
    const Eigen::Vector3d u = cap.normal.unitOrthogonal(), w = cap.normal.cross(u);
    double angle = 0, rim = 1e300;
    const size_t n = cap.loop.size();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d& a = cap.loop[i];
      const Eigen::Vector3d& b = cap.loop[(i + 1) % n];
      rim = std::min(rim, segmentDistance(p, a, b));
      const Eigen::Vector2d a2((a - p).dot(u), (a - p).dot(w)), b2((b - p).dot(u), (b - p).dot(w));
      angle += std::atan2(a2.x() * b2.y() - a2.y() * b2.x(), a2.dot(b2));
    }
    if (std::abs(angle) > M_PI && rim > margin) return true;
  }
  return false;
}

bool onOpenRimFacing(const Completion& completion, const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                     double margin) {
  // Facing: the cap's outward normal within 60 degrees of the surface's (-n).
  constexpr double kFacing = 0.5;
  for (const CompletionCap& cap : completion.caps) {
    if (cap.normal.dot(n) > -kFacing) continue;
    const size_t k = cap.loop.size();
    for (size_t i = 0; i < k; ++i)
      if (segmentDistance(p, cap.loop[i], cap.loop[(i + 1) % k]) <= margin) return true;
  }
  return false;
}

bool nearOpenEdge(const std::vector<std::array<Eigen::Vector3d, 2>>& edges, const Eigen::Vector3d& p, double margin) {
  for (const auto& e : edges)
    if (segmentDistance(p, e[0], e[1]) < margin) return true;
  return false;
}

}  // namespace place_planner
