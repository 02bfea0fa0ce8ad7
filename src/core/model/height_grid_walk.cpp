// The height grid read at a point (height_grid_walk.h).
#include "place_planner/model/height_grid_walk.h"

#include <limits>

namespace place_planner {

double gridHeightAt(const HeightGrid& g, double x, double y) {
  const int ix = static_cast<int>(std::floor((x - g.x0) / g.cell));
  const int iy = static_cast<int>(std::floor((y - g.y0) / g.cell));
  if (ix < 0 || iy < 0 || ix >= g.nx || iy >= g.ny) return -std::numeric_limits<double>::infinity();
  return g.max_z[static_cast<size_t>(iy) * g.nx + ix];
}

}  // namespace place_planner
