#include "place_planner/model/completion.h"
#include "place_planner/model/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <future>
#include <atomic>
#include <cstdint>

#include "place_planner/model/area_up.h"
#include "place_planner/model/winding.h"

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

Rigid rotatedAbout(const Rigid& X, const Eigen::Vector3d& s, const Eigen::Vector3d& d, double angle) {
  Eigen::Isometry3d Rot = Eigen::Isometry3d::Identity();
  Rot.linear() = Eigen::AngleAxisd(angle, d.normalized()).toRotationMatrix();
  Rot.translation() = s - Rot.linear() * s;
  return toRigid(Rot * toIsometry(X));
}

Eigen::Matrix3d gravityFrame(const Eigen::Vector3d& gravity_W) {
  // Minimal rotation taking -d_g to +z; identity for the default d_g = -z.
  const Eigen::Vector3d up = -gravity_W.normalized();
  return Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

std::vector<std::array<int, 2>> featureEdges(const Mesh& mesh, double flat_deg, const StopSignal* stop,
                                             const EdgeUses* known_uses) {
  // Each undirected edge with the triangles on it (winding.h), and which side is solid, per
  // connected piece (a scene may merge parts wound either way): on a consistently wound,
  // (nearly) closed piece the winding's normals point out where its signed volume is positive
  // and in where it is negative. Open sheets and scans (more than 2 % border edges) have no
  // inside: every side may be touched (solidSide 0).
  const EdgeUses found = known_uses ? EdgeUses{} : edgeUses(mesh, stop);
  const EdgeUses& uses = known_uses ? *known_uses : found;
  const MeshPieces pieces = meshPieces(mesh, uses);
  auto useOf = [&](int a, int b) { return uses.find(a, b); };
  auto outward = [&](int t) { return pieces.solidSide(t); };

  const double cos_flat = std::cos(flat_deg * M_PI / 180.0);
  auto normal = [&](int t) {
    const auto& tri = mesh.triangles[t];
    return (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
        .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]])
        .normalized();
  };
  std::vector<std::array<int, 2>> out;
  for (size_t ei = 0; ei < mesh.edges.size(); ++ei) {
    pollStop(stop, ei, 1u << 14);
    const auto& e = mesh.edges[ei];
    const EdgeUses::Use* use = useOf(e[0], e[1]);
    if (use && use->count == 2) {
      const int t1 = use->tris[0], t2 = use->tris[1];
      const Eigen::Vector3d n1 = normal(t1);
      if (std::abs(n1.dot(normal(t2))) >= cos_flat) continue;  // flat: the first contact there is a vertex's
      // Concave (valley) edge of a solid: the free space around it is a wedge narrower than a
      // half-space, which another edge can only touch along the valley, never across it; such
      // contacts start at an end point (a vertex/patch test). Only ridges meet edge against edge.
      if (const int out_sign = outward(t1)) {
        int c = 0;  // the vertex of t2 off the edge
        for (int k = 0; k < 3; ++k)
          if (mesh.triangles[t2][k] != e[0] && mesh.triangles[t2][k] != e[1]) c = mesh.triangles[t2][k];
        if (out_sign * n1.dot(mesh.vertices[c] - mesh.vertices[e[0]]) > 0) continue;
      }
    }
    out.push_back(e);
  }
  return out;
}

MeshModel buildMeshModel(const Mesh& mesh, const Eigen::Matrix3d& R, double sphere_radius,
                         const SphereIndexer& index_spheres, const StopSignal* stop, const EdgeUses* uses) {
  MeshModel m;
  m.vertices.reserve(mesh.vertices.size());
  m.bounds = aabbEmpty();
  for (const auto& v : mesh.vertices) {
    m.vertices.push_back(toV3(R * v));
    aabbAdd(m.bounds, m.vertices.back());
  }
  m.triangles = mesh.triangles;
  // The sphere model and its index are independent of the BVHs: built on a second thread
  // (same result).
  auto spheres = std::async(std::launch::async, [&] {
    SphereModel sm = sampleSpheres(m.vertices, m.triangles, mesh.edges, sphere_radius, stop);
    if (stop) stop->throwIfRequested();
    if (index_spheres) index_spheres(sm, m.bounds);
    return sm;
  });
  // A Stopped thrown here waits for the sphere thread (std::async's future), which stops too.
  m.edges = featureEdges(mesh, 2.0, stop, uses);
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
  if (stop) stop->throwIfRequested();
  m.triangle_bvh = buildBvh(tri_boxes);
  m.edge_bvh = buildBvh(edge_boxes);
  m.vertex_bvh = buildBvh(vert_boxes);
  m.spheres = spheres.get();
  return m;
}

ObjectModel buildObjectModel(const Mesh& object_O, double sphere_radius, const StopSignal* stop) {
  ObjectModel o;
  // The object's spheres are reached through a BVH posed with the object.
  static_cast<MeshModel&>(o) = buildMeshModel(
      object_O, Eigen::Matrix3d::Identity(), sphere_radius, [](SphereModel& sm, const Aabb&) {
        std::vector<Aabb> boxes;
        boxes.reserve(sm.centres.size());
        for (const V3& c : sm.centres) boxes.push_back(Aabb{c, c});
        sm.bvh = buildBvh(boxes, 8);
      },
      stop);
  o.com = toV3(object_O.properties.center_of_mass);
  o.bounding_radius = object_O.properties.bounding_radius;
  o.principal_axes = object_O.properties.principal_axes;
  return o;
}

void addProbes(ObjectModel& o, double spacing) {
  // Coarser where `spacing` would give more than kMaxProbes (a large, coarse object).
  constexpr size_t kMaxProbes = 20000;
  o.probe_spacing = spacing;
  for (;;) {
    o.probes = o.vertices;
    const double s = o.probe_spacing;
    // Splits the triangle at its longest edge's midpoint until that edge is at most s.
    std::function<void(const V3&, const V3&, const V3&, int)> split = [&](const V3& a, const V3& b, const V3& c,
                                                                         int depth) {
      const double lab = norm(b - a), lbc = norm(c - b), lca = norm(a - c);
      const double l = std::max({lab, lbc, lca});
      if (l <= s || depth > 24 || o.probes.size() > kMaxProbes) {
        if (depth > 0) o.probes.push_back((a + b + c) * (1.0 / 3.0));
        return;
      }
      if (l == lab) {
        const V3 m = (a + b) * 0.5;
        o.probes.push_back(m);
        split(a, m, c, depth + 1), split(m, b, c, depth + 1);
      } else if (l == lbc) {
        const V3 m = (b + c) * 0.5;
        o.probes.push_back(m);
        split(b, m, a, depth + 1), split(m, c, a, depth + 1);
      } else {
        const V3 m = (c + a) * 0.5;
        o.probes.push_back(m);
        split(c, m, b, depth + 1), split(m, a, b, depth + 1);
      }
    };
    for (const auto& t : o.triangles) split(o.vertices[t[0]], o.vertices[t[1]], o.vertices[t[2]], 0);
    if (o.probes.size() <= kMaxProbes) break;
    o.probe_spacing *= 1.5;
  }
  std::vector<Aabb> boxes;
  boxes.reserve(o.probes.size());
  for (const V3& p : o.probes) boxes.push_back(Aabb{p, p});
  o.probe_bvh = buildBvh(boxes);
}

AreaModel buildAreaModel(const Mesh& area_in_W, const Eigen::Vector3d& gravity_W, double sphere_radius,
                         double collision_distance, double grid_cell, const StopSignal* stop) {
  AreaModel a;
  // Wound outwards first (winding.h): the models read the area's solid side from its winding.
  // Its edge uses serve the feature edges too (reversed, each edge is traversed the other way).
  EdgeUses uses = edgeUses(area_in_W, stop);
  a.winding_reversed = woundInwards(area_in_W, uses, -gravity_W);
  const Mesh reversed = a.winding_reversed ? reversedWinding(area_in_W) : Mesh();
  const Mesh& area_W = a.winding_reversed ? reversed : area_in_W;
  if (a.winding_reversed)
    for (EdgeUses::Use& u : uses.uses) u.forward = u.count - u.forward;
  a.R_GW = gravityFrame(gravity_W);
  // The area's spheres are reached through the height grid (V-B), not a BVH.
  HeightGrid grid;
  static_cast<MeshModel&>(a) = buildMeshModel(
      area_W, a.R_GW, sphere_radius, [&](SphereModel& sm, const Aabb& bounds) {
        grid = buildHeightGrid(sm, bounds, collision_distance, grid_cell, stop);
      },
      stop, &uses);
  a.grid = std::move(grid);
  a.source_triangles = area_W.triangles.size();
  static std::atomic<uint64_t> next_id{1};
  a.id = next_id++;
  a.up_facing_share = upFacingShare(area_W, -gravity_W);
  for (const auto& e : openEdges(area_W))
    a.open_edges.push_back({a.R_GW * area_W.vertices[static_cast<size_t>(e[0])],
                            a.R_GW * area_W.vertices[static_cast<size_t>(e[1])]});
  return a;
}

double rotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

double rotationAngle(const Rigid& a, const Rigid& b) {
  return rotationAngle(toIsometry(a).linear(), toIsometry(b).linear());
}

}  // namespace place_planner
