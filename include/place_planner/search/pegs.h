// Pegs, hooks and rails of the area that an object can hang on (beyond the paper, whose
// planner "is currently not able to hang objects"): a thin part, longer than it is thick, with
// free space above its top, beside it and below it on both sides, and one free end to thread a
// loop over. Frame G (gravity -z), found from the geometry alone.
#pragma once
#include <Eigen/Core>
#include <vector>

#include "place_planner/infra/stop_signal.h"
#include "place_planner/model/scene.h"

namespace place_planner {

struct Peg {
  Eigen::Vector3d point;  // G: on the peg's axis, half its thickness under its top
  Eigen::Vector3d axis;   // G: unit, along the peg from its base to its free end (the tip)
  double half_width = 0;  // m: half the larger of its thickness and its width
  double to_tip = 0;      // m: from `point` to the tip along `axis`
  double to_base = 0;     // m: from `point` back to where the peg meets the rest of the area
};

struct PegParams {
  double max_thickness = 0.03;   // m: thicker parts are not pegs (a shelf board is 2 cm, but wide)
  double min_thickness = 0.003;  // m: thinner ones bend (a cover's edge, a sheet)
  double min_free_side = 0.01;   // m: room beside it for a loop's side
  double min_free_below = 0.04;  // m: room under it for what hangs
  double min_free_above = 0.008; // m: room over its top for a loop
  double min_tip_free = 0.04;    // m: free beyond the tip, along the axis
  double max_slope_deg = 60;     // axis at most this far from horizontal
  int max_samples = 1500;        // up-facing triangles probed (every k-th beyond)
};

// The area's pegs, one per peg (samples along one peg merged, the one nearest its middle kept),
// in a deterministic order. `stop` (may be null) interrupts with Stopped.
std::vector<Peg> findPegs(const AreaModel& area, const PegParams& p = {}, const StopSignal* stop = nullptr);

}  // namespace place_planner
