// bounded work on any input. Each limit is checked before the work it bounds and
// gives a named error or a reported automatic step; a cancel and the budget reach the setup.
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>

#include "place_planner/planner.h"
#include "place_planner/model/scene.h"
#include "place_planner/infra/work_limits.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {

// A wavy square sheet of 2 n^2 triangles, 1 m wide, at z = 0 (+- 1 mm): a big scan of a table.
Mesh sheet(int n) {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      v.emplace_back(-0.5 + i / double(n), -0.5 + j / double(n), 0.001 * std::sin(0.3 * i) * std::cos(0.2 * j));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      f.push_back({a, a + 1, a + n + 2});
      f.push_back({a, a + n + 2, a + n + 1});
    }
  return buildMesh(v, f, "sheet");
}

bool hasWarning(const PlanResult& r, const std::string& part) {
  for (const auto& w : r.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

std::string thrownBy(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

PlannerConfig quick() {
  PlannerConfig c;
  c.threads = 2;
  c.max_candidates = 3;
  return c;
}

}  // namespace

TEST(Limits, MugInMillimetresNamesTheUnit) {
  const Mesh mug = scenes::mug();
  const Mesh mug_mm = transformed(mug, 1000.0 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const std::string what = thrownBy([&] { Planner().plan(mug_mm, scenes::table(), quick()); });
  EXPECT_NE(what.find("object mesh"), std::string::npos) << what;
  EXPECT_NE(what.find("max_object_size"), std::string::npos) << what;
  EXPECT_NE(what.find("millimetres"), std::string::npos) << what;
  // The same mug in metres plans.
  EXPECT_GT(Planner().plan(mug, scenes::table(), quick()).stableCount(), 0);
}

TEST(Limits, HugeAreaStopsAtTheModelMemoryLimitBeforeBuilding) {
  const Mesh room = scenes::box(20, 20, 0.2, Eigen::Vector3d(0, 0, -0.1));
  const auto t0 = std::chrono::steady_clock::now();
  const std::string what = thrownBy([&] { Planner().plan(scenes::mug(), room, quick()); });
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NE(what.find("max_model_mb"), std::string::npos) << what;
  // Refused from the estimate, not after gigabytes were allocated (a build takes seconds).
  EXPECT_LT(ms, 500.0);
  // The estimate is of the right size: within a factor of 2 of what the models hold.
  const Mesh mug = scenes::mug();
  const ObjectModel om = buildObjectModel(mug, 0.002);
  const double held = om.spheres.centres.size() * 48.0;
  const double est = estimateModelBytes(mug, 0.002);
  EXPECT_GT(est, held);
  EXPECT_LT(est, 10 * held + 2e6);
}

TEST(Limits, FineFloorPointSpacingIsCoarsenedAndReported) {
  PlannerConfig c = quick();
  c.floor_point_spacing = 0.00011;  // 66 million rays on the 1 x 0.8 m table
  c.max_floor_points = 300;
  c.max_resting_faces = 1;
  const PlanResult r = Planner().plan(scenes::box(0.05, 0.05, 0.05), scenes::table(), c);
  ASSERT_TRUE(hasWarning(r, "coarsened")) << "no warning";
  EXPECT_LE(r.stats.floor_points_total, 300);
  EXPECT_GT(r.stats.floor_points_total, 150);
  EXPECT_GT(r.stableCount(), 0);
}

TEST(Limits, LargeMeshIsDecimatedAndStillPlanned) {
  const Mesh area = sheet(200);  // 80k triangles
  ASSERT_EQ(area.triangles.size(), 80000u);
  PlannerConfig c = quick();
  c.max_triangles = 20000;
  const PlanResult r = Planner().plan(scenes::box(0.06, 0.06, 0.04), area, c);
  ASSERT_TRUE(hasWarning(r, "placement area mesh decimated from 80000")) << (r.warnings.empty() ? "" : r.warnings[0]);
  ASSERT_GT(r.stableCount(), 0);
  // The box rests on the sheet: its lowest corner within 2 mm of the sheet's surface.
  const Candidate& best = r.candidates.front();
  double zmin = 1e9;
  for (const auto& p : scenes::box(0.06, 0.06, 0.04).vertices) zmin = std::min(zmin, (best.X_WO * p).z());
  EXPECT_NEAR(zmin, 0.0, 0.0025);
}

TEST(Limits, DecimationKeepsTheShapeAndTheMassProperties) {
  const Mesh area = sheet(300);
  double cell = 0;
  const Mesh d = decimated(area, 30000, &cell);
  EXPECT_LE(d.triangles.size(), 30000u);
  EXPECT_GT(d.triangles.size(), 5000u);
  EXPECT_GT(cell, 0.0);
  EXPECT_NEAR(d.properties.surface_area, area.properties.surface_area, 0.03 * area.properties.surface_area);
  EXPECT_TRUE(d.properties.center_of_mass.isApprox(area.properties.center_of_mass));
  for (const auto& v : d.vertices) EXPECT_LE(std::abs(v.z()), 0.0011);
}

TEST(Limits, CancelDuringSetupIsAnsweredAtOnce) {
  const Mesh area = sheet(500);  // 500k triangles: decimated, then a model build of about a second
  int calls = 0;
  const auto t0 = std::chrono::steady_clock::now();
  double cancelled_at = -1;
  const PlanResult r = Planner().plan(scenes::mug(), area, quick(), [&](const Progress& p) {
    if (++calls < 3) return true;  // let the setup start
    cancelled_at = p.elapsed_ms;
    return false;
  });
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_GE(calls, 3) << "the progress callback was not asked during the setup";
  EXPECT_TRUE(r.cancelled);
  EXPECT_TRUE(r.candidates.empty());
  EXPECT_EQ(r.stats.floor_points_total, 0) << "the plan went past the setup";
  // The target is 50 ms after the cancel; a loaded CI machine gets room.
  EXPECT_LT(ms - cancelled_at, 250.0) << "cancel at " << cancelled_at << " ms, answered at " << ms << " ms";
}

TEST(Limits, TimeBudgetHoldsDuringSetup) {
  const Mesh area = sheet(500);
  PlannerConfig c = quick();
  c.time_budget_ms = 60;
  const PlanResult r = Planner().plan(scenes::mug(), area, c);
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.outcome(), PlanOutcome::kTimedOutNone);
  EXPECT_LT(r.stats.total_ms, 60 + 250.0);
}

TEST(Limits, TreeNodeLimitStopsTheSearchWithAWarning) {
  PlannerConfig c = quick();
  c.max_tree_nodes = 200;  // the whole search takes about 830
  // The search's own nodes: the ranking's robustness trials after the stop (bounded by their
  // own count, at least 10 candidates' worth) would add theirs.
  c.robust_check = false;
  const PlanResult r = Planner().plan(scenes::box(0.05, 0.04, 0.03), scenes::table(), c);
  ASSERT_TRUE(hasWarning(r, "max_tree_nodes")) << "no warning";
  EXPECT_GE(r.stats.tree_nodes, 200);
  EXPECT_LT(r.stats.tree_nodes, 200 + 100);  // stopped after the step that crossed it
  EXPECT_LT(r.stats.floor_points_done, r.stats.floor_points_total);
}

TEST(Limits, MillimetreCubeStandsOnAFace) {
  // 1 mm: the sphere radius follows the object below 0.75 mm, so the faces are resolved.
  const Mesh cube = scenes::box(0.001, 0.001, 0.001);
  const Mesh coaster = scenes::box(0.1, 0.1, 0.005, Eigen::Vector3d(0, 0, -0.0025));
  PlannerConfig c = quick();
  const PlanResult r = Planner().plan(cube, coaster, c);
  ASSERT_GT(r.stableCount(), 0);
  EXPECT_LT(r.stats.sphere_radius, 1e-4);
  const Eigen::Matrix3d R = r.candidates.front().X_WO.linear();
  // Some face normal points straight down: the largest |component| of R's z row is 1.
  EXPECT_GT(R.row(2).cwiseAbs().maxCoeff(), std::cos(3 * M_PI / 180));
}

TEST(Limits, LargeNonConvexPolygonIsEarClippedNotFanned) {
  // A planar star with 4000 corners: a fan from corner 0 would cover area outside the star.
  const int n = 4000;
  std::vector<Eigen::Vector3d> v;
  std::vector<int> poly;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, r = i % 2 ? 0.05 : 0.1;
    v.emplace_back(r * std::cos(a), r * std::sin(a), 0);
    poly.push_back(i);
  }
  const Mesh m = buildMesh(v, {poly}, "star");
  EXPECT_EQ(m.report.fanned_polygons, 0);
  EXPECT_EQ(m.triangles.size(), static_cast<size_t>(n - 2));
  double star = 0;
  for (int i = 0; i < n; ++i) star += 0.5 * v[i].cross(v[(i + 1) % n]).z();
  EXPECT_NEAR(m.properties.surface_area, star, 1e-9);
  std::vector<int> huge(kMaxPolygonVertices + 1);
  std::vector<Eigen::Vector3d> hv(huge.size());
  for (size_t i = 0; i < huge.size(); ++i) {
    huge[i] = static_cast<int>(i);
    hv[i] = Eigen::Vector3d(std::cos(2 * M_PI * i / huge.size()), std::sin(2 * M_PI * i / huge.size()), 0);
  }
  const std::string what = thrownBy([&] { buildMesh(hv, {huge}, "object mesh"); });
  EXPECT_NE(what.find("object mesh: polygon 0 has 10001 vertices"), std::string::npos) << what;
}
