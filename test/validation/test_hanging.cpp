// Hanging placements (search/pegs.h, search/loops.h, search/hanging_starts.h) planned with
// default options and checked in the Bullet validator.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/planner.h"
#include "place_planner/validation/mesh_variants.h"
#include "place_planner/validation/mujoco_validator.h"
#include "place_planner/validation/physics_validator.h"
#include "validation_test_helpers.h"

namespace place_planner {
namespace validation {
namespace {

// A pendulum swings for long undamped: light damping, as air and the joint give it.
ValidatorConfig damped() { return forHanging(ValidatorConfig{}); }

PlannerConfig twoThreads() {
  PlannerConfig c;
  c.threads = 2;
  return c;
}

// The best candidate hangs, threaded along its peg towards the wall (+y), from a loop-on-peg root.
void expectHangsOnAPeg(const Mesh& object, const PlanResult& r) {
  ASSERT_FALSE(r.candidates.empty());
  const Candidate& best = r.candidates.front();
  ASSERT_TRUE(best.stable) << "no stable candidate";
  EXPECT_TRUE(best.hanging);
  EXPECT_EQ(best.start, StartKind::kLoopOnPeg);
  EXPECT_GT(best.placement.approach.direction.y(), 0.95) << "not threaded along the peg";
  EXPECT_FALSE(best.placement.straight);
  // The path: threaded, lowered onto the peg, and where it swings to (not every step of the swing).
  EXPECT_LE(best.intermediate_poses.size(), 8u);
  // The pre-place pose is beyond the peg's tip (the pegs end at y = -0.01), on the peg's line.
  EXPECT_LT(best.placement.pre_place_W.translation().y(), best.X_WO.translation().y() - 0.05);
  // Every contact is above the centre of mass, which hangs within 5 mm of straight below them.
  const Eigen::Vector3d com = best.X_WO * object.properties.center_of_mass;
  Eigen::Vector3d mid = Eigen::Vector3d::Zero();
  for (const ContactPoint& c : best.contacts) {
    EXPECT_GT(c.p_W.z(), com.z() + 0.01);
    mid += c.p_W / static_cast<double>(best.contacts.size());
  }
  EXPECT_LT((mid - com).head<2>().norm(), 0.005);
}

// A ring 6 cm across on the wall of coat pegs, nothing to stand on: it hangs by its hole, and
// Bullet keeps it there (released 2 mm above, damped).
TEST(Hanging, RingOnAWallOfPegsHangsAndStays) {
  const Mesh ring = scenes::byName("ring");
  const Mesh wall = scenes::pegWall();
  const PlanResult r = Planner().plan(ring, wall, twoThreads());
  EXPECT_EQ(r.stats.pegs, 6);
  EXPECT_EQ(r.stats.loops, 1);
  expectHangsOnAPeg(ring, r);
  if (r.candidates.empty() || !r.candidates.front().stable) return;
  const Candidate& best = r.candidates.front();
  // Its centre (the centre of mass) hangs 2.4 cm, its inner radius, under its contact on the peg.
  double top = -1;
  for (const ContactPoint& c : best.contacts) top = std::max(top, c.p_W.z());
  EXPECT_NEAR(top - best.X_WO.translation().z(), 0.024, 0.003);
  // Bullet keeps it hanging: its centre within 1 cm of the goal's, still under the peg. Its
  // turn is free: hung on a round peg through a hole four times as wide, a ring rests spun about
  // its axis or twisted about the vertical as well (a neutral family; Bullet's lands 20-30
  // degrees round it), so the validator's 5 degrees for a standing pose do not apply.
  const PoseCheck p = PhysicsValidator(ring, wall, damped()).check(best.X_WO);
  EXPECT_LT(p.moved_m, 0.01) << "Bullet: the ring moved " << 1000 * p.moved_m << " mm";
  EXPECT_NEAR(p.X_WO_final.translation().z(), best.X_WO.translation().z(), 0.005) << "Bullet: the ring dropped";
  // The product's physics check (CLI --verify, the node) judges a hanging candidate the same way.
  PlanResult verified = r;
  const VerifyStats vs = verifyTopK(ring, wall, twoThreads(), verified, 1, 0, 2);
  EXPECT_EQ(vs.checked, 1);
  EXPECT_TRUE(verified.candidates.front().physics.stayed);
}

// The YCB mug on the wall of pegs: the best candidate hangs by its handle.
TEST(Hanging, MugOnAWallOfPegsHangsByItsHandle) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const PlanResult r = Planner().plan(mug, scenes::pegWall(), twoThreads());
  EXPECT_EQ(r.stats.pegs, 6);
  expectHangsOnAPeg(mug, r);
}

// Scanned input: the same mug with 10 % of its surface punched out still hangs by its handle.
TEST(Hanging, MugWithHolesStillHangs) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = punchHoles(validation_test::sharedMesh("objects/mug_ycb025_1k.ply"), 0.10, 7);
  const PlanResult r = Planner().plan(mug, scenes::pegWall(), twoThreads());
  expectHangsOnAPeg(mug, r);
}

// Coat pegs rising 10 degrees (under the friction angle, atan 0.2): the YCB mug hangs by its
// handle at a peg's root, its body leaning on the wall below the peg (the wall's face at
// y = 0.09). Every perturbed release holds, and Bullet keeps it hanging. The wall's contacts
// push sideways along the wall's own normal; merged with the peg's into one mean normal, or
// blended with the mug's, they read as a floor or lose the peg's grip, and nothing held.
TEST(Hanging, MugHangsOnRisingPegsLeaningOnTheWall) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh wall = scenes::pegWall(10.0);
  const PlanResult r = Planner().plan(mug, wall, twoThreads());
  ASSERT_FALSE(r.candidates.empty());
  const Candidate& best = r.candidates.front();
  ASSERT_TRUE(best.stable) << "no stable candidate";
  EXPECT_TRUE(best.hanging);
  EXPECT_EQ(best.start, StartKind::kLoopOnPeg);
  EXPECT_EQ(best.robustness.held, best.robustness.trials);
  const Eigen::Vector3d com = best.X_WO * mug.properties.center_of_mass;
  int on_wall = 0;
  for (const ContactPoint& c : best.contacts) on_wall += c.p_W.y() > 0.088 && c.p_W.z() < com.z() + 0.003;
  EXPECT_GT(on_wall, 0) << "its body does not lean on the wall";
  const PoseCheck p = PhysicsValidator(mug, wall, damped()).check(best.X_WO);
  EXPECT_TRUE(stillHanging(p, best.X_WO, mug.properties.center_of_mass, damped()))
      << "Bullet: moved " << 1000 * p.moved_m << " mm, turned " << p.turned_deg << " deg";
}

// The best candidate of `object` on `area` with placement hanging: stable and hanging; none (a
// failure) when nothing stable hangs there. `max_radius` > 0: the sphere models were built finer
// than that for the object's loop (fineRadius).
std::optional<Candidate> bestHung(const Mesh& object, const Mesh& area, double max_radius = 0) {
  PlannerConfig c = twoThreads();
  c.placement = PlacementKind::kHanging;
  const PlanResult r = Planner().plan(object, area, c);
  if (max_radius > 0) EXPECT_LT(r.stats.sphere_radius, max_radius) << "the models were not built finer for the loop";
  EXPECT_GT(r.stableCount(), 0) << "it hangs nowhere";
  if (r.stableCount() == 0 || !r.candidates.front().stable) return std::nullopt;
  EXPECT_TRUE(r.candidates.front().hanging);
  return r.candidates.front();
}

// Some contact above the centre of mass (held from above), and every such contact within
// `reach` of the vertical axis through the area's origin (the mug tree's post).
void expectHeldFromAboveWithin(const Mesh& object, const Candidate& best, double reach) {
  const Eigen::Vector3d com = best.X_WO * object.properties.center_of_mass;
  int above = 0;
  for (const ContactPoint& p : best.contacts)
    if (p.p_W.z() > com.z() + 0.01) {
      ++above;
      EXPECT_LT(p.p_W.head<2>().norm(), reach) << "held too far out along the arm";
    }
  EXPECT_GT(above, 0) << "nothing holds it from above";
}

// Bullet keeps the candidate hanging (released 2 mm above, lightly damped: stillHanging).
void expectStillHangsInBullet(const Mesh& object, const Mesh& area, const Candidate& best) {
  const PoseCheck p = PhysicsValidator(object, area, damped()).check(best.X_WO);
  EXPECT_TRUE(stillHanging(p, best.X_WO, object.properties.center_of_mass, damped()))
      << "Bullet: moved " << 1000 * p.moved_m << " mm, turned " << p.turned_deg << " deg";
}

void expectStillHangsInMujoco(const Mesh& object, const Mesh& area, const Candidate& best) {
  const PoseCheck p = MujocoValidator(object, area, damped()).check(best.X_WO);
  EXPECT_TRUE(stillHanging(p, best.X_WO, object.properties.center_of_mass, damped()))
      << "MuJoCo: moved " << 1000 * p.moved_m << " mm, turned " << p.turned_deg << " deg";
}

// A wall mug rack whose board is only 12 cm tall, its pegs rising 15 degrees: the mug slides
// to a peg's root and leans on the board's lower edge. Its shifted releases stay out of the
// board (a release towards the wall cut to where it meets it): before, the one shifted into
// the board touched only the board, fell, and the pose had no robust rest.
TEST(Hanging, LowPolyMugHangsOnAWallMugRackLeaningOnItsBoard) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_lowpoly.ply");
  const Mesh rack = scenes::mugRack();
  const std::optional<Candidate> best = bestHung(mug, rack);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->robustness.held, best->robustness.trials);
  const Eigen::Vector3d com = best->X_WO * mug.properties.center_of_mass;
  int on_board = 0;
  for (const ContactPoint& p : best->contacts) on_board += p.p_W.y() > -0.002 && p.p_W.z() < com.z() + 0.003;
  EXPECT_GT(on_board, 0) << "it does not lean on the board";
  expectStillHangsInBullet(mug, rack, *best);
}

// The YCB mug on the same rack: pressed against the board by one side of its body, off its
// handle's line, gravity is not balanced there, yet no single turn or slide of the swing
// lowers it. The settle its unbalanced wrench starts turns it along the board (the turn about
// the vertical that Bullet shows, 15-20 degrees) to a rest on the board. Before, the swing
// stopped against the board and the mug had no stable pose on this rack.
TEST(Hanging, YcbMugTurnsAlongTheMugRacksBoardToARest) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh rack = scenes::mugRack();
  const std::optional<Candidate> best = bestHung(mug, rack);
  ASSERT_TRUE(best);
  const Eigen::Vector3d com = best->X_WO * mug.properties.center_of_mass;
  int on_board = 0;
  for (const ContactPoint& p : best->contacts) on_board += p.p_W.y() > -0.002;
  EXPECT_GT(on_board, 0) << "it does not lean on the board";
  EXPECT_GT(com.y(), -0.045) << "its centre of mass is not under its handle's contact";
  expectStillHangsInBullet(mug, rack, *best);
}

// The mug scanned from above: its handle's opening, fused from one side, is found 10 mm
// across where the true one is 12, and centred on a peg it meets the 14 mm knob on the
// peg's tip. Threaded with the loop's centre off the peg's axis, it passes the knob and hangs,
// and Bullet keeps the true mug there. Before, no start threaded it (no stable pose).
TEST(Hanging, AMugScannedFromAboveThreadsPastTheKnobOfTheMugRacksPeg) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh scan = validation_test::sharedMesh("scans/objects/mug_ycb025_upper_scan.ply");
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025.ply");
  const Mesh rack = scenes::mugRack();
  PlannerConfig c = twoThreads();
  c.placement = PlacementKind::kHanging;
  const PlanResult r = Planner().plan(scan, rack, c);
  EXPECT_GT(r.stats.hanging_starts, 0);
  ASSERT_GT(r.stableCount(), 0) << "it hangs nowhere";
  const Candidate& best = r.candidates.front();
  ASSERT_TRUE(best.stable);
  EXPECT_TRUE(best.hanging);
  EXPECT_EQ(best.start, StartKind::kLoopOnPeg);
  // Its contacts reach the scan's open rim: released no higher than the scan's noise (a standing
  // pose on a cap is released scan_unseen_reach higher; a hanging one would fall onto its peg).
  EXPECT_EQ(best.support, SupportKind::kCompleted);
  expectStillHangsInBullet(mug, rack, best);
}

// On cup hooks whose arms run along -y from their stems at y = 0, at height arm_z, reach long:
// threaded towards the stem (+y) from beyond the tip, its first pose above the goal (lifted over
// the tip), a contact above the centre of mass on an arm, and Bullet keeps it hanging.
void expectLiftedOverTheTipAndHungOnTheArm(const Mesh& object, const Mesh& hooks, const Candidate& best,
                                           double arm_z, double reach) {
  EXPECT_GT(best.placement.approach.direction.y(), 0.95) << "not threaded along the arm from its tip";
  EXPECT_GT(best.placement.pre_place_W.translation().z(), best.X_WO.translation().z() + 0.003)
      << "not lifted over the tip";
  const Eigen::Vector3d com = best.X_WO * object.properties.center_of_mass;
  int on_arm = 0;
  for (const ContactPoint& p : best.contacts)
    on_arm += p.p_W.z() > com.z() + 0.01 && std::abs(p.p_W.z() - arm_z) < 0.006 && p.p_W.y() < 0 && p.p_W.y() > -reach;
  EXPECT_GT(on_arm, 0) << "it does not hang from a hook's arm";
  expectStillHangsInBullet(object, hooks, best);
}

// Cup hooks under a shelf (J hooks: a stem down from the board, an arm out, a tip turned up 1
// cm). The arm is free beyond both its ends (the stem is as thin as the arm), and the mug's
// body reaches farther back than the 3.5 cm arm is long. Only the far end is threaded, lifted:
// the handle passes over the turned-up tip, then comes down on the arm. The mug hangs by its
// handle, its centre of mass below the arm, and Bullet keeps it there.
TEST(Hanging, YcbMugIsLiftedOverACupHooksTipAndHangsOnItsArm) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh hooks = scenes::cupHooks();
  const std::optional<Candidate> best = bestHung(mug, hooks);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  ASSERT_FALSE(best->intermediate_poses.empty());
  EXPECT_LT(best->placement.pre_place_W.translation().y(), -0.05) << "the approach does not start past the tip";
  expectLiftedOverTheTipAndHungOnTheArm(mug, hooks, *best, 0.35, 0.04);
}

// A rod of radius r from a to b (a cylinder along z, centred, turned by `turn` about its axis
// and moved there).
Mesh rod(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, int segments = 12, double turn = 0) {
  Mesh c = scenes::cylinder(r, (b - a).norm(), segments);
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), b - a).toRotationMatrix() *
                            Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Eigen::Vector3d& v : c.vertices) v = R * v + 0.5 * (a + b);
  return buildMesh(c.vertices, c.patches, "rod");
}

// A round tube of radius r along a polyline, its ends capped: each ring's frame carried from
// the last by the turn between their tangents (no twist), n sides, wound outwards.
Mesh tube(const std::vector<Eigen::Vector3d>& path, double r, int n) {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  const int k = static_cast<int>(path.size());
  Eigen::Vector3d u, t0;
  for (int i = 0; i < k; ++i) {
    const Eigen::Vector3d t = (path[std::min(i + 1, k - 1)] - path[std::max(i - 1, 0)]).normalized();
    if (i == 0) u = t.cross(std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).normalized();
    else if (t0.cross(t).norm() > 1e-12) u = Eigen::AngleAxisd(std::acos(std::clamp(t0.dot(t), -1.0, 1.0)), t0.cross(t).normalized()) * u;
    u = (u - u.dot(t) * t).normalized();
    t0 = t;
    const Eigen::Vector3d w = t.cross(u);
    for (int j = 0; j < n; ++j)
      v.push_back(path[i] + r * (std::cos(2 * M_PI * j / n) * u + std::sin(2 * M_PI * j / n) * w));
  }
  for (int i = 0; i + 1 < k; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * n, b = (i + 1) * n, j1 = (j + 1) % n;
      f.push_back({a + j, b + j1, b + j});
      f.push_back({a + j, a + j1, b + j1});
    }
  for (const int end : {0, 1}) {
    const int c = static_cast<int>(v.size()), ring = end ? (k - 1) * n : 0;
    v.push_back(end ? path.back() : path.front());
    for (int j = 0; j < n; ++j)
      f.push_back(end ? std::vector<int>{c, ring + j, ring + (j + 1) % n} : std::vector<int>{c, ring + (j + 1) % n, ring + j});
  }
  double volume = 0;
  for (const auto& t : f) volume += v[t[0]].dot(v[t[1]].cross(v[t[2]]));
  if (volume < 0)
    for (auto& t : f) std::swap(t[1], t[2]);
  return buildMesh(v, f, "tube");
}

// Two J-hooks on a wall (y in [0, 0.02]), 24 cm apart, 40 cm up: an arm 5 cm out rising 10
// degrees and a tip turned up 2 cm, rods of wire radius `r`.
Mesh wallJHooks(double r) {
  const double rise = 10 * M_PI / 180;
  std::vector<Mesh> parts{scenes::box(0.6, 0.02, 0.6, {0, 0.01, 0.3})};
  for (const double x : {-0.12, 0.12}) {
    const Eigen::Vector3d tip(x, -0.05 * std::cos(rise), 0.4 + 0.05 * std::sin(rise));
    parts.push_back(rod({x, 0.005, 0.4}, tip, r));
    parts.push_back(rod(tip, tip + Eigen::Vector3d(0, 0, 0.02), r));
  }
  return scenes::merge(parts, "wall_j_hooks");
}

// Cup hooks whose tip turns up 2.5 cm (not in the suite; the suite's turn up 1 cm): a stem 7 cm
// down from a shelf board, an arm 4 cm out, 6 mm wire. The tip with the arm under it stands 3.1
// cm; the YCB mug's handle, turned as it hangs, leaves 2.4 cm over the arm (its largest circle):
// it cannot pass over the tip that way. Turned a quarter about the arm, the handle's long side
// upright, it passes over, comes down on the arm and swings to its rest. (Without the turned
// starts: no threaded start, no stable pose.)
TEST(Hanging, YcbMugTurnsItsHandleUprightToPassOverATallHookTip) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  std::vector<Mesh> parts{scenes::box(0.6, 0.2, 0.02, {0, 0, 0.41})};
  for (const double x : {-0.2, 0.0, 0.2}) {
    parts.push_back(rod({x, 0, 0.33}, {x, 0, 0.403}, 0.003));
    parts.push_back(rod({x, 0.003, 0.33}, {x, -0.038, 0.33}, 0.003));
    parts.push_back(rod({x, -0.035, 0.33}, {x, -0.035, 0.355}, 0.003));
  }
  const Mesh hooks = scenes::merge(parts, "tall_tip_hooks");
  const std::optional<Candidate> best = bestHung(mug, hooks);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  expectLiftedOverTheTipAndHungOnTheArm(mug, hooks, *best, 0.33, 0.045);
}

// Two J-hooks of 6 mm wire on a wall (not in the suite): out 5 cm rising 10 degrees, the tip
// turned up 2 cm. Its handle over the arm, the YCB mug's body (8 cm across) beside the handle
// meets the wall before the handle is past the tip, rolled upright or not; turned 35 degrees
// about the vertical as well, the body swings out from the wall, the handle passes the tip,
// and the swing brings the mug to its rest below the arm. (Without the turned starts: no
// threaded start, no stable pose.)
TEST(Hanging, YcbMugTurnsItsBodyOutFromTheWallToPassAShortJHooksTip) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh hooks = wallJHooks(0.003);
  const std::optional<Candidate> best = bestHung(mug, hooks);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  EXPECT_GT(best->placement.approach.direction.y(), 0.95) << "not threaded along the arm from its tip";
  const Eigen::Vector3d com = best->X_WO * mug.properties.center_of_mass;
  int on_arm = 0;
  for (const ContactPoint& p : best->contacts)
    on_arm += p.p_W.z() > com.z() + 0.01 && p.p_W.y() < 0 && p.p_W.y() > -0.05 && p.p_W.z() < 0.415;
  EXPECT_GT(on_arm, 0) << "it does not hang from a hook's arm";
  expectStillHangsInBullet(mug, hooks, *best);
  expectStillHangsInMujoco(mug, hooks, *best);
}

// A pan 20 cm across with a slot 2 cm wide and 4 cm long through its handle's end, on two J-hooks
// of 8 mm wire (not in the suite): out 5 cm rising 10 degrees, the tip turned up 2 cm. The slot
// leaves 6 mm either side of the wire, under the contact distance of the pan's default sphere
// models (9.4 mm: the slot touched the wire on both sides, and no pose hung); built finer for
// it, the slot threads at its rest lifted over the tip (the slot's length upright), and the
// handle hangs from the arm with the pan against the wall.
TEST(Hanging, APanHangsByTheSlotInItsHandleOnAJHook) {
  std::vector<Mesh> pan_parts{rod({0, 0, 0}, {0, 0, 0.04}, 0.1, 40), scenes::box(0.105, 0.03, 0.012, {0.1475, 0, 0.031})};
  for (const double y : {-0.015, 0.015}) pan_parts.push_back(scenes::box(0.06, 0.01, 0.012, {0.23, y, 0.031}));
  for (const double x : {0.2025, 0.255}) pan_parts.push_back(scenes::box(x < 0.25 ? 0.015 : 0.01, 0.04, 0.012, {x, 0, 0.031}));
  const Mesh pan = scenes::merge(pan_parts, "pan");
  const Mesh hooks = wallJHooks(0.004);
  const std::optional<Candidate> hung = bestHung(pan, hooks, 0.002);
  ASSERT_TRUE(hung);
  const Candidate& best = *hung;
  EXPECT_EQ(best.start, StartKind::kLoopOnPeg);
  // Held from the arm (above the centre of mass, within the wire's reach of a hook's line).
  const Eigen::Vector3d com = best.X_WO * pan.properties.center_of_mass;
  int on_arm = 0;
  for (const ContactPoint& p : best.contacts)
    on_arm += p.p_W.z() > com.z() + 0.1 && std::abs(std::abs(p.p_W.x()) - 0.12) < 0.008 && p.p_W.y() < 0;
  EXPECT_GT(on_arm, 0) << "it does not hang from a hook's arm";
  // At rest across the arm: its centre of mass within 3 mm (across the wall) of straight below
  // the middle of its contacts on the arm; towards the wall, the wall holds it.
  Eigen::Vector3d mid = Eigen::Vector3d::Zero();
  for (const ContactPoint& p : best.contacts)
    if (p.p_W.z() > com.z() + 0.1 && std::abs(std::abs(p.p_W.x()) - 0.12) < 0.008 && p.p_W.y() < 0)
      mid += p.p_W / static_cast<double>(on_arm);
  EXPECT_LT(std::abs((mid - com).x()), 0.003);
  int on_wall = 0;
  for (const ContactPoint& p : best.contacts) on_wall += p.p_W.y() > -0.002;
  EXPECT_GT(on_wall, 0) << "it does not lean on the wall";
  // (Bullet keeps the pan on J-hooks bent from one wire, scripts/hanging_meshes.py: 3 of 3 best
  // out 5 cm rising 10 degrees; from these, an arm and a tip of two rods, it drops it 5-7 cm:
  // doc/validation.md, "Held-out hanging scenes".)
}

// A basket 16 x 11 x 8 cm with a handle of 8 mm bar arched 7 cm over its length, on cup hooks
// of 6 mm wire under a shelf (a 7 cm stem, a 4 cm arm, the tip turned up 2.5 cm; not in the
// suite). Bar on wire, both thinner than the basket's default contact distance (6.7 mm): the
// sphere models' contact normals there spread along the wire, and their forces did not balance
// though the basket hung straight below (no stable pose). Built finer for it (the contact
// distance at most the thinner's half width), it hangs from an arm by its handle, and Bullet keeps
// it there. (The arms are turned half a facet, a facet on top: with a ridge on top Bullet lets
// the handle through the wire, and the basket drops 6 cm onto its rim, from the same pose;
// doc/validation.md, "Held-out hanging scenes".)
TEST(Hanging, ABasketHangsByItsArchedHandleOnACupHooksThinWire) {
  std::vector<Mesh> basket_parts{scenes::box(0.16, 0.11, 0.08, {0, 0, 0.04})};
  Eigen::Vector3d prev(-0.07, 0, 0.075);
  for (int i = 1; i <= 12; ++i) {
    const double a = M_PI * (1.0 - i / 12.0);
    const Eigen::Vector3d next = i == 12 ? Eigen::Vector3d(0.07, 0, 0.075) : Eigen::Vector3d(0.07 * std::cos(a), 0, 0.08 + 0.07 * std::sin(a));
    basket_parts.push_back(rod(prev, next, 0.004));
    prev = next;
  }
  const Mesh basket = scenes::merge(basket_parts, "basket");
  std::vector<Mesh> parts{scenes::box(0.6, 0.2, 0.02, {0, 0, 0.41})};
  for (const double x : {-0.2, 0.0, 0.2}) {
    parts.push_back(rod({x, 0, 0.33}, {x, 0, 0.403}, 0.003));
    parts.push_back(rod({x, 0.003, 0.33}, {x, -0.043, 0.33}, 0.003, 12, M_PI / 12));
    parts.push_back(rod({x, -0.04, 0.33}, {x, -0.04, 0.355}, 0.003));
  }
  const Mesh hooks = scenes::merge(parts, "shelf_cup_hooks");
  const std::optional<Candidate> hung = bestHung(basket, hooks, 0.0015);
  ASSERT_TRUE(hung);
  const Candidate& best = *hung;
  EXPECT_EQ(best.start, StartKind::kLoopOnPeg);
  // Held from an arm, its centre of mass straight below (within 5 mm) the middle of those contacts.
  const Eigen::Vector3d com = best.X_WO * basket.properties.center_of_mass;
  Eigen::Vector3d mid = Eigen::Vector3d::Zero();
  int on_arm = 0;
  for (const ContactPoint& p : best.contacts)
    if (p.p_W.z() > com.z() + 0.05 && std::abs(p.p_W.z() - 0.33) < 0.006 && p.p_W.y() < 0.003 && p.p_W.y() > -0.045)
      mid += p.p_W, ++on_arm;
  ASSERT_GT(on_arm, 0) << "it does not hang from a hook's arm";
  mid /= on_arm;
  EXPECT_LT((mid - com).head<2>().norm(), 0.005);
  expectStillHangsInBullet(basket, hooks, best);
}

// A mug tree (not in the suite): a 2.8 cm trunk, four 8 mm arms 7 cm long rising 20 degrees,
// two at 25 cm and two at 33 cm. The built-in mug's body is 32-sided: no vertex between its
// rims, so a swing that pushes its side into the trunk leaves every vertex outside it; the
// result's guard also probes its long faces (ObjectModel::probes). The best pose keeps the mug
// out of the trunk (no surface point more than 2 mm inside) and Bullet keeps it hanging.
// (With the vertices alone it hung 1 cm into the trunk and Bullet threw it up the arm.)
TEST(Hanging, AMugsLongSideFacesStayOutOfAMugTreesTrunk) {
  const Mesh mug = scenes::byName("loop_mug");
  std::vector<Mesh> parts{rod({0, 0, 0}, {0, 0, 0.02}, 0.11, 32), rod({0, 0, 0.01}, {0, 0, 0.42}, 0.014, 24)};
  for (int k = 0; k < 4; ++k) {
    const double yaw = k * M_PI / 2 + 0.3, rise = 20 * M_PI / 180;
    const Eigen::Vector3d d(std::cos(yaw) * std::cos(rise), std::sin(yaw) * std::cos(rise), std::sin(rise));
    const Eigen::Vector3d root(0, 0, k % 2 ? 0.33 : 0.25);
    parts.push_back(rod(root + 0.01 * d, root + 0.08 * d, 0.004, 16));
  }
  const Mesh tree = scenes::merge(parts, "four_armed_tree");
  const std::optional<Candidate> best = bestHung(mug, tree);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  double deepest = 0;  // into the trunk, of points 2 mm apart on the mug's triangles
  for (const auto& t : mug.triangles)
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; i + j <= 20; ++j) {
        const Eigen::Vector3d p = best->X_WO * ((mug.vertices[t[0]] * (20 - i - j) + mug.vertices[t[1]] * i +
                                                 mug.vertices[t[2]] * j) / 20.0);
        if (p.z() > 0.02 && p.z() < 0.42) deepest = std::max(deepest, 0.014 - p.head<2>().norm());
      }
  EXPECT_LT(deepest, 0.002) << "the mug is inside the trunk";
  expectStillHangsInBullet(mug, tree, *best);
}

// A board 12 cm tall with three 10 mm pegs 8 cm long rising 10 degrees (not in the suite).
Mesh shortBoardOfRisingPegs() {
  std::vector<Mesh> parts{scenes::box(0.5, 0.02, 0.12, {0, 0.01, 0.4})};
  const Eigen::Vector3d d(0, -std::cos(10 * M_PI / 180), std::sin(10 * M_PI / 180));
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d).toRotationMatrix();
  for (const double x : {-0.12, 0.0, 0.12}) {
    Mesh peg = scenes::cylinder(0.005, 0.08, 12);
    for (Eigen::Vector3d& v : peg.vertices) v = R * v + Eigen::Vector3d(x, 0, 0.42) + 0.04 * d;
    parts.push_back(buildMesh(peg.vertices, peg.patches, "peg"));
  }
  return scenes::merge(parts, "short_board");
}

// The ring on that board swings against the board behind its peg. Each swing move is lowered
// straight down, so a turn could leave it a few millimetres inside the board, and the result's
// penetration guard then rejected every pose it came to (no stable pose). A move that leaves
// it in the area is not taken: it hangs clear of the board, and Bullet keeps it there.
TEST(Hanging, ARingSwingsAgainstAShortBoardWithoutEnteringIt) {
  const Mesh ring = scenes::byName("ring");
  const Mesh board = shortBoardOfRisingPegs();
  const std::optional<Candidate> best = bestHung(ring, board);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  double deepest = -1;  // how far its vertices reach into the board (y > 0), over its height
  for (const Eigen::Vector3d& v : ring.vertices) {
    const Eigen::Vector3d w = best->X_WO * v;
    if (w.z() > 0.34 && w.z() < 0.46) deepest = std::max(deepest, w.y());
  }
  EXPECT_LT(deepest, 0.002) << "the ring is " << 1000 * deepest << " mm inside the board";
  expectStillHangsInBullet(ring, board, *best);
}

// The same rack with its pegs rising 5 degrees, under half the friction angle: the mug stays
// where it is threaded, clear of the board, and hangs there. Before, every peg rising more
// than 2 degrees slid it down to the board's lower edge, where the YCB mug found no rest.
TEST(Hanging, MugStaysWhereThreadedOnAPegRisingUnderHalfTheFrictionAngle) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh rack = scenes::mugRack(5.0);
  const std::optional<Candidate> best = bestHung(mug, rack);
  ASSERT_TRUE(best);
  const Eigen::Vector3d com = best->X_WO * mug.properties.center_of_mass;
  for (const ContactPoint& p : best->contacts) {
    EXPECT_GT(p.p_W.z(), com.z() + 0.01) << "a contact below the centre of mass (the board?)";
    EXPECT_LT(p.p_W.y(), -0.01) << "a contact at the board";
  }
  expectStillHangsInBullet(mug, rack, *best);
}

// A roll of tape (11 cm across, 4.8 cm deep) on the mug tree's arms, 9 cm long and rising 25
// degrees: threaded to the middle of an arm, its rim, tilted with the arm, meets the post; it
// threads on to the arm's far end instead, slides down to the post and hangs there, held from
// above on the arm. Before, nothing threaded it (no start: no stable pose).
TEST(Hanging, ARollOfTapeThreadsPastTheMugTreesPostAndHangs) {
  const Mesh tape = scenes::byName("tape_roll");
  const Mesh tree = scenes::mugTree();
  const std::optional<Candidate> best = bestHung(tape, tree);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  // The arms reach 10 cm from the post's axis; the tape's 5.5 cm rim stays clear of the post
  // (1.2 cm) and of the foot (2 cm high).
  expectHeldFromAboveWithin(tape, *best, 0.10);
  const Eigen::Vector3d com = best->X_WO * tape.properties.center_of_mass;
  EXPECT_GT(com.head<2>().norm(), 0.03) << "its centre of mass inside the post";
  expectStillHangsInBullet(tape, tree, *best);
}

// A basket 16 x 11 x 8 cm, its handle an 8 mm tube arched 7 cm over its length, on a mug tree
// of six 12 mm arms rising 35 degrees round a 28 mm post (scripts/heldout_hanging's basket and
// six-armed tree, built the same way). Swung on an arm with each move
// checked at the vertices only, the box's faces pass over an arm between their corners and
// every rest it reaches lies in an arm (not stable: it hung nowhere). With nothing else
// hanging, those trees swing again with every move checked by all the object's probes
// (streamRoots), and it hangs from an arm by its handle, which Bullet keeps.
TEST(Hanging, ABasketSwungAgainWithAllItsProbesHangsOnASixArmedTree) {
  std::vector<Eigen::Vector3d> handle{{-0.07, 0, 0.075}};
  for (int i = 1; i < 20; ++i) handle.emplace_back(0.07 * std::cos(M_PI * (1 - i / 20.0)), 0, 0.08 + 0.07 * std::sin(M_PI * (1 - i / 20.0)));
  handle.emplace_back(0.07, 0, 0.075);
  std::vector<Mesh> parts{tube({{0, 0, 0}, {0, 0, 0.02}}, 0.11, 32), tube({{0, 0, 0.01}, {0, 0, 0.42}}, 0.014, 24)};
  for (int k = 0; k < 6; ++k) {
    const double yaw = k * M_PI / 3, z = std::array<double, 3>{0.22, 0.29, 0.36}[k % 3];
    const Eigen::Vector3d d(std::cos(yaw) * std::cos(35 * M_PI / 180), std::sin(yaw) * std::cos(35 * M_PI / 180),
                            std::sin(35 * M_PI / 180));
    parts.push_back(tube({Eigen::Vector3d(0, 0, z) + 0.01 * d, Eigen::Vector3d(0, 0, z) + 0.09 * d}, 0.006, 16));
  }
  // Read back from PLY files (single precision), as the CLI reads the held-out scene: the search
  // on the double-precision meshes takes other paths (nothing hangs there, with or without
  // the second swing; doc/validation.md, "Held-out hanging scenes").
  const std::string dir = ::testing::TempDir();
  saveMeshPly(scenes::merge(parts, "six_armed_tree"), dir + "/six_armed_tree.ply");
  saveMeshPly(scenes::merge({scenes::box(0.16, 0.11, 0.08, {0, 0, 0.04}), tube(handle, 0.004, 12)}, "basket"),
              dir + "/arched_basket.ply");
  const Mesh tree = loadMesh(dir + "/six_armed_tree.ply"), basket = loadMesh(dir + "/arched_basket.ply");
  const std::optional<Candidate> best = bestHung(basket, tree);
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  // Held from above by an arm (out to 9 cm from the post's axis), not standing on the foot.
  expectHeldFromAboveWithin(basket, *best, 0.095);
  const Eigen::Vector3d com = best->X_WO * basket.properties.center_of_mass;
  EXPECT_GT(com.z(), 0.1) << "down on the foot";
  expectStillHangsInBullet(basket, tree, *best);
}

// A hanging pose is stable when robust_min_share_hanging (0.75) of its perturbed releases hold:
// the flat-bar mug on the mug tree has fewer poses whose every release holds than poses that
// the default share keeps, and each of the three best is kept hanging by Bullet.
TEST(Hanging, MostReleasesHoldingIsEnoughForAHangingPoseAndBulletAgrees) {
  const Mesh mug = scenes::byName("loop_mug");
  const Mesh tree = scenes::mugTree();
  PlannerConfig all = twoThreads();
  all.placement = PlacementKind::kHanging;
  all.robust_min_share_hanging = 1.0;
  const PlanResult strict = Planner().plan(mug, tree, all);
  PlannerConfig c = twoThreads();
  c.placement = PlacementKind::kHanging;
  const PlanResult r = Planner().plan(mug, tree, c);
  EXPECT_LT(strict.stableCount(), r.stableCount());
  ASSERT_GE(r.stableCount(), 3);
  for (int i = 0; i < 3; ++i) {
    const Candidate& k = r.candidates[i];
    EXPECT_TRUE(k.stable && k.hanging);
    EXPECT_GE(k.robustness.share(), 0.75);
    expectStillHangsInBullet(mug, tree, k);
  }
}

// The YCB mug scanned all around, on level pegs: its pose whose every release holds hangs
// with its body propped on the wall (Q 0.46), and Bullet twists it off (moved 17 mm); poses
// hanging free (Q 0.84) hold 10 or 11 of 12. A failed release costs the score a twelfth of a
// Q unit, so the free pose ranks first, and Bullet keeps it hanging on the true mug. Before,
// a larger share of held releases always ranked first.
TEST(Hanging, AFreeHangingPoseOutranksAProppedOneThatHoldsOneMoreRelease) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh scan = validation_test::sharedMesh("scans/objects/mug_ycb025_allaround_scan.ply");
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025.ply");
  const Mesh wall = scenes::pegWall();
  const std::optional<Candidate> best = bestHung(scan, wall);
  ASSERT_TRUE(best);
  EXPECT_GE(best->robustness.share(), 0.75);
  expectStillHangsInBullet(mug, wall, *best);
}

// A mug tree's arms rise 25 degrees, past the friction angle (atan 0.2 = 11.3): hung on an arm,
// the mug slides down it to the post. It is threaded on until it meets the post and hangs there,
// its body leaning on the post below the arm; Bullet keeps it hanging.
TEST(Hanging, MugHangsAtTheRootOfAMugTreesRisingArm) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const std::optional<Candidate> best = bestHung(mug, scenes::mugTree());
  ASSERT_TRUE(best);
  EXPECT_EQ(best->start, StartKind::kLoopOnPeg);
  // Held from above by an arm, within its first 3 cm from the post (radius 12 mm), where it
  // slid to.
  expectHeldFromAboveWithin(mug, *best, 0.012 + 0.03);
  expectStillHangsInBullet(mug, scenes::mugTree(), *best);
}

// A ring threaded on a mug tree's rising arm slides to the root, swings, and turns the last
// degrees onto the post it leans on. That turn keeps its tree's peg: its perturbed releases
// swing on the arm as the pose's did (without the peg they slid and failed: no robust pose);
// all but one of them hold.
TEST(Hanging, RingLeansOnTheMugTreesPostAndStaysOnItsArm) {
  const Mesh ring = scenes::byName("ring");
  const std::optional<Candidate> best = bestHung(ring, scenes::mugTree());
  ASSERT_TRUE(best);
  EXPECT_GE(best->robustness.held + 1, best->robustness.trials);
  // Held from above by an arm (its root 1.2 cm from the post's axis, its tip 9 cm out).
  expectHeldFromAboveWithin(ring, *best, 0.012 + 0.09);
  expectStillHangsInBullet(ring, scenes::mugTree(), *best);
}

// The YCB mug hung by its handle stays on its peg in Bullet. The validator cuts a looped object
// into pieces no wider than its loop (ValidatorConfig::loop_sized_pieces); with 5 cm pieces
// the handle's opening is bridged and Bullet pushes the mug off the peg (moved about 2 cm).
TEST(Hanging, MugHangingOnAPegStaysInBullet) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh wall = scenes::pegWall();
  const PlanResult r = Planner().plan(mug, wall, twoThreads());
  expectHangsOnAPeg(mug, r);
  if (r.candidates.empty() || !r.candidates.front().stable) return;
  const Candidate& best = r.candidates.front();
  const Eigen::Vector3d com = best.X_WO * mug.properties.center_of_mass;
  // Still hanging where it was put: its centre of mass within 1 cm of the goal's and not
  // dropped. Its turn to Bullet's own rest on the peg (5-12 degrees) is reported, not bounded
  // (a pendulum's rest turns with the contact's friction, as the ring's does).
  const PoseCheck p = PhysicsValidator(mug, wall, damped()).check(best.X_WO);
  const Eigen::Vector3d com_end = p.X_WO_final * mug.properties.center_of_mass;
  EXPECT_LT(p.moved_m, 0.01) << "Bullet: the mug moved " << 1000 * p.moved_m << " mm (turned " << p.turned_deg << " deg)";
  EXPECT_GT(com_end.z(), com.z() - 0.005) << "Bullet: the mug dropped";
  // The same check with 5 cm pieces, which close the handle, loses it: the test can fail.
  ValidatorConfig coarse = damped();
  coarse.loop_sized_pieces = false;
  const PoseCheck q = PhysicsValidator(mug, wall, coarse).check(best.X_WO);
  EXPECT_GT(q.moved_m, coarse.max_translation) << "with its handle closed the mug should not stay on the peg";
}

}  // namespace
}  // namespace validation
}  // namespace place_planner
