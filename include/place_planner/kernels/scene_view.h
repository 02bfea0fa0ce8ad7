// Raw-pointer views of the prepared scene, valid on the host or (with device pointers) in
// CUDA kernels. Built from scene.h models by view(); the CUDA backend uploads the arrays and
// fills the same structs with device pointers.
#pragma once
#include "place_planner/model/bvh.h"

namespace place_planner {

struct MeshView {
  const V3* vertices;
  const int* triangles;  // 3 per triangle
  const int* edges;      // 2 per edge
  const V3* triangle_normals;
  int num_vertices, num_triangles, num_edges;
  BvhView triangle_bvh, edge_bvh, vertex_bvh;
  const V3* sphere_centres;
  const V3* sphere_normals;
  int num_spheres;
  double sphere_radius;
  BvhView sphere_bvh;
  Aabb bounds;
};

struct GridView {
  double x0, y0, cell;
  int nx, ny;
  double collision_distance;
  double contact_gap;  // max separation along the area normal of a contact
  const int* start;
  const int* items;
  // The highest object sphere centre that can make a contact, per cell (HeightGrid). The grid's
  // max_z is host-only (the fall test): no kernel reads it, so it is not on the device.
  const double* max_contact_z;
};

struct ObjectView {
  MeshView mesh;  // frame O
  V3 com;         // c_O in O
  double bounding_radius;
};

struct AreaView {
  MeshView mesh;  // frame G
  GridView grid;
};

}  // namespace place_planner
