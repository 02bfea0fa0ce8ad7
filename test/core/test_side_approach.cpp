// Areas approached from the side (a shelf, a cabinet): floor points by rays along d_vis reach the
// inner boards; the object ends on a board, clear of the one above, and its pre-place pose lies
// back along the approach.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "place_planner/infra/scenes.h"
#include "place_planner/planner.h"

namespace place_planner {
namespace {

TEST(SideApproach, MugGoesOnAnInnerShelfBoardClearOfTheOneAbove) {
  const Mesh mug = scenes::mug();
  const Mesh shelf = scenes::shelfUnit(4);  // the geometry of the benchmark's shelf, fewer triangles
  PlannerConfig cfg;
  cfg.approach = Eigen::Vector3d(0, 1, 0);
  cfg.floor_point_spacing = 0.15;
  const PlanResult r = Planner().plan(mug, shelf, cfg);
  ASSERT_GT(r.stableCount(), 0);
  int inner = 0;
  for (const Candidate& c : r.candidates) {
    if (!c.stable) continue;
    double lo = 1e9, hi = -1e9;
    for (const auto& v : mug.vertices) {
      const double z = (c.X_WO * v).z();
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
    // Board tops at 0.02 + 0.45 k; the board above starts 0.43 m higher.
    const double k = std::round((lo - 0.02) / 0.45);
    const double top = 0.02 + 0.45 * k;
    EXPECT_NEAR(lo, top, 0.003) << "not resting on a board";
    EXPECT_LT(hi, top + 0.43) << "into the board above";
    inner += k < 5;  // below the top board: reached from the side, not from above
    // Inside the unit, between its side walls and in front of its back wall.
    EXPECT_GT((c.X_WO * mug.properties.center_of_mass).x(), -0.5);
    EXPECT_LT((c.X_WO * mug.properties.center_of_mass).x(), 0.5);
    // The pre-place pose lies back along the approach: in front of the goal (smaller y).
    if (c.placement.checked && c.placement.straight) {
      const Eigen::Vector3d back = c.placement.pre_place_W.translation() - c.X_WO.translation();
      EXPECT_LT(back.normalized().y(), -0.99);
    }
  }
  EXPECT_GT(inner, 0) << "no stable pose on an inner board";
  // The best stands upright on its base, as a person would put a mug on a shelf.
  const Candidate& best = r.candidates.front();
  ASSERT_TRUE(best.stable);
  EXPECT_GT((best.X_WO.linear() * Eigen::Vector3d::UnitZ()).z(), 0.99);
}

}  // namespace
}  // namespace place_planner
