// Floor points in the middle of the area's openings (opening_points.h).
#include "place_planner/search/opening_points.h"

#include <algorithm>
#include <cmath>

namespace place_planner {
namespace {

constexpr int kDirections = 16;
constexpr int kCentring = 4;  // moves to the walls' mean

struct Walls {
  int hits = 0;                 // directions that met a wall within reach
  double nearest = kInf;        // m: the nearest wall
  double mx = 0, my = 0;        // the mean of the hits (a direction without one: its reach)
};

// Walks out from (x, y) at floor height h along kDirections directions, a cell at a time.
Walls walls(const HeightGrid& g, double x, double y, double h, const OpeningParams& p) {
  Walls w;
  const int steps = static_cast<int>(std::ceil(p.reach / g.cell));
  for (int k = 0; k < kDirections; ++k) {
    const double a = 2 * M_PI * k / kDirections, cx = std::cos(a), cy = std::sin(a);
    double r = p.reach;
    for (int s = 1; s <= steps; ++s) {
      const double t = s * g.cell;
      if (gridHeightAt(g, x + t * cx, y + t * cy) > h + p.wall_height) {
        r = t;
        ++w.hits;
        break;
      }
    }
    w.nearest = std::min(w.nearest, r);
    w.mx += (x + r * cx) / kDirections;
    w.my += (y + r * cy) / kDirections;
  }
  return w;
}

}  // namespace

double gridHeightAt(const HeightGrid& g, double x, double y) {
  const int ix = static_cast<int>(std::floor((x - g.x0) / g.cell));
  const int iy = static_cast<int>(std::floor((y - g.y0) / g.cell));
  if (ix < 0 || iy < 0 || ix >= g.nx || iy >= g.ny) return -kInf;
  return g.max_z[static_cast<size_t>(iy) * g.nx + ix];
}

std::vector<V3> openingCentres(const HeightGrid& grid, const std::vector<V3>& floor_points, const OpeningParams& p) {
  std::vector<V3> out;
  if (grid.nx == 0 || grid.ny == 0 || p.reach <= 0) return out;
  const int min_hits = static_cast<int>(std::ceil(p.min_enclosed * kDirections));
  auto near = [&](const V3& c, const std::vector<V3>& pts) {
    for (const V3& q : pts)
      if (std::hypot(c.x - q.x, c.y - q.y) < p.merge && std::abs(c.z - q.z) < p.wall_height) return true;
    return false;
  };
  for (const V3& fp : floor_points) {
    // The floor's height in the grid (its spheres' tops), the ray's hit for the point.
    const double h = gridHeightAt(grid, fp.x, fp.y);
    if (!std::isfinite(h)) continue;
    double x = fp.x, y = fp.y;
    Walls w = walls(grid, x, y, h, p);
    if (w.hits < min_hits) continue;  // open ground, an edge or a corner: not an opening
    bool on_floor = true;
    for (int it = 0; it < kCentring && on_floor; ++it) {
      if (std::hypot(w.mx - x, w.my - y) < 0.25 * grid.cell) break;
      x = w.mx;
      y = w.my;
      // Moved onto something (a peg between two others): not a floor of this opening.
      on_floor = std::abs(gridHeightAt(grid, x, y) - h) <= p.wall_height;
      if (on_floor) w = walls(grid, x, y, h, p);
    }
    if (!on_floor || w.hits < min_hits || w.nearest < p.min_clearance) continue;
    const V3 c = v3(x, y, fp.z);
    if (near(c, floor_points) || near(c, out)) continue;
    out.push_back(c);
  }
  return out;
}

double fittingYaw(const HeightGrid& grid, const V3& centre, const Eigen::Matrix3d& R_GO,
                  const std::vector<V3>& surface_O, const V3& com_O) {
  constexpr int kTurns = 24;
  const double floor = gridHeightAt(grid, centre.x, centre.y);
  if (!std::isfinite(floor) || surface_O.empty()) return 0.0;
  // At most 256 points, spread over the surface.
  const size_t stride = std::max<size_t>(1, surface_O.size() / 256);
  const Eigen::Vector3d c = R_GO * toEigen(com_O);
  double low = kInf;
  for (size_t i = 0; i < surface_O.size(); i += stride) low = std::min(low, (R_GO * toEigen(surface_O[i])).z());
  int best_hits = -1;
  double best = 0;
  for (int k = 0; k < kTurns; ++k) {
    // 0, +15, -15, +30, ... degrees: the smallest turn first among equal fits.
    const double yaw = (k % 2 ? 1 : -1) * ((k + 1) / 2) * 2 * M_PI / kTurns;
    const double cy = std::cos(yaw), sy = std::sin(yaw);
    int hits = 0;
    for (size_t i = 0; i < surface_O.size(); i += stride) {
      const Eigen::Vector3d v = R_GO * toEigen(surface_O[i]) - c;
      const double x = centre.x + cy * v.x() - sy * v.y(), y = centre.y + sy * v.x() + cy * v.y();
      hits += gridHeightAt(grid, x, y) > floor + (v.z() + c.z() - low);
    }
    if (best_hits < 0 || hits < best_hits) {
      best_hits = hits;
      best = yaw;
    }
    if (hits == 0) break;
  }
  return best;
}

}  // namespace place_planner
