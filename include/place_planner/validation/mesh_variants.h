// Mesh variants for the benchmark: decimation (Fig. 6, time against triangle count) and holes
// (unobserved regions). Frames are kept: a variant's vertices are in the source mesh's frame.
#pragma once
#include <cstdint>

#include "place_planner/model/mesh.h"

namespace place_planner {
namespace validation {

// Vertex clustering (Rossignac & Borrel 1993): vertices snap to the mean of their cell of a
// uniform grid; triangles whose corners fall into fewer than three cells vanish, duplicates are
// removed (work_limits.h clusterVertices, the pass the planner's own decimation uses). The cell
// size is bisected until the triangle count is closest to target_triangles.
// Returns the input unchanged when it already has <= target_triangles triangles.
// Throws std::invalid_argument when target_triangles < 4.
Mesh decimateByClustering(const Mesh& mesh, int target_triangles);

// Deletes `fraction` of the triangles in patches: a random seed triangle (std::mt19937 with
// `seed`) grows over edge-adjacent triangles (breadth first) until the patch holds
// patch_fraction of all triangles, repeated until the fraction is reached. Unused vertices are
// dropped; coordinates are unchanged, so the frame is the source's.
// Throws std::invalid_argument for fraction outside [0, 0.9].
Mesh punchHoles(const Mesh& mesh, double fraction, std::uint32_t seed, double patch_fraction = 0.02);

}  // namespace validation
}  // namespace place_planner
