#include "place_planner/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <future>
#include <map>

namespace place_planner {

Rigid toRigid(const Eigen::Isometry3d& T) {
  Rigid r;
  for (int i = 0; i < 9; ++i) r.R[i] = T.linear()(i / 3, i % 3);
  r.t = toV3(T.translation());
  return r;
}

Eigen::Isometry3d toIsometry(const Rigid& r) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 9; ++i) T.linear()(i / 3, i % 3) = r.R[i];
  T.translation() = toEigen(r.t);
  return T;
}

Eigen::Matrix3d gravityFrame(const Eigen::Vector3d& gravity_W) {
  // Minimal rotation taking -d_g to +z; identity for the default d_g = -z.
  const Eigen::Vector3d up = -gravity_W.normalized();
  return Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

std::vector<std::array<int, 2>> featureEdges(const Mesh& mesh, double flat_deg) {
  std::map<std::pair<int, int>, std::vector<int>> adjacent;
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      int a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      adjacent[{a, b}].push_back(static_cast<int>(t));
    }
  const double cos_flat = std::cos(flat_deg * M_PI / 180.0);
  auto normal = [&](int t) {
    const auto& tri = mesh.triangles[t];
    return (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
        .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]])
        .normalized();
  };
  std::vector<std::array<int, 2>> out;
  for (const auto& e : mesh.edges) {
    const auto it = adjacent.find({e[0], e[1]});
    if (it != adjacent.end() && it->second.size() == 2 &&
        std::abs(normal(it->second[0]).dot(normal(it->second[1]))) >= cos_flat)
      continue;  // flat: the first contact there is a vertex's (see scene.h)
    out.push_back(e);
  }
  return out;
}

MeshModel buildMeshModel(const Mesh& mesh, const Eigen::Matrix3d& R, double sphere_radius,
                         bool sphere_bvh) {
  MeshModel m;
  m.vertices.reserve(mesh.vertices.size());
  m.bounds = aabbEmpty();
  for (const auto& v : mesh.vertices) {
    m.vertices.push_back(toV3(R * v));
    aabbAdd(m.bounds, m.vertices.back());
  }
  m.triangles = mesh.triangles;
  // The sphere model is independent of the BVHs: built on a second thread (same result).
  auto spheres = std::async(std::launch::async, [&] {
    SphereModel sm = sampleSpheres(m.vertices, m.triangles, mesh.edges, sphere_radius);
    if (sphere_bvh) {
      std::vector<Aabb> sphere_boxes;
      sphere_boxes.reserve(sm.centres.size());
      for (const V3& c : sm.centres) sphere_boxes.push_back(Aabb{c, c});
      sm.bvh = buildBvh(sphere_boxes, 8);
    }
    return sm;
  });
  m.edges = featureEdges(mesh);
  std::vector<Aabb> tri_boxes, edge_boxes, vert_boxes;
  tri_boxes.reserve(m.triangles.size());
  for (const auto& t : m.triangles) {
    Aabb b = aabbEmpty();
    for (int k = 0; k < 3; ++k) aabbAdd(b, m.vertices[t[k]]);
    tri_boxes.push_back(b);
    m.triangle_normals.push_back(normalized(
        cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]])));
  }
  for (const auto& e : m.edges) {
    Aabb b = aabbEmpty();
    aabbAdd(b, m.vertices[e[0]]);
    aabbAdd(b, m.vertices[e[1]]);
    edge_boxes.push_back(b);
  }
  for (const auto& v : m.vertices) vert_boxes.push_back(Aabb{v, v});
  m.triangle_bvh = buildBvh(tri_boxes);
  m.edge_bvh = buildBvh(edge_boxes);
  m.vertex_bvh = buildBvh(vert_boxes);
  m.spheres = spheres.get();
  return m;
}

ObjectModel buildObjectModel(const Mesh& object_O, double sphere_radius) {
  ObjectModel o;
  static_cast<MeshModel&>(o) = buildMeshModel(object_O, Eigen::Matrix3d::Identity(), sphere_radius);
  o.com = toV3(object_O.properties.center_of_mass);
  o.bounding_radius = object_O.properties.bounding_radius;
  o.principal_axes = object_O.properties.principal_axes;
  return o;
}

AreaModel buildAreaModel(const Mesh& area_W, const Eigen::Vector3d& gravity_W, double sphere_radius,
                         double collision_distance, double grid_cell) {
  AreaModel a;
  a.R_GW = gravityFrame(gravity_W);
  // The area's spheres are reached through the height grid, not a BVH.
  static_cast<MeshModel&>(a) = buildMeshModel(area_W, a.R_GW, sphere_radius, false);
  a.grid = buildHeightGrid(a.spheres, a.bounds, collision_distance, grid_cell);
  return a;
}

}  // namespace place_planner
