// The node's PolygonMesh and shape_msgs/Mesh -> mesh conversions (src/node/conversions.cpp)
// under fuzzing: what a goal or a mesh topic may carry. Built where ROS is: the catkin build's fuzz_regression_tests
// and scripts/fuzz (fuzz_polygon_mesh, against the devel space's generated headers).
#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_targets.h"
#include "place_planner/ros/conversions.h"

namespace place_planner {
namespace fuzz {

void polygonMesh(const uint8_t* data, size_t size) {
  static const char* kNames[] = {"x", "y", "z", "rgb", "intensity", ""};
  Bytes b(data, size);
  pcl_msgs::PolygonMesh msg;
  sensor_msgs::PointCloud2& cloud = msg.cloud;
  cloud.height = b.byte() % 4;
  cloud.width = b.u16() % 512;
  cloud.point_step = b.byte();
  // Mostly a consistent row step, sometimes any (too short, or padded).
  cloud.row_step = b.flag() ? cloud.width * cloud.point_step + b.byte() % 8 : b.u32();
  cloud.is_bigendian = b.byte() % 16 == 0;
  const int n_fields = b.byte() % 6;
  for (int i = 0; i < n_fields; ++i) {
    sensor_msgs::PointField f;
    f.name = kNames[b.byte() % 6];
    f.offset = b.flag() ? b.byte() % 32 : b.u32();
    f.datatype = b.byte() % 10;  // 1..8 are PointField's types; 0 and 9 are not
    f.count = 1;
    cloud.fields.push_back(f);
  }
  const int n_polygons = b.byte() % 16;
  for (int i = 0; i < n_polygons; ++i) {
    pcl_msgs::Vertices poly;
    const int n = b.byte() % 7;
    for (int j = 0; j < n; ++j) poly.vertices.push_back(b.flag() ? b.byte() % 64 : b.u32());
    msg.polygons.push_back(poly);
  }
  const std::string bytes = b.take(b.u16() % 8192);
  cloud.data.assign(bytes.begin(), bytes.end());

  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> polygons;
  try {
    fromMsg(msg, "fuzz", &vertices, &polygons);
  } catch (const MeshError&) {
    return;  // a cloud it cannot read, refused as documented
  }
  // conversions.h: every point of the height x width cloud is one vertex; one polygon each.
  if (vertices.size() != static_cast<size_t>(cloud.width) * cloud.height) violated("one vertex per point");
  if (polygons.size() != msg.polygons.size()) violated("one polygon per Vertices");
  for (size_t i = 0; i < polygons.size(); ++i) {
    if (polygons[i].size() != msg.polygons[i].vertices.size()) violated("polygon lengths kept");
    for (size_t j = 0; j < polygons[i].size(); ++j) {
      if (polygons[i][j] < 0) violated("an index above INT_MAX must be clamped, not wrapped");
    }
  }
  if (std::getenv("PP_FUZZ_VERBOSE")) {  // what the input became
    for (const auto& v : vertices) std::fprintf(stderr, "v %.17g %.17g %.17g\n", v.x(), v.y(), v.z());
    for (const auto& p : polygons) {
      std::fprintf(stderr, "f");
      for (int i : p) std::fprintf(stderr, " %d", i);
      std::fprintf(stderr, "\n");
    }
  }
  Mesh mesh;
  try {
    mesh = buildMesh(vertices, polygons, "fuzz");
  } catch (const MeshError&) {
    return;
  }
  checkMesh(mesh);
  // And back: toMsg writes float32 x, y, z that fromMsg reads as they were.
  pcl_msgs::PolygonMesh again;
  toMsg(mesh, "world", &again);
  std::vector<Eigen::Vector3d> v2;
  std::vector<std::vector<int>> p2;
  fromMsg(again, "round trip", &v2, &p2);
  if (v2.size() != mesh.vertices.size() || p2 != mesh.patches) violated("toMsg/fromMsg round trip changed the mesh");
  for (size_t i = 0; i < v2.size(); ++i) {
    if (v2[i] != mesh.vertices[i].cast<float>().cast<double>()) violated("round trip changed a vertex");
  }
}

void shapeMesh(const uint8_t* data, size_t size) {
  Bytes b(data, size);
  shape_msgs::Mesh msg;
  const int n_vertices = b.byte() % 64;
  for (int i = 0; i < n_vertices; ++i) {
    geometry_msgs::Point p;
    // Raw float64 bit patterns sometimes (NaN, Inf, 1e300), small coordinates mostly.
    auto coordinate = [&] {
      if (!b.flag()) return b.range(-1, 1);
      const std::string bits = b.take(8);
      double v = 0;
      std::memcpy(&v, bits.data(), std::min<size_t>(8, bits.size()));
      return v;
    };
    p.x = coordinate();
    p.y = coordinate();
    p.z = coordinate();
    msg.vertices.push_back(p);
  }
  const int n_triangles = b.byte() % 64;
  for (int t = 0; t < n_triangles; ++t) {
    shape_msgs::MeshTriangle tri;
    for (auto& i : tri.vertex_indices) i = b.flag() ? b.byte() % 72 : b.u32();
    msg.triangles.push_back(tri);
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> polygons;
  try {
    fromMsg(msg, "fuzz shape", &vertices, &polygons);
  } catch (const MeshError& e) {
    // Refused only for an index past the vertices, and the message names the triangle.
    if (std::string(e.what()).find("triangle") == std::string::npos) violated("shape refused without naming the triangle");
    return;
  }
  if (vertices.size() != msg.vertices.size()) violated("one vertex per shape vertex");
  if (polygons.size() != msg.triangles.size()) violated("one polygon per shape triangle");
  for (const auto& p : polygons)
    for (int i : p)
      if (i < 0 || i >= static_cast<int>(vertices.size())) violated("an index past the vertices got through");
  Mesh mesh;
  try {
    mesh = buildMesh(vertices, polygons, "fuzz shape");
  } catch (const MeshError&) {
    return;
  }
  checkMesh(mesh);
  // And back: float64 both ways, the vertices exactly.
  shape_msgs::Mesh again;
  toMsg(mesh, &again);
  std::vector<Eigen::Vector3d> v2;
  std::vector<std::vector<int>> p2;
  fromMsg(again, "round trip", &v2, &p2);
  if (v2 != mesh.vertices) violated("shape round trip changed a vertex");
  size_t fan = 0;
  for (const auto& patch : mesh.patches) fan += patch.size() - 2;
  if (p2.size() != fan) violated("shape round trip: one triangle per fan triangle of the patches");
}

}  // namespace fuzz
}  // namespace place_planner
