// Reading the area's height grid (scene.h) at a point and walking out from one along horizontal
// directions, a cell at a time. Frame G (gravity -z). The openings' middles (opening_points.h)
// and the drop margin (drop_margin.h) both walk the grid this way.
#pragma once
#include <cmath>

#include "place_planner/model/scene.h"

namespace place_planner {

// Directions of a walk round a point: every 22.5 degrees; direction k's angle from +x (rad).
constexpr int kGridWalkDirections = 16;
inline double gridWalkAngle(int k) { return 2 * M_PI * k / kGridWalkDirections; }

// The grid's top at (x, y) (G): its highest sphere centre plus the collision distance;
// -infinity (not finite) off the grid or over an empty cell.
double gridHeightAt(const HeightGrid& grid, double x, double y);

// Where a walk stopped: at distance t (infinite when it did not), over a cell of this height.
struct GridStop {
  double t = INFINITY;
  double height = -INFINITY;
};

// Walks from (x, y) along direction k of kGridWalkDirections, one cell at a time while the
// distance is within `reach` rounded up to a cell, and stops at the first cell whose height
// `stop` accepts.
template <typename Stop>
GridStop walkOut(const HeightGrid& grid, double x, double y, int k, double reach, const Stop& stop) {
  const double a = gridWalkAngle(k), cx = std::cos(a), cy = std::sin(a);
  const int steps = static_cast<int>(std::ceil(reach / grid.cell));
  for (int s = 1; s <= steps; ++s) {
    const double t = s * grid.cell;
    const double h = gridHeightAt(grid, x + t * cx, y + t * cy);
    if (stop(h)) return GridStop{t, h};
  }
  return GridStop{};
}

}  // namespace place_planner
