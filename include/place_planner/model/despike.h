// Noise spikes of a scan (beyond the paper, whose input is a scan but whose planner takes every
// vertex as surface). A depth scan fused into a signed-distance grid and simplified keeps a few
// vertices that stand out of the surface around them by several times the sensor's noise: on a
// mustard bottle's flat bottom, seen in the hand, one vertex 4.2 mm proud of its flat neighbours
// propped the bottle 2.5 degrees off its true rest and 3 mm above it (the true bottle, released
// there, landed on its edge and turned 7 degrees). Such a vertex is an outlier of the noise, not
// a shape: where its neighbours lie on one plane, it is moved onto that plane.
// Frame: the object's own frame O.
#pragma once
#include "place_planner/model/mesh.h"

namespace place_planner {

// A copy of `scan` with each outward noise spike flattened: a vertex off the open rim (edges of
// one triangle: where the scan ends, the rim's own noise is the completion's matter) whose
// neighbours (its one-ring) fit a plane within half of `noise` (RMS), and which stands out
// of that plane, outwards (its faces' mean normal), by more than twice `noise`, is projected onto
// the plane. A real corner or edge has neighbours on two planes or more and is kept. `flattened`
// (may be null): how many vertices moved. A mesh with none is returned unchanged.
Mesh despiked(const Mesh& scan, double noise, int* flattened = nullptr);

}  // namespace place_planner
