// How far a standing pose is from a drop-off of the area (beyond the paper; a ranking term,
// ranking.h). Frame G (gravity -z).
//
// A person puts a mug into a tray's compartment, not on the top of its divider, and a box in
// the middle of a shelf, not at its edge: both hold in a physics engine, but a nudge sends the
// one at the edge over it. The contact forces see only the contacts, so the pose on a 6 mm
// divider top resists a push as well as the one on the compartment's floor. From the centre of
// mass the area's height grid is walked out along kGridWalkDirections horizontal directions
// (height_grid_walk.h), up to `reach`: a cell lower than the support by more than `drop` is a
// drop-off at that distance; a cell higher than the support by more than `wall` catches the
// object (a wall, the side of a cup: no drop-off that way). Where the area ends (no surface: a
// scan's border, a sheet's edge) nothing is known, and that way counts as no drop-off: a scan of
// a table top seen to its edge but not below it says nothing of a drop there.
#pragma once
#include <Eigen/Core>

#include "place_planner/model/scene.h"

namespace place_planner {

struct DropMarginParams {
  double reach = 0.1;   // m: the object's size; drop-offs farther away do not count
  double drop = 0.01;   // m below the support: a drop-off, not a dent
  double wall = 0.01;   // m above the support: a wall
};

// The mean over the directions of the distance to a drop-off over `reach` (each at most 1):
// 1 in the middle of a table, in a cup or a compartment; about 0.5 on a narrow wall top over a
// floor.
// `com_G`: the centre of mass, `support_z`: the height of the lowest contact (G).
double dropMargin(const HeightGrid& grid, const Eigen::Vector3d& com_G, double support_z, const DropMarginParams& p);

}  // namespace place_planner
