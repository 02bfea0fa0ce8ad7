// Every mesh in ../shared/data loads, validates and has sane extents and principal axes.
#include <dirent.h>

#include <fstream>
#include <sstream>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/model/completion.h"
#include "test_helpers.h"

using namespace place_planner;

TEST(SharedData, EveryManifestMeshLoads) {
  PP_REQUIRE_SHARED_DATA();
  std::ifstream in(test::sharedData() + "/MANIFEST.tsv");
  std::string line;
  std::getline(in, line);  // header
  int checked = 0;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string kind, file, tris, ext;
    std::getline(ls, kind, '\t');
    std::getline(ls, file, '\t');
    std::getline(ls, tris, '\t');
    std::getline(ls, ext, '\t');
    double ex, ey, ez;
    char c;
    std::istringstream es(ext);
    es >> ex >> c >> ey >> c >> ez;
    const Mesh m = loadMesh(test::sharedData() + "/" + file);
    const Eigen::Vector3d size = m.properties.bounds_max - m.properties.bounds_min;
    EXPECT_NEAR(size.x(), ex, 2e-3) << file;
    EXPECT_NEAR(size.y(), ey, 2e-3) << file;
    EXPECT_NEAR(size.z(), ez, 2e-3) << file;
    // Triangle count as listed (decimation may leave a few degenerate ones that are dropped).
    EXPECT_NEAR(static_cast<double>(m.triangles.size()), std::stod(tris), 0.02 * std::stod(tris) + 2) << file;
    const auto& p = m.properties;
    EXPECT_GE(p.eigenvalues[0], p.eigenvalues[1]) << file;
    EXPECT_GE(p.eigenvalues[1], p.eigenvalues[2]) << file;
    EXPECT_GE(p.eigenvalues[2], -1e-12) << file;
    EXPECT_NEAR(p.principal_axes.determinant(), 1.0, 1e-6) << file;
    // The centre of mass lies inside the bounds.
    EXPECT_TRUE((p.center_of_mass.array() >= p.bounds_min.array() - 1e-9).all()) << file;
    EXPECT_TRUE((p.center_of_mass.array() <= p.bounds_max.array() + 1e-9).all()) << file;
    if (kind == "area") EXPECT_NEAR(p.bounds_min.z(), 0.0, 2e-3) << file << " rests on z = 0";
    ++checked;
  }
  EXPECT_GE(checked, 20);
}

TEST(SharedData, MarkerAndPlateAxes) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh marker = loadMesh(test::sharedData() + "/objects/marker_ycb040_1k.ply");
  EXPECT_GT(std::abs(marker.properties.k1().y()), 0.95);  // 0.121 m long along y
  const Mesh plate = loadMesh(test::sharedData() + "/objects/plate_ycb029_1k.ply");
  EXPECT_GT(std::abs(plate.properties.principal_axes.col(2).z()), 0.95);  // flat: k3 is the normal
}

TEST(SharedData, ScanWithHolesLoads) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh scan = loadMesh(test::sharedData() + "/areas/tissuebox_scan_scene.ply");
  EXPECT_GT(scan.triangles.size(), 9000u);
  // Boundary edges (used by one triangle) exist: the scan is not watertight.
  EXPECT_GT(openEdges(scan).size(), 10u);
}
