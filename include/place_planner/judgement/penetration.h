// Penetration guard for result poses. Frame G (gravity -z).
#pragma once
#include <optional>

#include "place_planner/model/scene.h"

namespace place_planner {

// Deepest object probe (a vertex, or a point on a long triangle: ObjectModel::probes) inside
// the area: a ray from the probe (against gravity, and along the four horizontal axes of G)
// that first meets an area triangle from its back (the triangle's normal points along the ray)
// starts inside that surface, by the hit distance times the normal's part along the ray (the
// depth along the surface's normal); a probe's depth is the least over its rays that start
// inside (inside a vertical post only the sideways rays see it).
// Hits farther than `max_depth` are taken as another surface (an overhang), not penetration.
// Assumes the area's patch normals point out of its solid parts, as in reconstructed and CAD
// meshes.
double penetrationDepth(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth = 0.03, bool dense = true);

// The same (depth), and the deepest below a surface straight above (the upward rays alone:
// the guard's measure before the sideways rays, still held to a sphere radius).
struct Penetration {
  double depth = 0;
  double below = 0;
  // The guard's rule (the planner's result and the swing's moves): at most below_limit below a
  // surface and sideways_limit in any (0: not checked).
  bool within(double below_limit, double sideways_limit) const {
    return below <= below_limit && (sideways_limit <= 0 || depth <= sideways_limit);
  }
};
// dense: all the object's probes (ObjectModel::probes), else its vertices only. A standing pose
// comes from V-C's exact rotations, each stopped at the first contact of the sphere models, so
// its vertices suffice; a hanging pose's swing lowers each move straight down after a turn,
// which can push a long face sideways over a thin post or arm: the result's guard checks a
// hanging pose densely (the probes are 10-70 times the vertices).
Penetration penetration(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                        double max_depth = 0.03, bool dense = true);

// The translation (G) that takes the object out of the area: the deepest probe moved out of its
// surface along that surface's normal, `gap` beyond it, again until no probe is inside. A
// hanging pose settles within its contact band against a wall (sideways up to the contact
// distance, the guard above), where a robot's release would collide. None when more than
// max_steps moves or a shift over max_shift would be needed.
std::optional<V3> clearingShift(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO, double gap,
                                double max_shift, int max_steps = 6);

// The pose (G) out of the area that is nearest X_GO: clearingShift's, or, where no shift clears
// it (jammed between two surfaces, a shift out of one pushing it into the other: a basket's
// handle in a J-hook's turned-up tip, its back in the wall), the object turned first by 1, 2
// or 4 degrees about an axis of G through `pivot` (its support), the least turn that a shift
// then clears. None when neither clears it.
std::optional<Rigid> clearedPose(const ObjectModel& object, const AreaModel& area, const Rigid& X_GO,
                                 const V3& pivot, double gap, double max_shift);

}  // namespace place_planner
