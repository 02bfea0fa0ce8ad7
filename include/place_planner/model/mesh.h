// The polygonal surface mesh of the paper (Section III): convex planar patches, vertices
// counter-clockwise seen from the outside (the side the patch normal points to).
// Built from triangles or arbitrary polygons; sensor meshes with holes are fine (no
// watertightness is assumed anywhere).
#pragma once
#include <Eigen/Core>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "place_planner/infra/stop_signal.h"

namespace place_planner {

// Misuse of the mesh API or a broken input: the message names the element and index.
class MeshError : public std::invalid_argument {
 public:
  explicit MeshError(const std::string& what) : std::invalid_argument(what) {}
};

// What buildMesh changed while making patches convex and planar.
struct MeshBuildReport {
  int dropped_zero_area = 0;   // degenerate polygons/triangles removed
  int split_polygons = 0;      // non-planar or non-convex polygons split into triangles
  int fanned_polygons = 0;     // ... of them self-intersecting: what ear clipping left is a fan
};

// Polygons with more vertices are rejected (MeshError): ear clipping costs about n^2.
constexpr size_t kMaxPolygonVertices = 10000;

// Derived properties (Section III). Frame: the mesh's own frame.
struct MeshProperties {
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();  // c_O: area-weighted surface centroid
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();  // columns k1, k2, k3
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();         // lambda1 >= lambda2 >= lambda3
  Eigen::Vector3d bounds_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bounds_max = Eigen::Vector3d::Zero();
  double surface_area = 0.0;
  double bounding_radius = 0.0;  // max distance of a vertex from center_of_mass
  Eigen::Vector3d k1() const { return principal_axes.col(0); }
};

struct Mesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> patches;          // convex planar, CCW about patch_normals
  std::vector<Eigen::Vector3d> patch_normals;     // unit
  std::vector<std::array<int, 3>> triangles;      // fan triangulation of the patches
  std::vector<int> triangle_patch;                // patch of each triangle
  std::vector<std::array<int, 2>> edges;          // unique patch-boundary edges (i < j)
  MeshProperties properties;
  MeshBuildReport report;

  bool empty() const { return patches.empty(); }
};

// Validates and builds a mesh. Throws MeshError for: no vertices or no polygons ("empty mesh"),
// a NaN/Inf coordinate ("vertex 12 has a non-finite coordinate"), an index out of range
// ("polygon 5 refers to vertex 1200 but the mesh has 1000 vertices"), a polygon with fewer than
// 3 vertices. Zero-area polygons are dropped and counted; non-planar or non-convex polygons are
// split into triangles (ear clipping in their best-fit plane). Throws when nothing is left.
// `name` prefixes the messages (e.g. "object mesh").
// `stop` (may be null; stop_signal.h) interrupts a long build with Stopped.
Mesh buildMesh(const std::vector<Eigen::Vector3d>& vertices,
               const std::vector<std::vector<int>>& polygons, const std::string& name = "mesh",
               const StopSignal* stop = nullptr);

// Recomputes centre of mass (area-weighted over the surface, since sensor meshes are not
// watertight), principal axes of the surface's second moment, bounds and bounding radius.
MeshProperties computeProperties(const Mesh& mesh);

// For each triangle, the triangles that share an edge with it (several across a non-manifold
// edge, none across a hole's border).
std::vector<std::vector<int>> triangleNeighbours(const Mesh& mesh);

// Returns a copy with every vertex mapped by T (rotation R, translation t); properties recomputed.
Mesh transformed(const Mesh& mesh, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

}  // namespace place_planner
