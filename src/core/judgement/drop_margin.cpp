// The distance of a pose to a drop-off of the area (drop_margin.h).
#include "place_planner/judgement/drop_margin.h"

#include <algorithm>
#include <cmath>

#include "place_planner/model/height_grid_walk.h"

namespace place_planner {

double dropMargin(const HeightGrid& grid, const Eigen::Vector3d& com_G, double support_z, const DropMarginParams& p) {
  if (grid.nx == 0 || grid.ny == 0 || p.reach <= 0) return 1.0;
  double sum = 0;
  for (int k = 0; k < kGridWalkDirections; ++k) {
    // Where the area ends (off its mesh: a scan's border, a sheet's edge) nothing is known; a
    // wall catches the object: either ends the walk with no drop-off that way.
    const GridStop s = walkOut(grid, com_G.x(), com_G.y(), k, p.reach, [&](double h) {
      return !std::isfinite(h) || h > support_z + p.wall || h < support_z - p.drop;
    });
    const bool drop = std::isfinite(s.t) && std::isfinite(s.height) && s.height < support_z - p.drop;
    sum += (drop ? std::min(s.t, p.reach) : p.reach) / p.reach;
  }
  return sum / kGridWalkDirections;
}

}  // namespace place_planner
