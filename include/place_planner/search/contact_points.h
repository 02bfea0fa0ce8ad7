// Contact points (Section V-B), host side: the per-sphere contacts of the contact kernel
// reduced to a small set of contact points for the tilt axis, stability and the output.
#pragma once
#include <vector>

#include "place_planner/kernels/placement_kernels.h"
#include "place_planner/planner.h"

namespace place_planner {

// Clusters the per-sphere contacts in a voxel grid of size `cell` (frame G): one contact per
// occupied voxel at the mean position with the normalised mean normal. The result is sorted by
// voxel, so it does not depend on the order of `raw`. Empty input gives an empty result.
std::vector<ContactPoint> reduceContacts(const std::vector<SphereContact>& raw, double cell);

// The same clustering applied to contact points (coarser summaries for the result).
std::vector<ContactPoint> reduceContacts(const std::vector<ContactPoint>& contacts, double cell);

}  // namespace place_planner
