#include "place_planner/validation/mesh_variants.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <queue>
#include <random>
#include <stdexcept>
#include <vector>

#include "place_planner/infra/work_limits.h"

namespace place_planner {
namespace validation {
namespace {

// Builds a mesh from triangles over `vertices`, keeping only the vertices used.
Mesh fromTriangles(const std::vector<Eigen::Vector3d>& vertices,
                   const std::vector<std::array<int, 3>>& tris, const std::string& name) {
  std::vector<int> remap(vertices.size(), -1);
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> polys;
  polys.reserve(tris.size());
  for (const auto& t : tris) {
    std::vector<int> p;
    for (int i : t) {
      if (remap[i] < 0) {
        remap[i] = static_cast<int>(v.size());
        v.push_back(vertices[i]);
      }
      p.push_back(remap[i]);
    }
    polys.push_back(std::move(p));
  }
  return buildMesh(v, polys, name);
}

}  // namespace

Mesh decimateByClustering(const Mesh& mesh, int target) {
  if (target < 4) throw std::invalid_argument("decimateByClustering: target_triangles < 4");
  if (static_cast<int>(mesh.triangles.size()) <= target) return mesh;
  const Eigen::Vector3d ext = mesh.properties.bounds_max - mesh.properties.bounds_min;
  double lo = ext.maxCoeff() * 1e-4, hi = ext.maxCoeff();  // fine (many triangles) .. coarse
  double best_h = hi;
  long best_err = -1;
  for (int it = 0; it < 40; ++it) {
    const double h = std::sqrt(lo * hi);
    const int n = static_cast<int>(clusterVertices(mesh, h).triangles.size());
    const long err = std::labs(static_cast<long>(n) - target);
    if (best_err < 0 || err < best_err) {
      best_err = err;
      best_h = h;
    }
    if (n > target) lo = h; else hi = h;
    if (err == 0 || hi / lo < 1.0005) break;
  }
  const Clustered c = clusterVertices(mesh, best_h);
  return fromTriangles(c.vertices, c.triangles, "decimated mesh");
}

Mesh punchHoles(const Mesh& mesh, double fraction, std::uint32_t seed, double patch_fraction) {
  if (!(fraction >= 0.0 && fraction <= 0.9))
    throw std::invalid_argument("punchHoles: fraction must be in [0, 0.9]");
  const int nt = static_cast<int>(mesh.triangles.size());
  const int to_remove = static_cast<int>(std::round(fraction * nt));
  const int patch = std::max(1, static_cast<int>(std::round(patch_fraction * nt)));
  const std::vector<std::vector<int>> nbr = triangleNeighbours(mesh);
  std::mt19937 rng(seed);
  std::vector<char> removed(nt, 0);
  int n_removed = 0;
  while (n_removed < to_remove) {
    std::uniform_int_distribution<int> pick(0, nt - 1);
    int s = pick(rng);
    while (removed[s]) s = (s + 1) % nt;
    std::queue<int> q;
    q.push(s);
    removed[s] = 1;
    int in_patch = 1;
    ++n_removed;
    while (!q.empty() && in_patch < patch && n_removed < to_remove) {
      const int t = q.front();
      q.pop();
      for (int u : nbr[t]) {
        if (removed[u] || in_patch >= patch || n_removed >= to_remove) continue;
        removed[u] = 1;
        ++in_patch;
        ++n_removed;
        q.push(u);
      }
    }
  }
  std::vector<std::array<int, 3>> keep;
  for (int t = 0; t < nt; ++t)
    if (!removed[t]) keep.push_back(mesh.triangles[t]);
  return fromTriangles(mesh.vertices, keep, "holey mesh");
}

}  // namespace validation
}  // namespace place_planner
