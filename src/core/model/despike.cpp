// Noise spikes of a scan (despike.h).
#include "place_planner/model/despike.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "place_planner/model/completion.h"

namespace place_planner {

Mesh despiked(const Mesh& scan, double noise, int* flattened) {
  if (flattened) *flattened = 0;
  const size_t n = scan.vertices.size();
  if (noise <= 0 || n == 0) return scan;
  std::vector<char> rim(n, 0);
  for (const auto& e : openEdges(scan)) rim[e[0]] = rim[e[1]] = 1;
  std::vector<std::vector<int>> ring(n);
  std::vector<Eigen::Vector3d> normal(n, Eigen::Vector3d::Zero());  // area-weighted, outward
  for (const auto& t : scan.triangles) {
    const Eigen::Vector3d a = scan.vertices[t[0]], b = scan.vertices[t[1]], c = scan.vertices[t[2]];
    const Eigen::Vector3d an = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) {
      normal[t[k]] += an;
      ring[t[k]].push_back(t[(k + 1) % 3]);
      ring[t[k]].push_back(t[(k + 2) % 3]);
    }
  }
  std::vector<Eigen::Vector3d> v = scan.vertices;
  int moved = 0;
  for (size_t i = 0; i < n; ++i) {
    std::vector<int>& r = ring[i];
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    if (rim[i] || r.size() < 3 || normal[i].squaredNorm() == 0) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int j : r) c += scan.vertices[j];
    c /= static_cast<double>(r.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int j : r) cov += (scan.vertices[j] - c) * (scan.vertices[j] - c).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    const double rms = std::sqrt(std::max(0.0, es.eigenvalues()(0)) / static_cast<double>(r.size()));
    Eigen::Vector3d p = es.eigenvectors().col(0);
    if (p.dot(normal[i]) < 0) p = -p;  // the plane's normal, outwards
    const double out = (scan.vertices[i] - c).dot(p);
    if (rms > 0.5 * noise || out <= 2.0 * noise) continue;
    v[i] = scan.vertices[i] - out * p;
    ++moved;
  }
  if (flattened) *flattened = moved;
  if (moved == 0) return scan;
  return buildMesh(v, scan.patches, "object mesh");
}

}  // namespace place_planner
