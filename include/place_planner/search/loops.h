// Loops of the object that it can hang by (beyond the paper): a handle's opening, a ring's
// hole. Found from the geometry alone, as holes through the object's silhouette seen along a
// set of directions, so a scan's holes (which rarely line up through the whole object) do not
// hide them. Frame O.
#pragma once
#include <Eigen/Core>
#include <vector>

#include "place_planner/infra/stop_signal.h"
#include "place_planner/model/mesh.h"

namespace place_planner {

struct Loop {
  Eigen::Vector3d centre;  // O: the middle of the opening, halfway through the material around it
  Eigen::Vector3d axis;    // O: unit, the direction the opening is widest seen along
  double radius = 0;       // m: the largest circle through the opening, seen along the axis
  double thickness = 0;    // m: extent along the axis of the material around the opening
};

struct LoopParams {
  double min_radius = 0.004;  // m: smaller openings hang on nothing
  int directions = 32;        // views over the half sphere (about 20 degrees apart), each refined
  double cell = 0;            // m: silhouette pixel (0: the object's size / 64, 1 to 3 mm)
};

// The object's loops, widest first, one per opening. `stop` (may be null) interrupts with Stopped.
std::vector<Loop> findLoops(const Mesh& object, const LoopParams& p = {}, const StopSignal* stop = nullptr);

}  // namespace place_planner
