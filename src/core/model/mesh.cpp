#include "place_planner/model/mesh.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>

namespace place_planner {
namespace {

// Relative tolerances, scaled by the mesh's bounding-box diagonal: a reconstruction at 1 mm
// resolution has features well above 1e-6 of its size.
constexpr double kPlanarityTol = 1e-6;
constexpr double kZeroAreaTol = 1e-12;  // area relative to diag^2
// Coordinates beyond are refused: squared lengths of 1e77 overflow, and no scene is this big.
constexpr double kMaxCoordinate = 1e12;

Eigen::Vector3d newellNormal(const std::vector<Eigen::Vector3d>& v, const std::vector<int>& poly) {
  // Summed relative to the first vertex: from absolute coordinates, a mesh far from the origin
  // for its size carries rounding of |p| * size * eps that makes degenerate polygons look real.
  const Eigen::Vector3d& o = v[poly[0]];
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (size_t i = 1; i + 1 < poly.size(); ++i) n += (v[poly[i]] - o).cross(v[poly[i + 1]] - o);
  return n * 0.5;  // area-weighted normal: |n| = polygon area when planar
}

bool isPlanarConvex(const std::vector<Eigen::Vector3d>& v, const std::vector<int>& poly,
                    const Eigen::Vector3d& n_unit, double tol) {
  const Eigen::Vector3d& o = v[poly[0]];
  for (int idx : poly)
    if (std::abs((v[idx] - o).dot(n_unit)) > tol) return false;
  const size_t k = poly.size();
  for (size_t i = 0; i < k; ++i) {
    const Eigen::Vector3d e0 = v[poly[(i + 1) % k]] - v[poly[i]];
    const Eigen::Vector3d e1 = v[poly[(i + 2) % k]] - v[poly[(i + 1) % k]];
    if (e0.cross(e1).dot(n_unit) < -tol * tol) return false;
  }
  return true;
}

// Ear clipping in the plane of n_unit; returns triangles (indices into v).
std::vector<std::array<int, 3>> earClip(const std::vector<Eigen::Vector3d>& v,
                                        const std::vector<int>& poly,
                                        const Eigen::Vector3d& n_unit, bool* fanned) {
  Eigen::Vector3d u = n_unit.unitOrthogonal();
  Eigen::Vector3d w = n_unit.cross(u);
  std::vector<Eigen::Vector2d> p(poly.size());
  for (size_t i = 0; i < poly.size(); ++i) p[i] = {v[poly[i]].dot(u), v[poly[i]].dot(w)};
  auto cross2 = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  };
  std::vector<int> idx(poly.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
  std::vector<std::array<int, 3>> tris;
  // Each pass clips one ear, searching on from the last one (ears cluster): about n^2 tests.
  size_t from = 0;
  while (idx.size() > 3) {
    bool clipped = false;
    const size_t m = idx.size();
    for (size_t s = 0; s < m; ++s) {
      const size_t i = (from + s) % m;
      const int a = idx[(i + m - 1) % m], b = idx[i], c = idx[(i + 1) % m];
      if (cross2(p[a], p[b], p[c]) <= 0) continue;  // reflex or degenerate corner
      bool inside = false;
      for (size_t j = 0; j < m && !inside; ++j) {
        const int q = idx[j];
        if (q == a || q == b || q == c) continue;
        inside = cross2(p[a], p[b], p[q]) >= 0 && cross2(p[b], p[c], p[q]) >= 0 &&
                 cross2(p[c], p[a], p[q]) >= 0;
      }
      if (inside) continue;
      tris.push_back({poly[a], poly[b], poly[c]});
      idx.erase(idx.begin() + static_cast<long>(i));
      from = i == 0 ? 0 : i - 1;
      clipped = true;
      break;
    }
    if (!clipped) break;  // self-intersecting: no ear is left; a fan for the rest (counted)
  }
  *fanned = idx.size() > 3;
  for (size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({poly[idx[0]], poly[idx[i]], poly[idx[i + 1]]});
  return tris;
}

}  // namespace

Mesh buildMesh(const std::vector<Eigen::Vector3d>& vertices,
               const std::vector<std::vector<int>>& polygons, const std::string& name,
               const StopSignal* stop) {
  if (vertices.empty()) throw MeshError(name + ": empty mesh (no vertices)");
  if (polygons.empty()) throw MeshError(name + ": empty mesh (no polygons)");
  const int nv = static_cast<int>(vertices.size());
  for (int i = 0; i < nv; ++i) {
    const Eigen::Vector3d& p = vertices[i];
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(p[k]) || std::abs(p[k]) > kMaxCoordinate) {
        std::ostringstream os;
        os << name << ": vertex " << i << " has a "
           << (std::isfinite(p[k]) ? "coordinate beyond 1e12 m" : "non-finite coordinate") << " (" << "xyz"[k]
           << " = " << p[k] << ")";
        throw MeshError(os.str());
      }
    }
  }
  for (size_t f = 0; f < polygons.size(); ++f) {
    const auto& poly = polygons[f];
    if (poly.size() < 3 || poly.size() > kMaxPolygonVertices) {
      std::ostringstream os;
      os << name << ": polygon " << f << " has " << poly.size() << " vertices ("
         << (poly.size() < 3 ? "at least 3 needed" : "at most 10000: triangulate it first") << ")";
      throw MeshError(os.str());
    }
    for (int idx : poly) {
      if (idx < 0 || idx >= nv) {
        std::ostringstream os;
        os << name << ": polygon " << f << " refers to vertex " << idx << " but the mesh has "
           << nv << " vertices";
        throw MeshError(os.str());
      }
    }
  }

  Eigen::Vector3d lo = vertices[0], hi = vertices[0];
  for (const auto& p : vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double diag = std::max((hi - lo).norm(), 1e-9);
  const double plane_tol = kPlanarityTol * diag;
  const double area_tol = kZeroAreaTol * diag * diag;

  Mesh m;
  m.vertices = vertices;
  auto addPatch = [&](std::vector<int> poly, const Eigen::Vector3d& n) {
    m.patches.push_back(std::move(poly));
    m.patch_normals.push_back(n);
  };
  m.patches.reserve(polygons.size());
  m.patch_normals.reserve(polygons.size());
  for (size_t f = 0; f < polygons.size(); ++f) {
    pollStop(stop, f, 1u << 14);
    const auto& poly_in = polygons[f];
    // Drop consecutive repeated indices (common in decimated scans).
    std::vector<int> poly;
    for (int idx : poly_in)
      if (poly.empty() || poly.back() != idx) poly.push_back(idx);
    while (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
    if (poly.size() < 3) {
      ++m.report.dropped_zero_area;
      continue;
    }
    const Eigen::Vector3d an = newellNormal(vertices, poly);
    if (an.norm() <= area_tol) {
      ++m.report.dropped_zero_area;
      continue;
    }
    const Eigen::Vector3d n = an.normalized();
    if (poly.size() == 3 || isPlanarConvex(vertices, poly, n, plane_tol)) {
      addPatch(poly, n);
      continue;
    }
    ++m.report.split_polygons;
    bool fanned = false;
    const auto ears = earClip(vertices, poly, n, &fanned);
    m.report.fanned_polygons += fanned;
    for (const auto& t : ears) {
      std::vector<int> tri{t[0], t[1], t[2]};
      const Eigen::Vector3d tn = newellNormal(vertices, tri);
      if (tn.norm() <= area_tol) {
        ++m.report.dropped_zero_area;
        continue;
      }
      addPatch(tri, tn.normalized());
    }
  }
  if (m.patches.empty())
    throw MeshError(name + ": no patch with non-zero area (all " + std::to_string(polygons.size()) +
                    " polygons are degenerate)");

  // Unique edges in the order of their first use: (key, first use) pairs sorted, one per key.
  std::vector<std::pair<uint64_t, size_t>> uses;
  uses.reserve(3 * m.patches.size());
  for (size_t f = 0; f < m.patches.size(); ++f) {
    pollStop(stop, f, 1u << 14);
    const auto& poly = m.patches[f];
    for (size_t i = 1; i + 1 < poly.size(); ++i) {
      m.triangles.push_back({poly[0], poly[i], poly[i + 1]});
      m.triangle_patch.push_back(static_cast<int>(f));
    }
    for (size_t i = 0; i < poly.size(); ++i) {
      int a = poly[i], b = poly[(i + 1) % poly.size()];
      if (a > b) std::swap(a, b);
      uses.emplace_back((static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b), uses.size());
    }
  }
  if (stop) stop->throwIfRequested();
  std::sort(uses.begin(), uses.end());
  if (stop) stop->throwIfRequested();
  std::vector<size_t> first;
  for (size_t i = 0; i < uses.size(); ++i)
    if (i == 0 || uses[i].first != uses[i - 1].first) first.push_back(i);
  std::sort(first.begin(), first.end(), [&](size_t x, size_t y) { return uses[x].second < uses[y].second; });
  m.edges.reserve(first.size());
  for (size_t i : first)
    m.edges.push_back({static_cast<int>(uses[i].first >> 32), static_cast<int>(uses[i].first & 0xffffffffu)});
  m.properties = computeProperties(m);
  return m;
}

MeshProperties computeProperties(const Mesh& mesh) {
  MeshProperties p;
  if (mesh.vertices.empty()) return p;
  p.bounds_min = p.bounds_max = mesh.vertices[0];
  for (const auto& v : mesh.vertices) {
    p.bounds_min = p.bounds_min.cwiseMin(v);
    p.bounds_max = p.bounds_max.cwiseMax(v);
  }
  // Area-weighted first and second moments of the surface: for a triangle (a, b, c) with
  // area A, the integral of x is A (a+b+c)/3 and of x x^T is A/12 (a a^T + b b^T + c c^T + s s^T)
  // with s = a + b + c.
  double area = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d& b = mesh.vertices[t[1]];
    const Eigen::Vector3d& c = mesh.vertices[t[2]];
    const double A = 0.5 * (b - a).cross(c - a).norm();
    const Eigen::Vector3d s = a + b + c;
    area += A;
    first += A * s / 3.0;
    second += A / 12.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  p.surface_area = area;
  if (area > 0) {
    p.center_of_mass = first / area;
    const Eigen::Matrix3d cov = second / area - p.center_of_mass * p.center_of_mass.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    // Eigen sorts ascending; the paper's k1 belongs to the largest eigenvalue.
    for (int i = 0; i < 3; ++i) {
      p.eigenvalues[i] = es.eigenvalues()[2 - i];
      p.principal_axes.col(i) = es.eigenvectors().col(2 - i).normalized();
    }
    // Right-handed frame, and a deterministic sign: the largest component of k1, k2 positive.
    for (int i = 0; i < 2; ++i) {
      Eigen::Index j;
      p.principal_axes.col(i).cwiseAbs().maxCoeff(&j);
      if (p.principal_axes(j, i) < 0) p.principal_axes.col(i) *= -1.0;
    }
    p.principal_axes.col(2) = p.principal_axes.col(0).cross(p.principal_axes.col(1));
  } else {
    p.center_of_mass = 0.5 * (p.bounds_min + p.bounds_max);
  }
  for (const auto& v : mesh.vertices)
    p.bounding_radius = std::max(p.bounding_radius, (v - p.center_of_mass).norm());
  return p;
}

std::vector<std::vector<int>> triangleNeighbours(const Mesh& mesh) {
  const int nt = static_cast<int>(mesh.triangles.size());
  std::map<std::pair<int, int>, std::vector<int>> edge_tris;
  for (int t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      int i = mesh.triangles[t][k], j = mesh.triangles[t][(k + 1) % 3];
      if (i > j) std::swap(i, j);
      edge_tris[{i, j}].push_back(t);
    }
  std::vector<std::vector<int>> nbr(nt);
  for (const auto& kv : edge_tris)
    for (int a : kv.second)
      for (int b : kv.second)
        if (a != b) nbr[a].push_back(b);
  return nbr;
}

Mesh transformed(const Mesh& mesh, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Mesh out = mesh;
  for (auto& v : out.vertices) v = R * v + t;
  for (auto& n : out.patch_normals) n = R * n;
  out.properties = computeProperties(out);
  return out;
}

}  // namespace place_planner
