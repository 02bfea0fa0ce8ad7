// Surface sphere models and the 2D height grid (Section V-B).
#include <algorithm>
#include <cmath>
#include <future>
#include <limits>

#include "place_planner/model/scene.h"

namespace place_planner {

SphereModel sampleSpheres(const std::vector<V3>& vertices,
                          const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<std::array<int, 2>>& edges, double radius,
                          const StopSignal* stop) {
  SphereModel m;
  m.radius = radius;
  const double step = 2.0 * radius;  // "the distance between two sphere centres is 2r"
  // Room for every sphere up front (lattice, centroids, edges, vertices): no regrowth.
  double estimate = static_cast<double>(triangles.size() + vertices.size());
  for (const auto& t : triangles)
    estimate += 0.5 * norm(cross(vertices[t[1]] - vertices[t[0]], vertices[t[2]] - vertices[t[0]])) / (step * step);
  for (const auto& e : edges) estimate += norm(vertices[e[1]] - vertices[e[0]]) / step;
  m.centres.reserve(static_cast<size_t>(1.1 * estimate));
  m.normals.reserve(static_cast<size_t>(1.1 * estimate));
  std::vector<V3> vnormal(vertices.size(), v3(0, 0, 0));
  for (size_t ti = 0; ti < triangles.size(); ++ti) {
    pollStop(stop, ti, 256);
    const auto& t = triangles[ti];
    const V3 a = vertices[t[0]], b = vertices[t[1]], c = vertices[t[2]];
    const V3 n = cross(b - a, c - a);  // area-weighted
    for (int k = 0; k < 3; ++k) vnormal[t[k]] = vnormal[t[k]] + n;
    const double nn = norm(n);
    if (nn <= 0) continue;
    const V3 nu = (1.0 / nn) * n;
    // Interior lattice in the triangle's plane, offset half a step from the first edge.
    const V3 u = normalized(b - a);
    const V3 w = cross(nu, u);
    double umin = 0, umax = 0, wmin = 0, wmax = 0;
    for (V3 p : {b - a, c - a}) {
      umin = std::min(umin, dot(p, u));
      umax = std::max(umax, dot(p, u));
      wmin = std::min(wmin, dot(p, w));
      wmax = std::max(wmax, dot(p, w));
    }
    for (double x = umin + 0.5 * step; x < umax; x += step) {
      for (double y = wmin + 0.5 * step; y < wmax; y += step) {
        const V3 p = a + x * u + y * w;
        // Keep lattice points at least half a step inside: the edges get their own samples.
        if (insideTriangle(p, a, b, c, -0.5 * step)) {
          m.centres.push_back(p);
          m.normals.push_back(nu);
        }
      }
    }
    // Triangles too small for a lattice point still get their centroid.
    if (nn * 0.5 < step * step) {
      m.centres.push_back((1.0 / 3.0) * (a + b + c));
      m.normals.push_back(nu);
    }
  }
  // Edges (sharp features are typical contacts) and vertices, once each.
  for (size_t ei = 0; ei < edges.size(); ++ei) {
    pollStop(stop, ei, 1024);
    const auto& e = edges[ei];
    const V3 a = vertices[e[0]], b = vertices[e[1]];
    const double len = norm(b - a);
    const int n = static_cast<int>(std::floor(len / step));
    const V3 en = normalized(vnormal[e[0]] + vnormal[e[1]]);
    for (int i = 1; i <= n; ++i) {
      const double s = i / static_cast<double>(n + 1);
      m.centres.push_back(a + s * (b - a));
      m.normals.push_back(en);
    }
  }
  for (size_t i = 0; i < vertices.size(); ++i) {
    if (norm2(vnormal[i]) == 0) continue;  // unreferenced vertex
    m.centres.push_back(vertices[i]);
    m.normals.push_back(normalized(vnormal[i]));
  }
  return m;
}

HeightGrid buildHeightGrid(const SphereModel& s, const Aabb& bounds, double cd, double cell,
                           const StopSignal* stop) {
  HeightGrid g;
  g.collision_distance = cd;
  // Touching features meet to rounding after the exact translations and rotations; 0.25 mm
  // absorbs that and keeps curved surfaces from looking flat (a cylinder of 4 cm radius is
  // within 0.25 mm of its tangent plane over a 9 mm wide band only: a line contact). Small
  // objects (cd under 2.5 mm) get a gap of their own scale, else a 3 degree tilt of a 5 mm cube
  // would look flat.
  g.contact_gap = std::min(2.5e-4, 0.1 * cd) + 0.02 * cd;
  g.cell = cell;
  g.x0 = bounds.lo.x - cd;
  g.y0 = bounds.lo.y - cd;
  g.nx = std::max(1, static_cast<int>(std::ceil((bounds.hi.x - bounds.lo.x + 2 * cd) / cell)));
  g.ny = std::max(1, static_cast<int>(std::ceil((bounds.hi.y - bounds.lo.y + 2 * cd) / cell)));
  const size_t ncell = static_cast<size_t>(g.nx) * g.ny;
  g.max_z.assign(ncell, -std::numeric_limits<double>::infinity());
  g.max_contact_z = g.max_z;
  // How high above an area sphere an object sphere centre can make a contact (sphereContact):
  // within contact_gap along the sphere's normal n and 1.5 r across it, so at most
  // contact_gap |n_z| + 1.5 r sqrt(1 - n_z^2) higher, and within cd. Over a flat support that is
  // the contact gap, not cd: the spheres hovering a few millimetres above it cost a lookup only.
  auto reach = [&](size_t i) {
    const double nz = std::min(1.0, std::abs(s.normals[i].z));
    return std::min(cd, g.contact_gap * nz + 1.5 * s.radius * std::sqrt(1.0 - nz * nz)) + 1e-9;
  };
  std::vector<int> count(ncell, 0);
  // Cells meeting the virtual sphere's x/y disc (radius cd), restricted to the rows [r0, r1).
  auto forCells = [&](const V3& c, int r0, int r1, auto&& f) {
    const int iy0 = std::max(r0, static_cast<int>(std::floor((c.y - cd - g.y0) / cell)));
    const int iy1 = std::min(r1 - 1, static_cast<int>(std::floor((c.y + cd - g.y0) / cell)));
    if (iy0 > iy1) return;
    const int ix0 = std::max(0, static_cast<int>(std::floor((c.x - cd - g.x0) / cell)));
    const int ix1 = std::min(g.nx - 1, static_cast<int>(std::floor((c.x + cd - g.x0) / cell)));
    for (int iy = iy0; iy <= iy1; ++iy) {
      // Distance from the centre to the cell rectangle, in x/y.
      const double dy = std::max({0.0, g.y0 + iy * cell - c.y, c.y - (g.y0 + (iy + 1) * cell)});
      for (int ix = ix0; ix <= ix1; ++ix) {
        const double dx = std::max({0.0, g.x0 + ix * cell - c.x, c.x - (g.x0 + (ix + 1) * cell)});
        if (dx * dx + dy * dy <= cd * cd) f(static_cast<size_t>(iy) * g.nx + ix);
      }
    }
  };
  // Two bands of rows on two threads; each visits the spheres in index order, so every cell
  // lists its spheres in the same order as a single pass would.
  const int mid = g.ny / 2;
  auto bands = [&](auto&& pass) {
    auto lower = std::async(std::launch::async, [&] { pass(0, mid); });
    pass(mid, g.ny);
    lower.get();
  };
  bands([&](int r0, int r1) {
    for (size_t i = 0; i < s.centres.size(); ++i) {
      pollStop(stop, i, 4096);
      forCells(s.centres[i], r0, r1, [&](size_t k) { ++count[k]; });
    }
  });
  g.start.assign(ncell + 1, 0);
  for (size_t k = 0; k < ncell; ++k) g.start[k + 1] = g.start[k] + count[k];
  g.items.resize(g.start[ncell]);
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  bands([&](int r0, int r1) {
    for (size_t i = 0; i < s.centres.size(); ++i) {
      pollStop(stop, i, 4096);
      forCells(s.centres[i], r0, r1, [&](size_t k) {
        g.items[fill[k]++] = static_cast<int>(i);
        g.max_z[k] = std::max(g.max_z[k], s.centres[i].z + cd);  // "max z plus collision distance"
        g.max_contact_z[k] = std::max(g.max_contact_z[k], s.centres[i].z + reach(i));
      });
    }
  });
  // Each cell's spheres highest first (ties in index order): the contact kernel stops at the
  // first one below the object sphere's reach, so the layers under a box top (its bottom, the
  // table, the boxes below) cost nothing.
  bands([&](int r0, int r1) {
    for (size_t k = static_cast<size_t>(r0) * g.nx; k < static_cast<size_t>(r1) * g.nx; ++k) {
      pollStop(stop, k, 4096);
      if (g.start[k + 1] - g.start[k] < 2) continue;
      std::sort(g.items.begin() + g.start[k], g.items.begin() + g.start[k + 1], [&](int a, int b) {
        return s.centres[a].z > s.centres[b].z || (s.centres[a].z == s.centres[b].z && a < b);
      });
    }
  });
  return g;
}

}  // namespace place_planner
