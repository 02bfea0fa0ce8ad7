// Floor points in the middle of the area's openings (opening_points.h).
#include "place_planner/search/opening_points.h"

#include <algorithm>
#include <cmath>

#include "place_planner/model/height_grid_walk.h"

namespace place_planner {
namespace {

constexpr int kCentring = 4;  // moves to the walls' mean

struct Walls {
  int hits = 0;                 // directions that met a wall within reach
  double nearest = kInf;        // m: the nearest wall
  double mx = 0, my = 0;        // the mean of the hits (a direction without one: its reach)
};

// Walks out from (x, y) at floor height h round the point (height_grid_walk.h).
Walls walls(const HeightGrid& g, double x, double y, double h, const OpeningParams& p) {
  Walls w;
  const double top = h + p.wall_height;
  for (int k = 0; k < kGridWalkDirections; ++k) {
    const GridStop wall = walkOut(g, x, y, k, p.reach, [top](double z) { return z > top; });
    const double r = std::isfinite(wall.t) ? wall.t : p.reach;
    w.hits += std::isfinite(wall.t);
    const double a = gridWalkAngle(k);
    w.nearest = std::min(w.nearest, r);
    w.mx += (x + r * std::cos(a)) / kGridWalkDirections;
    w.my += (y + r * std::sin(a)) / kGridWalkDirections;
  }
  return w;
}

}  // namespace

std::vector<V3> openingCentres(const HeightGrid& grid, const std::vector<V3>& floor_points, const OpeningParams& p,
                               const StopSignal* stop) {
  std::vector<V3> out;
  if (grid.nx == 0 || grid.ny == 0 || p.reach <= 0) return out;
  const int min_hits = static_cast<int>(std::ceil(p.min_enclosed * kGridWalkDirections));
  auto near = [&](const V3& c, const std::vector<V3>& pts) {
    for (const V3& q : pts)
      if (std::hypot(c.x - q.x, c.y - q.y) < p.merge && std::abs(c.z - q.z) < p.wall_height) return true;
    return false;
  };
  for (const V3& fp : floor_points) {
    if (static_cast<int>(out.size()) >= p.max_openings) break;
    if (stop) stop->throwIfRequested();
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

OpeningFit fitIntoOpening(const HeightGrid& grid, const V3& centre, const Eigen::Matrix3d& R_GO,
                          const std::vector<V3>& surface_O, const V3& com_O, double margin) {
  constexpr int kTurns = 24;
  OpeningFit best;
  const double floor = gridHeightAt(grid, centre.x, centre.y);
  if (!std::isfinite(floor) || surface_O.empty()) return best;
  // At most 256 points, spread over the surface; about the centre of mass, turned by R_GO.
  const size_t stride = std::max<size_t>(1, surface_O.size() / 256);
  const Eigen::Vector3d c = R_GO * toEigen(com_O);
  std::vector<Eigen::Vector3d> pts;
  double low = kInf;
  for (size_t i = 0; i < surface_O.size(); i += stride) {
    pts.push_back(R_GO * toEigen(surface_O[i]) - c);
    low = std::min(low, pts.back().z());
  }
  int best_hits[2] = {-1, -1};
  std::vector<Eigen::Vector2d> turned(pts.size());
  for (int k = 0; k < kTurns; ++k) {
    // 0, +15, -15, +30, ... degrees: the smallest turn first among equal fits.
    const double yaw = (k % 2 ? 1 : -1) * ((k + 1) / 2) * 2 * M_PI / kTurns;
    const Eigen::Rotation2Dd R(yaw);
    Eigen::Vector2d lo(kInf, kInf), hi(-kInf, -kInf);
    for (size_t i = 0; i < pts.size(); ++i) {
      turned[i] = R * pts[i].head<2>();
      lo = lo.cwiseMin(turned[i]);
      hi = hi.cwiseMax(turned[i]);
    }
    const Eigen::Vector2d mid = 0.5 * (lo + hi);
    int hits[2] = {0, 0};  // as it is, and grown by margin
    for (size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector2d q = Eigen::Vector2d(centre.x, centre.y) + turned[i] - mid;
      const double top = floor + (pts[i].z() - low);  // the point's height, the object on the floor
      const Eigen::Vector2d out = (turned[i] - mid).norm() > 1e-9 ? Eigen::Vector2d((turned[i] - mid).normalized()) : Eigen::Vector2d::Zero();
      hits[0] += gridHeightAt(grid, q.x(), q.y()) > top;
      hits[1] += gridHeightAt(grid, q.x() + margin * out.x(), q.y() + margin * out.y()) > top;
    }
    if (best_hits[0] < 0 || hits[0] < best_hits[0] || (hits[0] == best_hits[0] && hits[1] < best_hits[1])) {
      best_hits[0] = hits[0];
      best_hits[1] = hits[1];
      best.yaw = yaw;
      best.shift = -mid;
    }
    if (hits[0] == 0 && hits[1] == 0) break;
  }
  return best;
}

}  // namespace place_planner
