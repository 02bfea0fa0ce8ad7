// Bounded work (work_limits.h): size checks, the model memory estimate, decimation.
#include "place_planner/infra/work_limits.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <unordered_map>

namespace place_planner {
namespace {

double diameter(const Mesh& m) { return (m.properties.bounds_max - m.properties.bounds_min).norm(); }

std::string sizeMessage(const char* what, double d, const char* field, double limit) {
  char msg[400];
  std::snprintf(msg, sizeof msg,
                "%s is %.3g m across, larger than %s = %.3g m: meshes are read in metres; is it in "
                "millimetres (%.3g m if so)?",
                what, d, field, limit, d / 1000.0);
  return msg;
}

}  // namespace

std::vector<std::string> checkMeshSizes(const Mesh& object, const Mesh& area, const PlannerConfig& config) {
  const double d_obj = diameter(object), d_area = diameter(area);
  if (d_obj > config.max_object_size)
    throw LimitError(sizeMessage("object mesh", d_obj, "max_object_size", config.max_object_size));
  if (d_area > config.max_area_size)
    throw LimitError(sizeMessage("placement area mesh", d_area, "max_area_size", config.max_area_size));
  std::vector<std::string> warnings;
  if (d_obj > d_area) {
    char msg[300];
    std::snprintf(msg, sizeof msg,
                  "the object (%.3g m across) is larger than the placement area (%.3g m): are both "
                  "meshes in metres?",
                  d_obj, d_area);
    warnings.push_back(msg);
  }
  return warnings;
}

double estimateModelBytes(const Mesh& mesh, double r, double cd, double cell, size_t max_triangles) {
  const double step = 2.0 * r;  // sphere spacing (sphere_model.cpp)
  const double n = std::max<double>(1.0, static_cast<double>(std::min(mesh.triangles.size(), max_triangles)));
  const double nv = std::min<double>(static_cast<double>(mesh.vertices.size()), n);
  double spheres = nv + n + mesh.properties.surface_area / (step * step);
  // Edge samples: about three edges per two triangles of mean length sqrt(2 A / n).
  spheres += 1.5 * n * std::sqrt(2.0 * mesh.properties.surface_area / n) / step;
  // Centre and normal (48 B), the object's BVH or the area's grid entries (~7 cells, 4 B each).
  double bytes = spheres * (48.0 + 28.0);
  // Triangles, normals, three BVHs, feature edges, the mesh's own copies.
  bytes += n * 300.0 + nv * 100.0;
  if (cd > 0 && cell > 0) {
    const Eigen::Vector3d ext = mesh.properties.bounds_max - mesh.properties.bounds_min;
    // Any horizontal extent: the grid spans the two largest.
    double e[3] = {ext.x(), ext.y(), ext.z()};
    std::sort(e, e + 3);
    bytes += (e[2] + 2 * cd) / cell * ((e[1] + 2 * cd) / cell) * 24.0;  // offset, two heights
  }
  return bytes;
}

Clustered clusterVertices(const Mesh& mesh, double h, const StopSignal* stop) {
  const Eigen::Vector3d lo = mesh.properties.bounds_min;
  std::unordered_map<uint64_t, int> cluster_of_cell;
  cluster_of_cell.reserve(mesh.vertices.size() / 4 + 16);
  std::vector<int> cluster(mesh.vertices.size());
  Clustered out;
  std::vector<int> count;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    pollStop(stop, i, 1u << 16);
    const Eigen::Vector3d q = (mesh.vertices[i] - lo) / h;
    const uint64_t key = (static_cast<uint64_t>(q.x()) & 0x1fffff) |
                         ((static_cast<uint64_t>(q.y()) & 0x1fffff) << 21) |
                         ((static_cast<uint64_t>(q.z()) & 0x1fffff) << 42);
    auto it = cluster_of_cell.emplace(key, static_cast<int>(out.vertices.size())).first;
    if (it->second == static_cast<int>(out.vertices.size())) out.vertices.emplace_back(0, 0, 0), count.push_back(0);
    cluster[i] = it->second;
    out.vertices[it->second] += mesh.vertices[i];
    ++count[it->second];
  }
  for (size_t k = 0; k < out.vertices.size(); ++k) out.vertices[k] /= count[k];
  // Candidates with their sorted cluster triple; the first of each triple is kept, in order.
  std::vector<std::pair<std::array<int, 3>, size_t>> keys;
  std::vector<std::array<int, 3>> tris;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    pollStop(stop, t, 1u << 16);
    const auto& tri = mesh.triangles[t];
    const std::array<int, 3> r{cluster[tri[0]], cluster[tri[1]], cluster[tri[2]]};
    if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2]) continue;
    std::array<int, 3> k = r;
    std::sort(k.begin(), k.end());
    keys.emplace_back(k, tris.size());
    tris.push_back(r);
  }
  if (stop) stop->throwIfRequested();
  std::sort(keys.begin(), keys.end());
  if (stop) stop->throwIfRequested();
  std::vector<char> keep(tris.size(), 0);
  for (size_t i = 0; i < keys.size(); ++i)
    if (i == 0 || keys[i].first != keys[i - 1].first) keep[keys[i].second] = 1;
  const auto& v = out.vertices;
  for (size_t t = 0; t < tris.size(); ++t) {
    const auto& r = tris[t];
    if (keep[t] && (v[r[1]] - v[r[0]]).cross(v[r[2]] - v[r[0]]).norm() >= 1e-14) out.triangles.push_back(r);
  }
  return out;
}

Mesh decimated(const Mesh& mesh, size_t max_triangles, double* cell_out, const StopSignal* stop) {
  if (mesh.triangles.size() <= max_triangles) {
    if (cell_out) *cell_out = 0.0;
    return mesh;
  }
  // A surface of area A in cells of size h keeps about 2 A / h^2 triangles; start there.
  double h = std::sqrt(2.0 * std::max(mesh.properties.surface_area, 1e-12) / max_triangles);
  // Cell and cluster indices fit 21 bits each (clusterVertices' keys).
  h = std::max(h, (mesh.properties.bounds_max - mesh.properties.bounds_min).maxCoeff() / (1 << 20));
  for (int attempt = 0; attempt < 40; ++attempt, h *= 1.25) {
    const Clustered cl = clusterVertices(mesh, h, stop);
    if (cl.triangles.size() > max_triangles || cl.triangles.empty() || cl.vertices.size() >= (1u << 21)) continue;
    std::vector<std::vector<int>> polys;
    polys.reserve(cl.triangles.size());
    for (const auto& t : cl.triangles) polys.push_back({t[0], t[1], t[2]});
    Mesh out = buildMesh(cl.vertices, polys, "decimated mesh", stop);
    if (out.triangles.size() > max_triangles) continue;
    // The object's mass properties stay the input's: the answer is for the real object.
    const MeshProperties p = out.properties;
    out.properties = mesh.properties;
    out.properties.bounds_min = p.bounds_min;
    out.properties.bounds_max = p.bounds_max;
    out.properties.surface_area = p.surface_area;
    if (cell_out) *cell_out = h;
    return out;
  }
  throw LimitError("mesh of " + std::to_string(mesh.triangles.size()) +
                   " triangles could not be decimated below max_triangles = " + std::to_string(max_triangles));
}

}  // namespace place_planner
