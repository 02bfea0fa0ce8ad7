// Floor points in the middle of the area's openings (beyond the paper's grid of rays, IV-B):
// where a person puts an object into a cup, a crock, a holder or a tray's compartment. Frame G
// (gravity -z), rays along gravity only.
//
// The paper's floor points are a grid of rays at a spacing set for the whole area: an opening
// a little wider than the object gets a few of them, off its middle, and an object lowered
// there lands on the rim (the YCB mustard over a 13 cm crock: 4 of 16 floor points inside, each
// a few centimetres off the middle, no pose inside). From each floor point, the height grid is
// walked out along kGridWalkDirections horizontal directions (height_grid_walk.h) to the first
// wall, a cell higher than the floor point by `wall_height`, or to `reach`. Where walls stand in
// most directions the point lies in an opening; it is moved to the mean of the walls' hits (for
// a round opening its middle), a few times, and kept when the opening there is wide enough for
// the object's narrowest side.
#pragma once
#include <Eigen/Core>
#include <vector>

#include "place_planner/model/scene.h"

namespace place_planner {

struct OpeningParams {
  double reach = 0.1;         // m: how far from a floor point a wall counts (the object's size)
  double wall_height = 0.01;  // m above the floor point: a wall, not a bump of the floor
  double min_clearance = 0;   // m: the opening's narrowest half-width must reach this
  double merge = 0.01;        // m: a centre this close to a floor point or another centre is not added
  double min_enclosed = 0.75; // share of the directions that must meet a wall
  int max_openings = 64;      // bounded work: at most this many middles (each root there is fitted)
};

// The middles of the openings around `floor_points` (G), each at its floor's height, not
// within `merge` of a floor point or of each other, in the order of the floor points they came from,
// at most max_openings. `stop` (may be null) interrupts it with Stopped.
std::vector<V3> openingCentres(const HeightGrid& grid, const std::vector<V3>& floor_points, const OpeningParams& p,
                               const StopSignal* stop = nullptr);

// How the object goes into the opening at `centre`, turned by R_GO: turned about the vertical by
// `yaw` (rad), its centre of mass `shift` from the centre (G), so that its footprint's middle is
// over the opening's. The turn fits the fewest of its surface points (frame O: the sphere model's
// centres) over area higher than the point stands above the object's lowest, when the object
// rests on the opening's floor (a mug's handle along a compartment's longer side), then the
// fewest with the footprint grown by `margin`; of equal fits the smallest turn. 24 turns.
struct OpeningFit {
  double yaw = 0;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
};
OpeningFit fitIntoOpening(const HeightGrid& grid, const V3& centre, const Eigen::Matrix3d& R_GO,
                          const std::vector<V3>& surface_O, const V3& com_O, double margin = 0.01);

}  // namespace place_planner
