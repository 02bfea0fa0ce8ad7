// Penetration guard for result poses. Frame G (gravity -z).
#pragma once
#include "place_planner/model/scene.h"

namespace place_planner {

// Deepest object vertex below an area surface it is inside of: a ray from the vertex against
// gravity that first meets an area triangle from its back (the triangle's normal points along
// the ray) is inside that surface, by the hit distance times the normal's vertical part (the
// depth along the surface's normal). Hits farther than `max_depth` are
// taken as another surface above (an overhang), not penetration. Assumes the area's patch
// normals point out of its solid parts, as in reconstructed and CAD meshes.
double penetrationDepth(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth = 0.03);

}  // namespace place_planner
