// Bounded work on any input (beyond the paper): the checks that run before each costly step,
// the one automatic step (decimating a mesh over max_triangles) and the stop signal that lets a
// cancel or the time budget interrupt the setup steps (models, floor points, resting faces).
// Frames: none; sizes in metres.
#pragma once
#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "place_planner/config.h"
#include "place_planner/model/mesh.h"
#include "place_planner/infra/stop_signal.h"

namespace place_planner {

// The input is too large for the limits in the config; the message names the mesh, the
// limit's field and, for sizes, the likely unit mistake.
class LimitError : public std::invalid_argument {
 public:
  explicit LimitError(const std::string& what) : std::invalid_argument(what) {}
};

// Sizes in metres. Throws LimitError when the object is larger than max_object_size or the
// area larger than max_area_size (both say "is it in millimetres?"); returns warnings for an
// object larger than the area.
std::vector<std::string> checkMeshSizes(const Mesh& object, const Mesh& area, const PlannerConfig& config);

// Bytes of a mesh model with surface spheres of radius r (scene.h): spheres, BVHs, triangles
// and, for an area (cd > 0), the height grid with cells of `cell`. An estimate within a factor
// of about 1.5, computed in O(triangles) before anything is allocated.
// Counts are capped at max_triangles (what decimation leaves).
double estimateModelBytes(const Mesh& mesh, double r, double cd = 0.0, double cell = 0.0,
                          size_t max_triangles = static_cast<size_t>(-1));

// One pass of vertex clustering (Rossignac & Borrel 1993) with cells of size h from the mesh's
// bounds_min: each vertex snaps to the mean of its cell; a triangle survives when its corners
// fall in three cells and it keeps some area, once per set of three cells (the first, in
// triangle order). Cell indices must fit 21 bits (h >= extent / 2^20). Shared by decimated()
// and the benchmark's validation::decimateByClustering.
struct Clustered {
  std::vector<Eigen::Vector3d> vertices;  // cluster means, in order of first vertex
  std::vector<std::array<int, 3>> triangles;
};
Clustered clusterVertices(const Mesh& mesh, double h, const StopSignal* stop = nullptr);

// Vertex clustering on a grid, coarsened until at most max_triangles remain (the only
// automatic step: a documented loss of detail finer than the returned cell). Frame and
// centre of mass stay those of the input; `cell_out` is the cluster size used.
Mesh decimated(const Mesh& mesh, size_t max_triangles, double* cell_out = nullptr,
               const StopSignal* stop = nullptr);

}  // namespace place_planner
