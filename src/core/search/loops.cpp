// Loops of the object (loops.h): each view rasterises the triangles into a silhouette; empty
// pixels that the outside cannot reach are openings through the object.
#include "place_planner/search/loops.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <deque>

namespace place_planner {
namespace {

struct View {
  int w = 0, h = 0;
  std::vector<char> solid;
  std::vector<float> depth_lo, depth_hi;  // along the view direction, of the triangles over a pixel
};

// Fills the pixels of triangle (a, b, c) (2D + depth); edges are drawn too, so a wall seen edge
// on still blocks.
void rasterise(View& v, const std::array<Eigen::Vector3d, 3>& t) {
  auto mark = [&](int x, int y, double lo, double hi) {
    if (x < 0 || y < 0 || x >= v.w || y >= v.h) return;
    const int i = y * v.w + x;
    v.solid[i] = 1;
    v.depth_lo[i] = std::min<float>(v.depth_lo[i], lo);
    v.depth_hi[i] = std::max<float>(v.depth_hi[i], hi);
  };
  const double lo = std::min({t[0].z(), t[1].z(), t[2].z()}), hi = std::max({t[0].z(), t[1].z(), t[2].z()});
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector3d& p = t[e];
    const Eigen::Vector3d& q = t[(e + 1) % 3];
    const int n = 1 + static_cast<int>(2 * (q - p).head<2>().norm());
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector3d r = p + (q - p) * (static_cast<double>(k) / n);
      mark(static_cast<int>(std::floor(r.x())), static_cast<int>(std::floor(r.y())), lo, hi);
    }
  }
  const double x0 = std::floor(std::min({t[0].x(), t[1].x(), t[2].x()})), x1 = std::max({t[0].x(), t[1].x(), t[2].x()});
  const double y0 = std::floor(std::min({t[0].y(), t[1].y(), t[2].y()})), y1 = std::max({t[0].y(), t[1].y(), t[2].y()});
  const Eigen::Vector2d a = t[0].head<2>(), b = t[1].head<2>(), c = t[2].head<2>();
  auto edge = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
  };
  const double area = edge(a, b, c);
  if (std::abs(area) < 1e-12) return;
  for (double y = y0; y <= y1; ++y)
    for (double x = x0; x <= x1; ++x) {
      const Eigen::Vector2d m(x + 0.5, y + 0.5);
      const double u = edge(b, c, m) / area, w = edge(c, a, m) / area, s = edge(a, b, m) / area;
      if (u >= 0 && w >= 0 && s >= 0) mark(static_cast<int>(x), static_cast<int>(y), lo, hi);
    }
}

// Directions over the half sphere (a Fibonacci lattice): a view and its opposite see one silhouette.
std::vector<Eigen::Vector3d> halfSphere(int n) {
  std::vector<Eigen::Vector3d> d;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = (i + 0.5) / n, r = std::sqrt(1 - z * z), a = golden * i;
    d.emplace_back(r * std::cos(a), r * std::sin(a), z);
  }
  return d;
}

}  // namespace

std::vector<Loop> findLoops(const Mesh& object, const LoopParams& p, const StopSignal* stop) {
  const MeshProperties& mp = object.properties;
  const double size = (mp.bounds_max - mp.bounds_min).norm();
  const double cell = p.cell > 0 ? p.cell : std::clamp(size / 64, 0.001, 0.003);
  const Eigen::Vector3d mid = 0.5 * (mp.bounds_max + mp.bounds_min);
  const int n = static_cast<int>(std::ceil(size / cell)) + 4;  // the bounding sphere's diameter, and a border
  // The openings seen along d, each with its area (pixels): seen along its axis an opening is
  // widest, and its area (as cos of the view's angle) tells the axis finer than its radius does.
  struct Seen {
    Loop loop;
    int area;
  };
  int view_index = 0;
  auto view = [&](const Eigen::Vector3d& d) {
    std::vector<Seen> found;
    pollStop(stop, view_index++, 8);
    const Eigen::Vector3d e1 = d.unitOrthogonal(), e2 = d.cross(e1);
    // Pixel coordinates (x, y) and depth (z, metres along d) of a point.
    auto pixel = [&](const Eigen::Vector3d& q) {
      const Eigen::Vector3d r = q - mid;
      return Eigen::Vector3d(r.dot(e1) / cell + 0.5 * n, r.dot(e2) / cell + 0.5 * n, r.dot(d));
    };
    View v;
    v.w = v.h = n;
    v.solid.assign(n * n, 0);
    v.depth_lo.assign(n * n, 1e9f);
    v.depth_hi.assign(n * n, -1e9f);
    for (const auto& f : object.triangles)
      rasterise(v, {pixel(object.vertices[f[0]]), pixel(object.vertices[f[1]]), pixel(object.vertices[f[2]])});
    // Closed by one pixel (a gap of a pixel in a thin handle's outline is a scan's hole), then
    // the outside flooded from the border; what it cannot reach is an opening.
    std::vector<char> closed = v.solid;
    for (int y = 1; y + 1 < n; ++y)
      for (int x = 1; x + 1 < n; ++x)
        if (v.solid[y * n + x])
          for (const int k : {-1, 1, -n, n}) closed[y * n + x + k] = 1;
    std::vector<char> outside(n * n, 0);
    std::deque<int> queue;
    for (int i = 0; i < n; ++i)
      for (const int j : {i, (n - 1) * n + i, i * n, i * n + n - 1})
        if (!closed[j] && !outside[j]) outside[j] = 1, queue.push_back(j);
    auto flood = [&](std::vector<char>& mark, std::deque<int>& q, std::vector<int>* members) {
      while (!q.empty()) {
        const int i = q.front();
        q.pop_front();
        if (members) members->push_back(i);
        const int x = i % n, y = i / n;
        for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          const int X = x + dx, Y = y + dy;
          if (X < 0 || Y < 0 || X >= n || Y >= n) continue;
          const int j = Y * n + X;
          if (!closed[j] && !mark[j]) mark[j] = 1, q.push_back(j);
        }
      }
    };
    flood(outside, queue, nullptr);
    // Chamfer distance (pixels) from each free pixel to the nearest solid one.
    std::vector<float> dist(n * n);
    for (int i = 0; i < n * n; ++i) dist[i] = closed[i] ? 0.f : 1e9f;
    const float diag = std::sqrt(2.f);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        float& m = dist[y * n + x];
        if (x > 0) m = std::min(m, dist[y * n + x - 1] + 1);
        if (y > 0) m = std::min(m, dist[(y - 1) * n + x] + 1);
        if (x > 0 && y > 0) m = std::min(m, dist[(y - 1) * n + x - 1] + diag);
        if (x + 1 < n && y > 0) m = std::min(m, dist[(y - 1) * n + x + 1] + diag);
      }
    for (int y = n - 1; y >= 0; --y)
      for (int x = n - 1; x >= 0; --x) {
        float& m = dist[y * n + x];
        if (x + 1 < n) m = std::min(m, dist[y * n + x + 1] + 1);
        if (y + 1 < n) m = std::min(m, dist[(y + 1) * n + x] + 1);
        if (x + 1 < n && y + 1 < n) m = std::min(m, dist[(y + 1) * n + x + 1] + diag);
        if (x > 0 && y + 1 < n) m = std::min(m, dist[(y + 1) * n + x - 1] + diag);
      }
    // Each enclosed opening: its widest point, and the material around it for the depth.
    std::vector<char> seen = outside;
    for (int i = 0; i < n * n; ++i) {
      if (closed[i] || seen[i]) continue;
      std::vector<int> members;
      seen[i] = 1;
      queue.push_back(i);
      flood(seen, queue, &members);
      const int centre = *std::max_element(members.begin(), members.end(),
                                           [&](int a, int b) { return dist[a] < dist[b]; });
      // Drawn edges and the closing fatten the solid by about a pixel and a half.
      const double radius = (dist[centre] + 1.5) * cell;
      if (radius < p.min_radius) continue;
      std::vector<float> mids, extents;
      const int cx = centre % n, cy = centre / n, reach = static_cast<int>(dist[centre]) + 3;
      for (int y = std::max(0, cy - reach); y <= std::min(n - 1, cy + reach); ++y)
        for (int x = std::max(0, cx - reach); x <= std::min(n - 1, cx + reach); ++x) {
          const int j = y * n + x;
          if (!v.solid[j] || std::hypot(x - cx, y - cy) > reach) continue;
          mids.push_back(0.5f * (v.depth_lo[j] + v.depth_hi[j]));
          extents.push_back(v.depth_hi[j] - v.depth_lo[j]);
        }
      if (mids.empty()) continue;
      std::nth_element(mids.begin(), mids.begin() + mids.size() / 2, mids.end());
      std::nth_element(extents.begin(), extents.begin() + extents.size() / 2, extents.end());
      const double x = (cx + 0.5 - 0.5 * n) * cell, y = (cy + 0.5 - 0.5 * n) * cell;
      found.push_back(Seen{Loop{mid + x * e1 + y * e2 + mids[mids.size() / 2] * d, d, radius, extents[extents.size() / 2]},
                           static_cast<int>(members.size())});
    }
    return found;
  };
  std::vector<Seen> found;
  for (const Eigen::Vector3d& d : halfSphere(p.directions))
    for (Seen& o : view(d)) found.push_back(o);
  // One per opening: views of the same opening (centres within its diameter) keep the widest.
  std::stable_sort(found.begin(), found.end(), [](const Seen& a, const Seen& b) {
    return a.loop.radius != b.loop.radius ? a.loop.radius > b.loop.radius : a.area > b.area;
  });
  std::vector<Seen> kept;
  for (const Seen& o : found) {
    bool same = false;
    for (const Seen& k : kept) same = same || (o.loop.centre - k.loop.centre).norm() < std::max(2 * k.loop.radius, 0.01);
    if (!same) kept.push_back(o);
  }
  // Each axis refined by views 5 then 2.5 degrees apart about it, to the one where the same
  // opening's area is largest.
  std::vector<Loop> loops;
  for (Seen best : kept) {
    for (const double step : {10.0, 5.0, 2.5}) {
      const Eigen::Vector3d d0 = best.loop.axis, u = d0.unitOrthogonal(), v = d0.cross(u);
      const Seen around = best;
      for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 1; ++j) {
          if (i == 0 && j == 0) continue;
          const Eigen::Vector3d d = (d0 + std::tan(step * i * M_PI / 180) * u + std::tan(step * j * M_PI / 180) * v).normalized();
          for (const Seen& o : view(d))
            if ((o.loop.centre - around.loop.centre).norm() < std::max(around.loop.radius, 0.005) && o.area > best.area) best = o;
        }
    }
    loops.push_back(best.loop);
  }
  return loops;
}

}  // namespace place_planner
