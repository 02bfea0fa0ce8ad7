// Openings of the area (search/opening_points.h), drop-offs (judgement/drop_margin.h) and the
// height grid's walk both use (model/height_grid_walk.h).
#include <Eigen/Geometry>
#include <cmath>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/judgement/drop_margin.h"
#include "place_planner/model/height_grid_walk.h"
#include "place_planner/model/scene.h"
#include "place_planner/planner.h"
#include "place_planner/search/opening_points.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {

constexpr double kR = 0.002;  // m, the area's sphere radius in these models

AreaModel model(const Mesh& area) { return buildAreaModel(area, Eigen::Vector3d(0, 0, -1), kR, 2 * kR, 2 * kR); }

// A cup 12 cm across inside and 12 cm tall on a 1 cm base 20 cm square.
Mesh cup() {
  return scenes::merge({scenes::box(0.2, 0.2, 0.01, {0, 0, 0.005}), [] {
                          Mesh t = scenes::tube(0.06, 0.066, 0.12, 48);
                          for (auto& v : t.vertices) v.z() += 0.01;
                          return t;
                        }()});
}

// A tray 40 x 30 cm: a 1 cm base, 5 cm walls 6 mm thick round it and a divider along x at y = 0,
// so two compartments 38.8 x 14.1 cm; and one across at x = 0.07.
Mesh tray() {
  return scenes::merge({scenes::box(0.4, 0.3, 0.01, {0, 0, 0.005}), scenes::box(0.006, 0.3, 0.05, {-0.197, 0, 0.035}),
                        scenes::box(0.006, 0.3, 0.05, {0.197, 0, 0.035}), scenes::box(0.4, 0.006, 0.05, {0, -0.147, 0.035}),
                        scenes::box(0.4, 0.006, 0.05, {0, 0.147, 0.035}), scenes::box(0.4, 0.006, 0.05, {0, 0, 0.035}),
                        scenes::box(0.006, 0.3, 0.05, {0.07, 0, 0.035})});
}

}  // namespace

// From the cup's middle every direction meets its wall 6 cm out (within a cell and a sphere);
// a walk that asks for nothing runs to its reach and stops nowhere; off the grid the height is
// not finite.
TEST(HeightGridWalk, EveryDirectionFromACupsMiddleMeetsItsWall) {
  const AreaModel am = model(cup());
  const double floor = gridHeightAt(am.grid, 0, 0);
  ASSERT_TRUE(std::isfinite(floor));
  for (int k = 0; k < kGridWalkDirections; ++k) {
    const GridStop wall = walkOut(am.grid, 0, 0, k, 0.1, [&](double h) { return h > floor + 0.02; });
    ASSERT_TRUE(std::isfinite(wall.t)) << "direction " << k;
    EXPECT_NEAR(wall.t, 0.06, am.grid.cell + 2 * kR) << "direction " << k;
    EXPECT_GT(wall.height, floor + 0.02);
    EXPECT_FALSE(std::isfinite(walkOut(am.grid, 0, 0, k, 0.1, [](double) { return false; }).t));
  }
  EXPECT_FALSE(std::isfinite(gridHeightAt(am.grid, 5.0, 0.0)));
}

TEST(Openings, AFloorPointInACupMovesToItsMiddle) {
  const AreaModel am = model(cup());
  OpeningParams p;
  p.reach = 0.1;
  p.wall_height = 0.02;
  p.min_clearance = 0.01;
  const std::vector<V3> off = {v3(0.035, -0.02, 0.01)};
  const std::vector<V3> c = openingCentres(am.grid, off, p);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_LT(std::hypot(c[0].x, c[0].y), 0.006) << c[0].x << " " << c[0].y;
  EXPECT_NEAR(c[0].z, 0.01, 1e-9);  // at its floor point's height
  // On the base outside the cup (walls on one side only) and on open ground: no opening.
  EXPECT_TRUE(openingCentres(am.grid, {v3(0.085, 0.085, 0.01)}, p).empty());
  EXPECT_TRUE(openingCentres(model(scenes::table()).grid, {v3(0.1, 0.05, 0.0)}, p).empty());
  // An object wider than the cup: its narrowest side does not fit, no opening for it.
  p.min_clearance = 0.07;
  EXPECT_TRUE(openingCentres(am.grid, off, p).empty());
}

TEST(Openings, ALongObjectIsTurnedAlongItsCompartment) {
  const AreaModel am = model(tray());
  // A stick 20 cm long along x of O, held along y: across the 14 cm compartment it does not fit.
  const Mesh stick = scenes::box(0.2, 0.03, 0.03, {0, 0, 0.015});
  const Eigen::Matrix3d along_y = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const std::vector<V3> v = buildObjectModel(stick, 0.002).spheres.centres;  // its surface
  const OpeningFit fit = fitIntoOpening(am.grid, v3(-0.06, 0.075, 0.01), along_y, v, toV3(stick.properties.center_of_mass));
  // Turned (the smallest turn that fits) until its extent across the compartment fits its 14.1 cm.
  EXPECT_LT(0.2 * std::abs(std::cos(fit.yaw)) + 0.03 * std::abs(std::sin(fit.yaw)), 0.141) << fit.yaw;
  EXPECT_LE(std::abs(fit.yaw), M_PI / 2 + 1e-9);
  EXPECT_LT(fit.shift.norm(), 0.003);  // its footprint's middle is its centre of mass
  // Already along x: not turned.
  EXPECT_EQ(fitIntoOpening(am.grid, v3(-0.06, 0.075, 0.01), Eigen::Matrix3d::Identity(), v,
                           toV3(stick.properties.center_of_mass)).yaw,
            0.0);
}

// An object whose centre of mass is off its footprint's middle (a mug's handle) goes in with its
// footprint's middle over the opening's.
TEST(Openings, AnObjectsFootprintIsCentredInTheOpening) {
  const AreaModel am = model(cup());
  // A block 6 x 4 cm with a 3 cm tab on one side: its centre of mass off its footprint's middle.
  const Mesh block = scenes::merge({scenes::box(0.06, 0.04, 0.04, {0, 0, 0.02}), scenes::box(0.03, 0.01, 0.02, {0.045, 0, 0.02})});
  const std::vector<V3> v = buildObjectModel(block, 0.002).spheres.centres;
  const OpeningFit fit = fitIntoOpening(am.grid, v3(0, 0, 0.01), Eigen::Matrix3d::Identity(), v,
                                        toV3(block.properties.center_of_mass));
  // Footprint x from -0.03 to 0.06: its middle 1.5 cm from x = 0, the centre of mass nearer.
  const Eigen::Rotation2Dd R(fit.yaw);
  const Eigen::Vector2d mid = R * Eigen::Vector2d(0.015 - block.properties.center_of_mass.x(), 0);
  EXPECT_GT(mid.norm(), 0.007);  // the test would pass on no shift otherwise
  EXPECT_LT((fit.shift + mid).norm(), 0.006) << fit.shift.transpose() << " / " << mid.transpose();
}

TEST(DropMargin, ADividersTopIsNearADropAndItsCompartmentIsNot) {
  const AreaModel am = model(tray());
  DropMarginParams p;
  p.reach = 0.06;
  const double top = dropMargin(am.grid, Eigen::Vector3d(-0.06, 0.0, 0.1), 0.06, p);      // on the divider
  const double floor = dropMargin(am.grid, Eigen::Vector3d(-0.06, 0.075, 0.05), 0.01, p);  // in a compartment
  EXPECT_LT(top, 0.7);
  EXPECT_GT(floor, 0.99);
  // A table top 1.0 x 0.8 m, 75 cm over a floor: 2 cm from its edge the floor far below is a
  // drop-off. A scan of the top alone (a sheet) says nothing of what lies beyond its edge.
  const Mesh table = scenes::box(1.0, 0.8, 0.03, {0, 0, 0.735});
  const AreaModel room = model(scenes::merge({table, scenes::box(2.0, 2.0, 0.01, {0, 0, -0.005})}));
  EXPECT_GT(dropMargin(room.grid, Eigen::Vector3d(0, 0, 0.8), 0.75, p), 0.99);
  EXPECT_LT(dropMargin(room.grid, Eigen::Vector3d(0.48, 0, 0.8), 0.75, p), 0.9);
  EXPECT_GT(dropMargin(model(scenes::plane(1.0, 0.8)).grid, Eigen::Vector3d(0.48, 0, 0.05), 0.0, p), 0.99);
}

// A person puts the mug into one of the tray's compartments, not on a divider's 6 mm top. The
// grid of floor points puts none near a compartment's middle and the mug lowered off it lands on
// the walls; the openings' middles, with the mug turned to fit, reach the floor, and the drop
// margin ranks the floor first (Q alone: the pose on the divider, 0.90 against 0.89).
TEST(PlannerOpenings, MugGoesIntoATraysCompartment) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh area = scenes::merge({tray(), scenes::box(0.006, 0.3, 0.05, {-0.07, 0, 0.035})});
  const PlanResult r = Planner().plan(mug, area, PlannerConfig());
  ASSERT_FALSE(r.candidates.empty());
  const Candidate& best = r.candidates.front();
  ASSERT_TRUE(best.stable);
  double low = 1e9;
  for (const auto& v : mug.vertices) low = std::min(low, (best.X_WO * v).z());
  EXPECT_LT(low, 0.015) << "on the compartment's floor (1 cm), not on the walls (6 cm)";
  EXPECT_GT(best.drop_margin, 0.95);  // walls round it, no drop-off
  // A stable pose on the walls' tops, if any, is near a drop-off and ranks after it.
  for (const auto& c : r.candidates)
    if (c.stable && (c.X_WO * mug.properties.center_of_mass).z() > 0.08) EXPECT_LT(c.drop_margin, 0.9);
}
