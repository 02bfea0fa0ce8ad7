// Floor points (Section IV-B). Frame G.
#pragma once
#include <vector>

#include "place_planner/model/scene.h"

namespace place_planner {

struct FloorPointParams {
  V3 d_vis;                 // approach direction (unit), rays are parallel to it
  double spacing = 0.09;    // m between neighbouring rays
  int min_points = 16;      // spacing is halved (up to 6 times) until this many rays hit
  int lowest_n = 0;         // > 0: keep the n lowest hits along gravity (box-like areas)
  int max_rays = 5000;      // a spacing that would cast more rays is coarsened to fit
  bool has_region = false;  // keep hits inside [region_lo, region_hi] only
  V3 region_lo, region_hi;
};

struct FloorPoints {
  std::vector<V3> points;  // visible hit points, in grid order (deterministic)
  double spacing = 0;      // as finally used
  bool coarsened = false;  // the spacing asked for would have cast more than max_rays
};

// Casts a grid of rays parallel to d_vis over the area's extent (perpendicular to d_vis) and
// keeps the first hit of each: the visible points of the area.
// `stop` (may be null) interrupts the casting with Stopped.
FloorPoints floorPoints(const AreaModel& area, const FloorPointParams& p, const StopSignal* stop = nullptr);

}  // namespace place_planner
