// Hanging roots (beyond the paper): an object threaded by one of its loops onto one of the
// area's pegs, clear of both, from where the tree's first translation (along gravity, V-A)
// lowers the loop onto the peg and the swing (tree_stepper.cpp) brings it to rest. Frame G.
#pragma once
#include <Eigen/Geometry>
#include <vector>

#include "place_planner/infra/backend.h"
#include "place_planner/model/scene.h"
#include "place_planner/search/loops.h"
#include "place_planner/search/pegs.h"

namespace place_planner {

struct HangingStart {
  Rigid X_GO;                  // threaded: the peg through the loop's middle, touching nothing
  double drop = 0;             // m: the translation along -z that lowers the loop onto the peg
  Eigen::Vector3d approach;    // G, unit: the threading motion, along the peg towards its base
  double approach_distance = 0;  // m: from wholly beyond the tip to the threaded pose, checked free
  Eigen::Vector3d peg_point;   // G: where on the peg (reported as the candidate's floor point)
  // Rolled about the peg and turned about the vertical off its rest: its tree swings to rest
  // before the fall cut may end it (PegLine::swing_first).
  bool turned = false;
  double room = 0;  // m: the loop's largest circle less the peg's half width
};

// For each peg (in order) and each loop wide enough for it, both ways round the peg: the loop's
// axis along the peg, turned about it so that the centre of mass hangs below the loop, and far
// enough along the peg that the object clears the peg's base (or, where it reaches back past
// the room, that the loop does), centred on the peg, off it a little or lifted over a tip that
// turns up. Kept when the object's sphere model sweeps along the peg from beyond its tip to
// that pose without touching the area (the first free of each peg, loop and way round). Where
// none is, the same lifted by two to four times the loop's room (a slot long along the hang),
// then the same turned a quarter about the peg either way and lifted by up to four times the
// loop's room (an opening longer than its largest circle passes a tall turned-up tip upright),
// these kept when the object also meets the peg moving up and moving down from it (round it);
// where none of those is, the same also turned 20, 35 or 50 degrees either way about the
// vertical. On a peg rising more than half the friction angle atan(friction) / 2 it is then slid
// down the peg to its first contact there (the wall, a post), where it would come to rest.
std::vector<HangingStart> hangingStarts(const std::vector<Peg>& pegs, const std::vector<Loop>& loops,
                                        const ObjectModel& om, Backend& backend, double collision_distance,
                                        double friction);

}  // namespace place_planner
