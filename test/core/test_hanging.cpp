// Hanging (beyond the paper): the area's pegs (search/pegs.h), the object's loops
// (search/loops.h), and the choice of placement kind (config.h PlacementKind).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/model/scene.h"
#include "place_planner/planner.h"
#include "place_planner/search/loops.h"
#include "place_planner/search/pegs.h"
#include "test_helpers.h"

namespace place_planner {
namespace {

std::vector<Peg> pegsOf(const Mesh& area) {
  const AreaModel am = buildAreaModel(area, Eigen::Vector3d(0, 0, -1), 0.002, 0.004, 0.004);
  return findPegs(am);
}

double degrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180 / M_PI;
}

TEST(Pegs, CoatPegsAndAMugTreesArmsAreFoundTablesAndShelvesAreNot) {
  // Six pegs 10 cm long rising 5 degrees towards -y: each once, its axis along it, to its tip.
  const std::vector<Peg> wall = pegsOf(scenes::pegWall(5.0));
  ASSERT_EQ(wall.size(), 6u);
  for (const Peg& p : wall) {
    EXPECT_LT(degrees(p.axis, Eigen::Vector3d(0, -std::cos(5 * M_PI / 180), std::sin(5 * M_PI / 180))), 4.0);
    EXPECT_NEAR(p.to_tip + p.to_base, 0.10, 0.01);
    EXPECT_NEAR(p.half_width, 0.006, 0.002);
    const Eigen::Vector3d tip = p.point + p.to_tip * p.axis;
    EXPECT_NEAR(tip.y(), 0.092 - 0.1 * std::cos(5 * M_PI / 180), 0.006);
  }
  // The mug tree's four arms rise 25 degrees.
  const std::vector<Peg> tree = pegsOf(scenes::mugTree());
  ASSERT_EQ(tree.size(), 4u);
  for (const Peg& p : tree) EXPECT_NEAR(std::asin(p.axis.z()) * 180 / M_PI, 25.0, 4.0);
  // Boards, table tops, binders and upright rack pegs are no pegs.
  EXPECT_TRUE(pegsOf(scenes::table()).empty());
  EXPECT_TRUE(pegsOf(scenes::shelfUnit(4)).empty());
  EXPECT_TRUE(pegsOf(scenes::binderStack()).empty());
  EXPECT_TRUE(pegsOf(scenes::dishRack()).empty());
}

// Pegs as racks are made: the wall mug rack's 8 mm pegs rising 15 degrees with a knob on the
// end (its mesh a part overlapping the peg's, so the peg's end face lies inside it), 16-sided;
// and a tree of six arms rising 35 degrees from inside its post. Each found once, whole, along
// its own axis.
TEST(Pegs, KnobbedPegsAndSteepArmsAreFoundWholeAlongTheirAxes) {
  const double rise = 15 * M_PI / 180;
  const Eigen::Vector3d d(0, -std::cos(rise), std::sin(rise));
  const std::vector<Peg> pegs = pegsOf(scenes::mugRack());
  ASSERT_EQ(pegs.size(), 4u);
  for (const Peg& p : pegs) {
    EXPECT_LT(degrees(p.axis, d), 2.0);
    EXPECT_NEAR(p.to_tip + p.to_base, 0.084, 0.006);  // to the knob's end, not the peg's end face inside it
  }
  auto posed = [](Mesh m, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
    for (auto& v : m.vertices) v = R * v + t;
    return buildMesh(m.vertices, m.patches, "part");
  };
  std::vector<Mesh> tree = {scenes::cylinder(0.0125, 0.42, 20)};
  tree[0] = posed(tree[0], Eigen::Matrix3d::Identity(), {0, 0, 0.23});
  std::vector<Eigen::Vector3d> arms;
  for (int k = 0; k < 6; ++k) {
    const double yaw = k * M_PI / 3, up = 35 * M_PI / 180;
    arms.emplace_back(std::cos(yaw) * std::cos(up), std::sin(yaw) * std::cos(up), std::sin(up));
    const Eigen::Matrix3d Ra = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), arms.back()).toRotationMatrix();
    tree.push_back(posed(scenes::cylinder(0.004, 0.1, 12), Ra, Eigen::Vector3d(0, 0, k % 2 ? 0.27 : 0.36) + 0.062 * arms.back()));
  }
  const std::vector<Peg> found = pegsOf(scenes::merge(tree, "six-armed tree"));
  ASSERT_EQ(found.size(), 6u);  // no arm twice, none pointing back through the post
  for (const Peg& p : found) {
    double nearest = 180;
    for (const auto& a : arms) nearest = std::min(nearest, degrees(p.axis, a));
    EXPECT_LT(nearest, 3.0);
  }
}

// Cup hooks under a shelf: each hook's arm is free beyond both its ends (its stem is as thin as
// it), so it is a peg each way, horizontal along y, about as long as the arm between the stem
// and the arm's end; the upright stem and tip are no pegs. The threading sweep then finds that
// a loop gets on from the tip's end only (Hanging.YcbMugIsLiftedOverACupHooksTipAndHangsOnItsArm).
TEST(Pegs, ACupHooksArmIsAPegBothWays) {
  const std::vector<Peg> pegs = pegsOf(scenes::cupHooks());
  ASSERT_EQ(pegs.size(), 6u);
  int towards_tip = 0;
  for (const Peg& p : pegs) {
    EXPECT_GT(std::abs(p.axis.y()), std::cos(3 * M_PI / 180));
    EXPECT_NEAR(p.point.z(), 0.35, 0.003);
    EXPECT_NEAR(p.to_tip + p.to_base, 0.0385, 0.005);
    towards_tip += p.axis.y() < 0;
  }
  EXPECT_EQ(towards_tip, 3);
}

TEST(Loops, AHandlesOpeningAndARingsHoleAreFoundSolidsHaveNone) {
  // The loop mug's handle: an opening 5.8 cm tall and 2.4 cm deep, through y.
  const std::vector<Loop> mug = findLoops(scenes::loopMug());
  ASSERT_FALSE(mug.empty());
  EXPECT_LT(std::min(degrees(mug[0].axis, Eigen::Vector3d::UnitY()), degrees(mug[0].axis, -Eigen::Vector3d::UnitY())), 10.0);
  EXPECT_NEAR(mug[0].radius, 0.012, 0.002);
  EXPECT_GT(mug[0].centre.x(), 0.04);
  EXPECT_LT(mug[0].centre.x(), 0.064);
  EXPECT_NEAR(mug[0].centre.y(), 0.0, 0.005);
  // A ring 6 cm across: its hole, 2.4 cm in radius, about z.
  const std::vector<Loop> ring = findLoops(scenes::torus(0.03, 0.006));
  ASSERT_EQ(ring.size(), 1u);
  EXPECT_LT(degrees(ring[0].axis, Eigen::Vector3d::UnitZ()), 10.0);
  EXPECT_NEAR(ring[0].radius, 0.024, 0.002);
  EXPECT_LT(ring[0].centre.norm(), 0.002);
  // No opening through a cube, a plate, a pen, or the mug whose handle is a solid block.
  for (const char* name : {"cube", "plate", "pen", "mug"}) EXPECT_TRUE(findLoops(scenes::byName(name)).empty()) << name;
}

// The choice of placement kind: standing only drops the hanging poses; hanging only on a table
// says why nothing hangs; the mug's best pose on a table is the same with any kind allowed.
// A roll of tape: a hole 7.6 cm across through a loop 4.8 cm deep, on the knobbed 8 cm pegs of
// the wall mug rack. Threaded with half its depth to spare (a whole depth short of the tip
// left no room on the peg), it hangs round a peg, its centre of mass below the peg's axis.
TEST(Placement, ARollOfTapeHangsOnAKnobbedPeg) {
  PlannerConfig c;
  c.threads = 2;
  c.placement = PlacementKind::kHanging;
  const Mesh tape = scenes::byName("tape_roll");
  const PlanResult r = Planner().plan(tape, scenes::mugRack(), c);
  ASSERT_GT(r.stableCount(), 0);
  const Candidate& best = r.candidates.front();
  ASSERT_TRUE(best.hanging);
  const Eigen::Vector3d com = best.X_WO * tape.properties.center_of_mass;
  // Below one of the four pegs (x = -0.18, -0.06, 0.06, 0.18; axes 4 to 10 cm high over z = 0.4
  // along the first 8 cm of -y), within the hole's radius of its axis.
  double nearest = 1;
  for (const double x : {-0.18, -0.06, 0.06, 0.18}) nearest = std::min(nearest, std::abs(com.x() - x));
  EXPECT_LT(nearest, 0.01);
  EXPECT_LT(com.z(), 0.4);
  EXPECT_GT(com.z(), 0.4 - 0.038);
  EXPECT_LT(com.y(), 0.0);
  EXPECT_GT(com.y(), -0.085);
}

TEST(Placement, KindChoosesStandingOrHanging) {
  const Mesh ring = scenes::torus(0.03, 0.006);
  PlannerConfig c;
  c.threads = 2;
  c.placement = PlacementKind::kStanding;
  const PlanResult standing = Planner().plan(ring, scenes::pegWall(), c);
  EXPECT_EQ(standing.stats.pegs, 0);  // not searched
  for (const Candidate& k : standing.candidates) EXPECT_FALSE(k.hanging);
  c.placement = PlacementKind::kHanging;
  const PlanResult hanging = Planner().plan(ring, scenes::pegWall(), c);
  ASSERT_GT(hanging.stableCount(), 0);
  for (const Candidate& k : hanging.candidates) EXPECT_TRUE(k.hanging);
  const PlanResult none = Planner().plan(scenes::mug(), scenes::table(), c);
  EXPECT_EQ(none.stableCount(), 0);
  bool said = false;
  for (const std::string& w : none.warnings) said = said || w.find("nothing to hang on") != std::string::npos;
  EXPECT_TRUE(said);
  c.placement = PlacementKind::kStanding;
  const PlanResult table_standing = Planner().plan(scenes::mug(), scenes::table(), c);
  c.placement = PlacementKind::kAny;
  const PlanResult table_any = Planner().plan(scenes::mug(), scenes::table(), c);
  ASSERT_GT(table_any.stableCount(), 0);
  EXPECT_TRUE(table_any.candidates.front().X_WO.isApprox(table_standing.candidates.front().X_WO, 1e-9));
  EXPECT_THROW(placementKindFromString("dangling"), std::invalid_argument);
}

// A hanging search's roots are threaded starts, not floor points: its progress counts them
// (a progress bar stuck at "0 of 33 floor points" for seconds says nothing), up to all of them
// when the search ends; standing and hanging together, both count.
TEST(Placement, ProgressCountsThreadedStarts) {
  const Mesh ring = scenes::torus(0.03, 0.006);
  PlannerConfig c;
  c.threads = 2;
  c.placement = PlacementKind::kHanging;
  std::vector<Progress> seen;
  const PlanResult r = Planner().plan(ring, scenes::pegWall(), c, [&](const Progress& p) {
    seen.push_back(p);
    return true;
  });
  ASSERT_GT(r.stats.hanging_starts, 0);
  EXPECT_EQ(r.stats.hanging_starts_done, r.stats.hanging_starts);
  EXPECT_EQ(r.stats.start_orientations, 0);
  // While the models are built the roots are not known yet: those reports say 0 of 0.
  seen.erase(seen.begin(), std::find_if(seen.begin(), seen.end(), [](const Progress& p) { return p.hanging_starts_total > 0; }));
  ASSERT_GE(seen.size(), 2u) << "reports while the trees grow";
  for (size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].floor_points_total, 0) << "floor points are not searched with placement hanging";
    EXPECT_EQ(seen[i].hanging_starts_total, r.stats.hanging_starts);
    EXPECT_LE(seen[i].hanging_starts_done, seen[i].hanging_starts_total);
    if (i > 0) EXPECT_GE(seen[i].hanging_starts_done, seen[i - 1].hanging_starts_done);
  }
  EXPECT_LT(seen.front().hanging_starts_done, r.stats.hanging_starts);
  EXPECT_EQ(seen.back().hanging_starts_done, r.stats.hanging_starts);
  c.placement = PlacementKind::kAny;
  seen.clear();
  const PlanResult any = Planner().plan(ring, scenes::pegWall(), c, [&](const Progress& p) {
    seen.push_back(p);
    return true;
  });
  ASSERT_FALSE(seen.empty());
  EXPECT_GT(seen.back().floor_points_total, 0);
  EXPECT_EQ(seen.back().hanging_starts_total, any.stats.hanging_starts);
  EXPECT_EQ(any.stats.hanging_starts_done, any.stats.hanging_starts);
  EXPECT_EQ(any.stats.floor_points_done, any.stats.floor_points_total);
}

// A mug hung on a mug tree whose arms rise 35 degrees slides down its arm until its body meets
// the trunk, and its swing then presses the body sideways against the trunk. Lowered straight
// down after each turn, the swing cannot feel the trunk (straight up from inside a post is its
// top, far off): the YCB mug ended 5 mm inside it, and the validator's engine threw it 1 cm up
// the arm. The swing's moves and the result guard look sideways too (penetration.h).
TEST(Placement, AMugHungBesideATreesTrunkStaysOutOfIt) {
  PP_REQUIRE_SHARED_DATA();
  const double trunk_r = 0.014;
  std::vector<Mesh> parts{scenes::cylinder(0.11, 0.02), transformed(scenes::cylinder(trunk_r, 0.41, 24),
                                                                     Eigen::Matrix3d::Identity(), {0, 0, 0.215})};
  for (int k = 0; k < 6; ++k) {
    const double yaw = k * M_PI / 3, z = std::array<double, 3>{0.22, 0.29, 0.36}[k % 3];
    const Eigen::Vector3d d(std::cos(yaw) * std::cos(35 * M_PI / 180), std::sin(yaw) * std::cos(35 * M_PI / 180),
                            std::sin(35 * M_PI / 180));
    const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d).toRotationMatrix();
    parts.push_back(transformed(scenes::cylinder(0.006, 0.08, 16), R, Eigen::Vector3d(0, 0, z) + 0.05 * d));
  }
  const Mesh tree = scenes::merge(parts, "mug_tree_six");
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  PlannerConfig c;
  c.threads = 2;
  c.placement = PlacementKind::kHanging;
  const PlanResult r = Planner().plan(mug, tree, c);
  ASSERT_GT(r.stableCount(), 0);
  for (const Candidate& k : r.candidates) {
    if (!k.stable) continue;
    EXPECT_TRUE(k.hanging);
    // No vertex of the mug deeper in the trunk than the planner's contact distance (3.75 mm).
    double deepest = 0;
    for (const Eigen::Vector3d& v : mug.vertices) {
      const Eigen::Vector3d p = k.X_WO * v;
      if (p.z() > 0.02 && p.z() < 0.42) deepest = std::max(deepest, trunk_r - p.head<2>().norm());
    }
    EXPECT_LT(deepest, 0.004) << "at " << k.X_WO.translation().transpose();
  }
}

}  // namespace
}  // namespace place_planner
