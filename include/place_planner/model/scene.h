// The prepared planning scene: both meshes as flat arrays with their BVHs and sphere models,
// and the area's 2D height grid. Frames: the object model is in O (the object mesh frame);
// the area model is in G, the planning frame W rotated so that gravity is -z (R_GW), which
// makes the grid of Section V-B axis-aligned in x/y.
#pragma once
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "place_planner/model/bvh.h"
#include "place_planner/model/mesh.h"
#include "place_planner/model/winding.h"
#include "place_planner/infra/stop_signal.h"

namespace place_planner {

struct SphereModel {  // Section V-B: centres 2r apart on every patch
  double radius = 0.0;
  std::vector<V3> centres;
  std::vector<V3> normals;  // unit normal of the patch each sphere was sampled on
  Bvh bvh;                  // over the centres, leaves sorted by index
};

// Height grid (Section V-B): each cell lists the area spheres whose virtual sphere of radius
// `collision distance` overlaps it, and the maximum z of those spheres plus that distance.
struct HeightGrid {
  double x0 = 0, y0 = 0, cell = 1;
  int nx = 0, ny = 0;
  double collision_distance = 0;
  double contact_gap = 0;    // see sphereContact
  std::vector<int> start;    // nx * ny + 1 offsets into items
  std::vector<int> items;    // area sphere indices, each cell's highest first
  std::vector<double> max_z; // per cell; -inf when empty
  // Per cell: the highest object sphere centre that can make a contact there (sphereContact:
  // within contact_gap of an area sphere's plane and over its patch); -inf when empty.
  std::vector<double> max_contact_z;
};

struct MeshModel {
  std::vector<V3> vertices;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::array<int, 2>> edges;  // feature edges only (see featureEdges)
  std::vector<V3> triangle_normals;
  Bvh triangle_bvh, edge_bvh, vertex_bvh;
  SphereModel spheres;
  Aabb bounds;
};

struct ObjectModel : MeshModel {  // frame O
  V3 com;                  // c_O
  double bounding_radius;  // about c_O
  Eigen::Matrix3d principal_axes;
  // The penetration guard's probes (penetration.h; addProbes, empty until then): the vertices
  // and, on triangles longer than probe_spacing, the midpoints of their longest edges, halved
  // until short, and the centroids of the pieces; so a thin part of the area through a coarse
  // mesh's long face (a mug tree's trunk through the side of a 32-sided mug, no vertex of either
  // inside the other) is seen.
  std::vector<V3> probes;
  Bvh probe_bvh;
  double probe_spacing = 0;  // m
};

struct AreaModel : MeshModel {  // frame G
  HeightGrid grid;
  Eigen::Matrix3d R_GW;  // rotation from the planning frame W into G
  double up_facing_share = 1.0;  // of the surface, facing against gravity (area_up.h)
  size_t source_triangles = 0;   // of the mesh given; more than triangles.size() when decimated
  uint64_t id = 0;               // unique per build: the key of the CUDA backend's device copy
  double decimation_cell = 0.0;  // m, cluster size of the decimation (0: none)
  // Borders of what the area's scan saw (edges of one triangle, completion.h), frame G: beyond
  // them the area is unknown, so a pose leaning there needs surface that was not seen.
  std::vector<std::array<Eigen::Vector3d, 2>> open_edges;
  // The mesh given was wound inwards and is modelled wound outwards (winding.h).
  bool winding_reversed = false;
};

// Edges for the edge/edge tests: all but those between two (nearly) coplanar triangles. A
// segment first touches a plane at an end point (or all along, when parallel), so contacts on
// a flat region are found by the vertex/face tests; only creases, silhouettes and hole
// borders can meet as edge against edge. flat_deg bounds the dihedral angle called flat.
// On a closed, consistently wound mesh (a solid) valley edges are dropped too: a crossing
// contact needs both edges to be ridges (see scene.cpp); open sheets keep both kinds.
// `uses`: the mesh's edge uses (winding.h) when known already, else found here.
std::vector<std::array<int, 2>> featureEdges(const Mesh& mesh, double flat_deg = 2.0,
                                             const StopSignal* stop = nullptr, const EdgeUses* uses = nullptr);

// `stop` (may be null) interrupts the builds below with Stopped (stop_signal.h).
// index_spheres(spheres, bounds) builds the index of the sphere model (the object's BVH, the
// area's height grid); it runs on the thread that samples the spheres, beside the BVH builds.
using SphereIndexer = std::function<void(SphereModel&, const Aabb&)>;
MeshModel buildMeshModel(const Mesh& mesh, const Eigen::Matrix3d& R, double sphere_radius,
                         const SphereIndexer& index_spheres = {}, const StopSignal* stop = nullptr,
                         const EdgeUses* uses = nullptr);
ObjectModel buildObjectModel(const Mesh& object_O, double sphere_radius, const StopSignal* stop = nullptr);
// Fills o.probes and o.probe_bvh, at most `spacing` apart on each triangle (coarser past 20000
// probes). The planner adds them where the area has pegs (a hanging pose's guard, penetration.h),
// 4 sphere radii apart: on 12 mug trees (arms 7-10 cm, 8-12 mm, rising 20-40 degrees), 1.5-2.5 cm
// apart still let the YCB mug hang 1-2 cm into an arm on 3 of them, 4 radii on none.
void addProbes(ObjectModel& o, double spacing);
AreaModel buildAreaModel(const Mesh& area_W, const Eigen::Vector3d& gravity_W, double sphere_radius,
                         double collision_distance, double grid_cell, const StopSignal* stop = nullptr);

// Samples sphere centres 2r apart on each triangle, its edges and vertices (sphere_model.cpp).
SphereModel sampleSpheres(const std::vector<V3>& vertices,
                          const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<std::array<int, 2>>& edges, double radius,
                          const StopSignal* stop = nullptr);

HeightGrid buildHeightGrid(const SphereModel& area_spheres, const Aabb& area_bounds,
                           double collision_distance, double cell, const StopSignal* stop = nullptr);

// Rotation taking -gravity to +z (the G frame), with a deterministic choice about z.
Eigen::Matrix3d gravityFrame(const Eigen::Vector3d& gravity_W);

inline V3 toV3(const Eigen::Vector3d& p) { return v3(p.x(), p.y(), p.z()); }
inline Eigen::Vector3d toEigen(V3 p) { return Eigen::Vector3d(p.x, p.y, p.z); }
Rigid toRigid(const Eigen::Isometry3d& T);
Eigen::Isometry3d toIsometry(const Rigid& T);
// Rotation by `angle` about the axis (s, d) applied after X.
Rigid rotatedAbout(const Rigid& X, const Eigen::Vector3d& s, const Eigen::Vector3d& d, double angle);

// Angle (rad) of the rotation between two orientations (host only: scene.cpp).
double rotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);
double rotationAngle(const Rigid& a, const Rigid& b);

}  // namespace place_planner
