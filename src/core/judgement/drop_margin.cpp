// The distance of a pose to a drop-off of the area (drop_margin.h).
#include "place_planner/judgement/drop_margin.h"

#include <algorithm>
#include <cmath>

#include "place_planner/search/opening_points.h"

namespace place_planner {

double dropMargin(const HeightGrid& grid, const Eigen::Vector3d& com_G, double support_z, const DropMarginParams& p) {
  constexpr int kDirections = 16;
  if (grid.nx == 0 || grid.ny == 0 || p.reach <= 0) return 1.0;
  const int steps = static_cast<int>(std::ceil(p.reach / grid.cell));
  double sum = 0;
  for (int k = 0; k < kDirections; ++k) {
    const double a = 2 * M_PI * k / kDirections, cx = std::cos(a), cy = std::sin(a);
    double d = p.reach;
    for (int s = 1; s <= steps; ++s) {
      const double t = s * grid.cell;
      const double h = gridHeightAt(grid, com_G.x() + t * cx, com_G.y() + t * cy);
      // Where the area ends (off its mesh: a scan's border, a sheet's edge) nothing is known.
      if (!std::isfinite(h) || h > support_z + p.wall) break;  // unknown, or caught by a wall
      if (h < support_z - p.drop) {                             // over a drop-off
        d = t;
        break;
      }
    }
    sum += std::min(d, p.reach) / p.reach;
  }
  return sum / kDirections;
}

}  // namespace place_planner
