#include <gtest/gtest.h>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/validation/mesh_variants.h"
#include "validation_test_helpers.h"

namespace place_planner {
namespace validation {
namespace {

TEST(MeshVariants, HolesRemoveTheRequestedFractionAndKeepTheFrame) {
  const Mesh full = scenes::cylinder(0.04, 0.1, 200);  // 200 quads + 2 caps
  for (double f : {0.05, 0.1, 0.2}) {
    const Mesh h = punchHoles(full, f, 7);
    const double removed = 1.0 - double(h.triangles.size()) / full.triangles.size();
    EXPECT_NEAR(removed, f, 0.01) << f;
    // Every remaining vertex is one of the source's (same frame).
    for (const auto& p : h.vertices) {
      bool found = false;
      for (const auto& q : full.vertices) found = found || (p - q).norm() < 1e-12;
      ASSERT_TRUE(found);
    }
  }
  EXPECT_EQ(punchHoles(full, 0.1, 7).triangles.size(), punchHoles(full, 0.1, 7).triangles.size());
  EXPECT_THROW(punchHoles(full, 1.0, 7), std::invalid_argument);
}

TEST(MeshVariants, ClusteringHitsTheTargetOnTheFullMug) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025.ply");
  for (int target : {200, 600, 1000}) {
    const Mesh d = decimateByClustering(mug, target);
    EXPECT_NEAR(double(d.triangles.size()), target, 0.1 * target) << target;
    // Shape kept: extents within a few millimetres.
    const Eigen::Vector3d e0 = mug.properties.bounds_max - mug.properties.bounds_min;
    const Eigen::Vector3d e1 = d.properties.bounds_max - d.properties.bounds_min;
    EXPECT_LT((e0 - e1).cwiseAbs().maxCoeff(), 0.015) << target;
  }
}

}  // namespace
}  // namespace validation
}  // namespace place_planner
