#include <fstream>
#include <unistd.h>

#include "place_planner/infra/mesh_io.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {
// Surface area, centroid and second moments are exact; tolerances only absorb rounding.
constexpr double kTol = 1e-9;

std::string tmpFile(const std::string& name, const std::string& content) {
  const std::string path = "/tmp/pp_test_" + std::to_string(getpid()) + "_" + name;
  std::ofstream(path, std::ios::binary) << content;
  return path;
}
}  // namespace

TEST(Mesh, UnitCubeProperties) {
  const Mesh m = scenes::box(1, 1, 1, {0.5, 0.5, 0.5});
  EXPECT_EQ(m.patches.size(), 6u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.edges.size(), 12u);
  EXPECT_NEAR(m.properties.surface_area, 6.0, kTol);
  EXPECT_TRUE(m.properties.center_of_mass.isApprox(Eigen::Vector3d(0.5, 0.5, 0.5), kTol));
  // Surface of a cube is isotropic: all eigenvalues equal. For one face at distance 1/2 from the
  // centre, int x^2 over the 6 faces / 6 = (2 * 1/4 + 4 * 1/12) / 6 = 5/36.
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(m.properties.eigenvalues[i], 5.0 / 36.0, 1e-9);
  EXPECT_NEAR(m.properties.bounding_radius, std::sqrt(3.0) / 2, kTol);
  // Normals point outward.
  for (size_t i = 0; i < m.patches.size(); ++i) {
    const Eigen::Vector3d c = m.vertices[m.patches[i][0]] - m.properties.center_of_mass;
    EXPECT_GT(c.dot(m.patch_normals[i]), 0.0) << "patch " << i;
  }
}

TEST(Mesh, CylinderPrincipalAxisAlongLength) {
  const Mesh m = scenes::cylinder(0.02, 0.3, 24);
  EXPECT_EQ(m.patches.size(), 26u);  // 24 sides + 2 convex caps kept whole
  EXPECT_NEAR(std::abs(m.properties.k1().z()), 1.0, 1e-9);
  EXPECT_GT(m.properties.eigenvalues[0], m.properties.eigenvalues[1]);
  EXPECT_NEAR(m.properties.eigenvalues[1], m.properties.eigenvalues[2], 1e-9);
  EXPECT_LT(m.properties.center_of_mass.norm(), 1e-9);
}

TEST(Mesh, PlateFirstAxisInPlane) {
  const Mesh m = scenes::plate();
  EXPECT_LT(std::abs(m.properties.k1().z()), 1e-6);
  EXPECT_NEAR(std::abs(m.properties.principal_axes.col(2).z()), 1.0, 1e-6);
  EXPECT_NEAR(m.properties.principal_axes.determinant(), 1.0, 1e-9);
}

TEST(Mesh, PlaneCentroidAndBounds) {
  const Mesh m = scenes::plane(2.0, 1.0);
  EXPECT_NEAR(m.properties.surface_area, 2.0, kTol);
  EXPECT_TRUE(m.properties.bounds_min.isApprox(Eigen::Vector3d(-1, -0.5, 0), kTol));
  EXPECT_TRUE(m.properties.bounds_max.isApprox(Eigen::Vector3d(1, 0.5, 0), kTol));
  EXPECT_NEAR(m.properties.eigenvalues[2], 0.0, kTol);
  EXPECT_NEAR(m.properties.eigenvalues[0], 4.0 / 12.0, kTol);  // x variance of width 2
}

TEST(Mesh, NonConvexPolygonIsSplit) {
  // An L-shaped hexagon (area 3) in the z = 0 plane.
  std::vector<Eigen::Vector3d> v = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  const Mesh m = buildMesh(v, {{0, 1, 2, 3, 4, 5}});
  EXPECT_EQ(m.report.split_polygons, 1);
  EXPECT_EQ(m.patches.size(), 4u);
  EXPECT_NEAR(m.properties.surface_area, 3.0, kTol);
  for (const auto& n : m.patch_normals) EXPECT_NEAR(n.z(), 1.0, kTol);
  // Centroid of the L: (1*1.5*... ) = ((2*1)*(1,0.5) + (1*1)*(0.5,1.5)) / 3 = (5/6, 5/6).
  EXPECT_TRUE(m.properties.center_of_mass.isApprox(Eigen::Vector3d(5. / 6, 5. / 6, 0), 1e-9));
}

TEST(Mesh, NonPlanarQuadIsSplit) {
  std::vector<Eigen::Vector3d> v = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.3}, {0, 1, 0}};
  const Mesh m = buildMesh(v, {{0, 1, 2, 3}});
  EXPECT_EQ(m.report.split_polygons, 1);
  EXPECT_EQ(m.patches.size(), 2u);
}

TEST(Mesh, ZeroAreaDroppedAndCounted) {
  std::vector<Eigen::Vector3d> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  const Mesh m = buildMesh(v, {{0, 1, 2}, {0, 1, 3}, {1, 1, 2}});
  EXPECT_EQ(m.patches.size(), 1u);
  EXPECT_EQ(m.report.dropped_zero_area, 2);
}

TEST(Mesh, ErrorsNameTheElement) {
  std::vector<Eigen::Vector3d> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_THROW(buildMesh({}, {{0, 1, 2}}), MeshError);
  EXPECT_THROW(buildMesh(v, {}), MeshError);
  try {
    buildMesh(v, {{0, 1, 2}, {0, 1, 7}}, "object mesh");
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("polygon 1 refers to vertex 7"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("object mesh"), std::string::npos);
  }
  try {
    buildMesh(v, {{0, 1}});
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("polygon 0 has 2 vertices"), std::string::npos) << e.what();
  }
  auto bad = v;
  bad[2].y() = std::nan("");
  try {
    buildMesh(bad, {{0, 1, 2}});
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 2 has a non-finite coordinate (y"), std::string::npos)
        << e.what();
  }
  bad[2].y() = INFINITY;
  EXPECT_THROW(buildMesh(bad, {{0, 1, 2}}), MeshError);
  EXPECT_THROW(buildMesh({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}}), MeshError);  // all degenerate
}

TEST(MeshIo, AsciiPlyObjStlAgree) {
  const std::string ply = tmpFile("t.ply",
      "ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nelement face 2\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n3 0 1 2\n3 0 2 3\n");
  const std::string obj = tmpFile("t.obj", "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n");
  const std::string stl = tmpFile("t.stl",
      "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\n"
      "endfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
      "endfacet\nendsolid s\n");
  for (const auto& path : {ply, obj, stl}) {
    const Mesh m = loadMesh(path);
    EXPECT_EQ(m.vertices.size(), 4u) << path;
    EXPECT_NEAR(m.properties.surface_area, 1.0, 1e-9) << path;
    EXPECT_TRUE(m.properties.center_of_mass.isApprox(Eigen::Vector3d(0.5, 0.5, 0), 1e-9)) << path;
    std::remove(path.c_str());
  }
}

TEST(MeshIo, BinaryPlyRoundTrip) {
  const Mesh m = scenes::mug();
  const std::string path = "/tmp/pp_test_" + std::to_string(getpid()) + "_rt.ply";
  saveMeshPly(m, path, true);
  const Mesh r = loadMesh(path);
  EXPECT_EQ(r.patches.size(), m.patches.size());
  EXPECT_NEAR(r.properties.surface_area, m.properties.surface_area, 1e-6);
  EXPECT_TRUE(r.properties.center_of_mass.isApprox(m.properties.center_of_mass, 1e-5));
  saveMeshPly(m, path, false);
  EXPECT_EQ(loadMesh(path).patches.size(), m.patches.size());
  std::remove(path.c_str());
}

TEST(MeshIo, BadFilesGiveClearErrors) {
  EXPECT_THROW(loadMesh("/nonexistent/x.ply"), MeshError);
  EXPECT_THROW(loadMesh("/tmp/x.dae"), MeshError);
  const std::string trunc = tmpFile("trunc.ply",
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\nabc");
  try {
    loadMesh(trunc);
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("unexpected end"), std::string::npos) << e.what();
  }
  std::remove(trunc.c_str());
}

TEST(Scenes, BuiltInScenesAreValid) {
  for (const auto& n : scenes::areaNames()) {
    const Mesh m = scenes::byName(n);
    EXPECT_GT(m.patches.size(), 0u) << n;
    EXPECT_NEAR(m.properties.bounds_min.x(), -m.properties.bounds_max.x(), 1e-3) << n << " centred";
  }
  for (const auto& n : scenes::objectNames()) EXPECT_GT(scenes::byName(n).properties.surface_area, 0) << n;
  EXPECT_NEAR(std::abs(scenes::pen().properties.k1().z()), 1.0, 1e-6);
  EXPECT_THROW(scenes::byName("sofa"), std::invalid_argument);
}
