// The node's PolygonMesh -> mesh conversion (src/node/conversions.cpp) under fuzzing: what a
// goal or a mesh topic may carry. Built where ROS is: the catkin build's fuzz_regression_tests
// and scripts/fuzz (fuzz_polygon_mesh, against the devel space's generated headers).
#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

}  // namespace fuzz
}  // namespace place_planner
