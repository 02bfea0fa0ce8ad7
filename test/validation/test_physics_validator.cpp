// The Bullet validator on analytic cases whose answer is known by hand.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/planner.h"
#include "place_planner/search/resting_faces.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/validation/physics_validator.h"
#include "validation_test_helpers.h"

namespace place_planner {
namespace validation {
namespace {

Eigen::Isometry3d pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R;
  X.translation() = t;
  return X;
}
Eigen::Matrix3d rotX(double deg) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
// Cube of 10 cm with its mesh frame at the centre of its bottom face.
Mesh cube() { return scenes::byName("cube"); }

ValidatorConfig withFriction(double mu) {
  ValidatorConfig c;
  c.friction = mu;
  return c;
}

TEST(PhysicsValidator, CubeFlatOnTableIsConfirmed) {
  ValidatorConfig c = withFriction(0.2);
  c.early_accept_steps = 0;  // the full 2 s
  PhysicsValidator v(cube(), scenes::table(), c);
  EXPECT_EQ(v.convexPieces(), 1);  // convex: simulated as its hull
  EXPECT_NEAR(v.convexity(), 1.0, 1e-6);
  EXPECT_NEAR(v.mass(), 400.0 * 1e-3, 1e-9);
  const PoseCheck r = v.check(Eigen::Isometry3d::Identity());
  EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
  EXPECT_LT(r.moved_m, 0.003);  // the 2 mm release gap
  EXPECT_LT(r.turned_deg, 0.5);
  EXPECT_FALSE(r.early_accepted);
  EXPECT_NEAR(r.sim_time, 2.0, 1e-6);
}

TEST(PhysicsValidator, CubeOfPiecesFlatOnTableIsConfirmed) {
  ValidatorConfig c = withFriction(0.2);
  c.convex_volume_ratio = 1.01;  // force the compound of surface pieces
  PhysicsValidator v(cube(), scenes::table(), c);
  EXPECT_GE(v.convexPieces(), 6);
  EXPECT_LE(v.convexPieces(), 12);  // at most one per triangle
  const PoseCheck r = v.check(Eigen::Isometry3d::Identity());
  EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
  EXPECT_LT(r.moved_m, 0.003);
}

TEST(PhysicsValidator, CubeOnThinTwoTrianglePlaneIsConfirmed) {
  PhysicsValidator v(cube(), scenes::plane(1.0, 1.0), withFriction(0.5));
  const PoseCheck r = v.check(pose(Eigen::Matrix3d::Identity(), {0.1, -0.05, 0.0}));
  EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
}

// tan(30 deg) = 0.58 > mu = 0.2: the cube slides down the slope; at mu = 0.8 it sticks.
TEST(PhysicsValidator, CubeOnSlopeSlidesOrSticksByFriction) {
  const Mesh slope = scenes::plane(1.0, 1.0, 30.0);
  const Eigen::Isometry3d X_WO = pose(rotX(30.0), Eigen::Vector3d::Zero());
  {
    PhysicsValidator v(cube(), slope, withFriction(0.2));
    const PoseCheck r = v.check(X_WO);
    EXPECT_FALSE(r.confirmed) << "moved " << r.moved_m << " m";
    EXPECT_GT(r.moved_m, 0.01);
  }
  {
    PhysicsValidator v(cube(), slope, withFriction(0.8));
    const PoseCheck r = v.check(X_WO);
    EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
  }
}

// tan(5 deg) = 0.087 < 0.2: sticks (the measured case where 0.5 mm margins went wrong).
TEST(PhysicsValidator, CubeOnGentleSlopeSticks) {
  PhysicsValidator v(cube(), scenes::plane(1.0, 1.0, 5.0), withFriction(0.2));
  const PoseCheck r = v.check(pose(rotX(5.0), Eigen::Vector3d::Zero()));
  EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
}

// tan(20 deg) = 0.36: slides at mu 0.3, sticks at mu 0.4 (the textbook threshold).
TEST(PhysicsValidator, FrictionThresholdOnTwentyDegrees) {
  const Mesh slope = scenes::plane(1.0, 1.0, 20.0);
  const Eigen::Isometry3d X_WO = pose(rotX(20.0), Eigen::Vector3d::Zero());
  EXPECT_FALSE(PhysicsValidator(cube(), slope, withFriction(0.3)).check(X_WO).confirmed);
  EXPECT_TRUE(PhysicsValidator(cube(), slope, withFriction(0.4)).check(X_WO).confirmed);
}

TEST(PhysicsValidator, CylinderUprightIsConfirmed) {
  PhysicsValidator v(scenes::cylinder(0.04, 0.1, 32), scenes::table(), withFriction(0.3));
  const PoseCheck r = v.check(pose(Eigen::Matrix3d::Identity(), {0, 0, 0.05}));
  EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
}

// A solid mug (a closed cylinder, 10 cm across, and a C of 6 mm bars for a handle) fills over
// 85 % of its convex hull, but the hull would also fill the handle's opening: a bar through the
// opening, touching nothing, would then be inside the mug, and Bullet would throw the mug off
// it (moved 18 mm). Standing on the table with the bar through its handle, it stays.
TEST(PhysicsValidator, ASolidMugsHandleStaysOpen) {
  using scenes::box;
  // The opening: x 0.05-0.069, z -0.027-0.027 (the body's centre at the origin).
  const Mesh mug = scenes::merge({scenes::cylinder(0.05, 0.1, 32), box(0.03, 0.006, 0.006, {0.06, 0, 0.03}),
                                  box(0.03, 0.006, 0.006, {0.06, 0, -0.03}), box(0.006, 0.006, 0.066, {0.072, 0, 0})});
  const Mesh area = scenes::merge({scenes::table(), box(0.006, 0.2, 0.006, {0.06, 0, 0.05})});
  PhysicsValidator v(mug, area, withFriction(0.3));
  const PoseCheck r = v.check(pose(Eigen::Matrix3d::Identity(), {0, 0, 0.05}));
  EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
}

// Balanced on its bottom rim, tilted 30 deg: the centre of mass is 1 cm off the contact edge,
// so it falls back (or over). Not a stable pose.
TEST(PhysicsValidator, CylinderTiltedOnItsEdgeIsRejected) {
  const double r = 0.04, h = 0.1, tilt = 30.0 * M_PI / 180.0;
  const double lift = r * std::sin(tilt) + h / 2 * std::cos(tilt);  // lowest rim point to 0
  PhysicsValidator v(scenes::cylinder(r, h, 32), scenes::table(), withFriction(0.3));
  const PoseCheck c = v.check(pose(rotX(30.0), {0, 0, lift}));
  EXPECT_FALSE(c.confirmed) << "moved " << c.moved_m << " m, turned " << c.turned_deg << " deg";
  EXPECT_GT(c.turned_deg, 5.0);
}

TEST(PhysicsValidator, CylinderLyingOnItsSideIsConfirmed) {
  const double r = 0.04, h = 0.1;
  // 32-gon lying on a facet: the facet between vertices 0 and 1 has its normal at angle pi/32
  // about z; turn it to +x, then +90 deg about y takes +x to -z (down).
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix() *
      Eigen::AngleAxisd(-M_PI / 32, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const double apothem = r * std::cos(M_PI / 32);
  PhysicsValidator v(scenes::cylinder(r, h, 32), scenes::table(), withFriction(0.3));
  const PoseCheck c = v.check(pose(R, {0, 0, apothem}));
  EXPECT_TRUE(c.confirmed) << "moved " << c.moved_m << " m, turned " << c.turned_deg << " deg";
}

// A round body let go lying along a V trough (sides 35 degrees, past atan 0.2) lands on one
// side and slides down it into the groove, where it rests on both sides: the planner's best
// pose has its axis over the groove at the height the two tangent sides give (r / cos 35),
// and Bullet keeps it. Without the slide down a surface steeper than friction the trees
// turned it about its line of contact by fractions of a degree until they were cut, and no
// pose was stable.
TEST(PhysicsValidator, CylinderLyingAlongAVTroughRestsInItsGroove) {
  const double r = 0.03, h = 0.16, side = 35.0;
  const Mesh rod = scenes::cylinder(r, h, 48);
  const Mesh trough = scenes::vTrough(0.6, side);
  PlannerConfig config;
  config.threads = 2;
  config.orientation = OrientationMode::kKeep;  // lying, its axis along the groove (x)
  config.start_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));
  const PlanResult r_plan = Planner().plan(rod, trough, config);
  ASSERT_FALSE(r_plan.candidates.empty());
  const Candidate& best = r_plan.candidates.front();
  ASSERT_TRUE(best.stable) << "no stable pose: " << r_plan.candidates.size() << " candidates";
  const Eigen::Vector3d com = best.X_WO * rod.properties.center_of_mass;
  EXPECT_NEAR(com.y(), 0.0, 0.003) << "not over the groove";
  EXPECT_NEAR(com.z(), r / std::cos(side * M_PI / 180), 0.003);
  bool left = false, right = false;
  for (const auto& p : best.contacts) left |= p.p_W.y() < -0.005, right |= p.p_W.y() > 0.005;
  EXPECT_TRUE(left && right) << "it must rest on both sides";
  PhysicsValidator v(rod, trough, withFriction(config.friction));
  const PoseCheck k = v.check(best.X_WO);
  EXPECT_TRUE(k.confirmed) << "moved " << k.moved_m << " m, turned " << k.turned_deg << " deg";
}

// The early-accept shortcut gives the same verdict and nearly the same pose as the full 2 s.
TEST(PhysicsValidator, EarlyAcceptAgreesWithTheFullRun) {
  struct Case {
    Mesh object, area;
    Eigen::Isometry3d X;
    double mu;
  };
  const double r = 0.04, h = 0.1, tilt = 30.0 * M_PI / 180.0;
  const std::vector<Case> cases = {
      {cube(), scenes::table(), Eigen::Isometry3d::Identity(), 0.2},
      {cube(), scenes::plane(1.0, 1.0, 5.0), pose(rotX(5.0), Eigen::Vector3d::Zero()), 0.2},
      {cube(), scenes::plane(1.0, 1.0, 20.0), pose(rotX(20.0), Eigen::Vector3d::Zero()), 0.4},
      {cube(), scenes::plane(1.0, 1.0, 20.0), pose(rotX(20.0), Eigen::Vector3d::Zero()), 0.3},
      {scenes::cylinder(r, h, 32), scenes::binderStack(), pose(Eigen::Matrix3d::Identity(), {-0.05, 0, 0.22}), 0.3},
      {scenes::cylinder(r, h, 32), scenes::table(),
       pose(rotX(30.0), {0, 0, r * std::sin(tilt) + h / 2 * std::cos(tilt)}), 0.3}};
  int early = 0;
  for (size_t i = 0; i < cases.size(); ++i) {
    ValidatorConfig full = withFriction(cases[i].mu), fast = full;
    full.early_accept_steps = 0;
    const PoseCheck a = PhysicsValidator(cases[i].object, cases[i].area, full).check(cases[i].X);
    const PoseCheck b = PhysicsValidator(cases[i].object, cases[i].area, fast).check(cases[i].X);
    EXPECT_EQ(a.confirmed, b.confirmed) << "case " << i;
    if (b.early_accepted) {
      ++early;
      EXPECT_LT(b.sim_time, full.settle_time);
      EXPECT_LT((a.X_WO_final.translation() - b.X_WO_final.translation()).norm(), 0.002) << i;
    }
  }
  EXPECT_GE(early, 3);
}

TEST(PhysicsValidator, FloatingPoseIsRejected) {
  PhysicsValidator v(cube(), scenes::table(), withFriction(0.2));
  const PoseCheck r = v.check(pose(Eigen::Matrix3d::Identity(), {0, 0, 0.05}));
  EXPECT_FALSE(r.confirmed);
}

// A tilted cube dropped from 4 cm settles on a face: one of its axes points up, its centre of
// mass 5 cm above the table.
TEST(PhysicsValidator, DroppedCubeSettlesFaceDown) {
  PhysicsValidator v(cube(), scenes::table(), withFriction(0.5));
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d c_O(0, 0, 0.05);
  const Eigen::Isometry3d X0 = pose(R, Eigen::Vector3d(0, 0, 0.04 + 0.09) - R * c_O);
  const DropResult d = v.drop(X0);
  ASSERT_TRUE(d.at_rest) << "steps " << d.steps;
  EXPECT_FALSE(d.fell_off);
  double best = 0;
  for (int k = 0; k < 3; ++k) best = std::max(best, std::abs(d.X_WO_rest.linear().col(k).z()));
  EXPECT_GT(best, std::cos(2.0 * M_PI / 180.0));
  EXPECT_NEAR((d.X_WO_rest * c_O).z(), 0.05, 0.003);
  EXPECT_GT(d.wall_ms, 0.0);
}

TEST(PhysicsValidator, DropOffTheEdgeFallsOff) {
  PhysicsValidator v(cube(), scenes::table(), withFriction(0.5));
  const DropResult d = v.drop(pose(Eigen::Matrix3d::Identity(), {2.0, 0, 0.1}));
  EXPECT_FALSE(d.at_rest);
  EXPECT_TRUE(d.fell_off);
}

TEST(PhysicsValidator, BadConfigNamesTheField) {
  ValidatorConfig c;
  c.friction = -1;
  try {
    PhysicsValidator v(cube(), scenes::table(), c);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("friction"), std::string::npos) << e.what();
  }
}

TEST(PhysicsValidator, YcbMugUprightOnSharedTable) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh table = validation_test::sharedMesh("areas/table.ply");
  PhysicsValidator v(mug, table, withFriction(0.3));
  EXPECT_GT(v.convexPieces(), 50);
  // Upright: lift the mug so its lowest vertex touches z = 0.
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation().z() = -mug.properties.bounds_min.z();
  const PoseCheck r = v.check(X);
  EXPECT_TRUE(r.confirmed) << "moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
}

// The 2 cm scanned marker released 2 mm above each of its six best hull facets (tipping margins
// 7-11 degrees: it holds on each, by hand) stays put. At 1 Bullet unit per metre it sank 1-2 mm
// and rolled off all six at up to 0.3 m/s (ValidatorConfig::world_scale).
TEST(PhysicsValidator, YcbMarkerLyingOnItsHullFacetsStaysPut) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh marker = validation_test::sharedMesh("objects/marker_ycb040_1k.ply");
  const Mesh table = validation_test::sharedMesh("areas/table.ply");
  const auto faces = restingFaces(marker, 7.0 * M_PI / 180.0);
  ASSERT_GE(faces.size(), 6u);
  PhysicsValidator v(marker, table, withFriction(0.2));
  for (size_t i = 0; i < 6; ++i) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = Eigen::Quaterniond::FromTwoVectors(faces[i].normal_O, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
    double low = 1e9;
    for (const auto& p : marker.vertices) low = std::min(low, (X.linear() * p).z());
    X.translation().z() = -low;
    const PoseCheck r = v.check(X);
    EXPECT_TRUE(r.confirmed) << "facet " << i << ": moved " << r.moved_m << " m, turned " << r.turned_deg << " deg";
  }
}

// Thin-walled objects rest at their geometric height: the YCB mug, bowl and plate (compounds of
// slabs, their bottoms 1-3 mm thick) released exactly on the table end within 2 mm of where
// they were put. Slabs thickened to 6 margins poked through those bottoms: they rested 5.4-6.8 mm
// high, which a 1 cm "stays put" bar then mostly spent before anything moved.
TEST(PhysicsValidator, ThinWalledYcbObjectsRestAtTheirHeight) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh table = validation_test::sharedMesh("areas/table.ply");
  for (const std::string name : {"mug_ycb025", "bowl_ycb024", "plate_ycb029"}) {
    const Mesh object = validation_test::sharedMesh("objects/" + name + ".ply");
    PhysicsValidator v(object, table, withFriction(0.2));
    ASSERT_GT(v.convexPieces(), 1) << name << ": a compound of slabs, not one hull";
    double low = 1e9;
    for (const auto& p : object.vertices) low = std::min(low, p.z());
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Eigen::Vector3d(0.1, 0.05, -low);
    const PoseCheck r = v.check(X);
    const double rise = r.X_WO_final.translation().z() - X.translation().z();
    EXPECT_LT(std::abs(rise), 0.002) << name << " rests " << 1000 * rise << " mm above its height";
    EXPECT_TRUE(r.confirmed) << name;
  }
}

// The cracker box on the divided tray, default options (rock settle on): the five best stable
// candidates stay put in Bullet. Before the wedge rule (tree_stepper.cpp, kWedgeTilt) three of
// them were the box rocked down across a compartment onto its walls' edges, and fell in.
TEST(PhysicsValidator, CrackerBoxInDividedTrayBestCandidatesStayPut) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh box = validation_test::sharedMesh("objects/cracker_box_ycb003_1k.ply");
  const Mesh tray = validation_test::sharedMesh("areas/divided_tray.ply");
  const PlanResult r = Planner().plan(box, tray, PlannerConfig());
  PhysicsValidator v(box, tray, withFriction(PlannerConfig().friction));
  int checked = 0;
  for (const Candidate& c : r.candidates) {
    if (!c.stable || checked == 5) continue;
    ++checked;
    const PoseCheck k = v.check(c.X_WO);
    EXPECT_TRUE(k.confirmed) << "candidate at " << c.X_WO.translation().transpose() << ": moved " << k.moved_m
                             << " m, turned " << k.turned_deg << " deg";
  }
  EXPECT_EQ(checked, 5);
}

// The YCB bowl on the 1k pen cup, default options. Upside down over the cup's rim like a lid,
// its dome on the rim all round, it was judged hanging and ranked best; but the contacts'
// normals meet 2-3 cm below its centre of mass, and Bullet slides it off the rim (15 mm, 8
// degrees; MuJoCo 22 mm). Now no stable candidate is held from above, and the best (the bowl
// standing on the rim) stays put.
TEST(PhysicsValidator, BowlIsNotLaidUpsideDownOverThePenCupsRim) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh bowl = validation_test::sharedMesh("objects/bowl_ycb024_1k.ply");
  const Mesh cup = validation_test::sharedMesh("areas/pen_cup_ycb065j_1k.ply");
  PlannerConfig config;
  config.threads = 2;
  const PlanResult r = Planner().plan(bowl, cup, config);
  PhysicsValidator v(bowl, cup, withFriction(config.friction));
  // The lid pose the planner returned first before.
  Eigen::Isometry3d lid = Eigen::Isometry3d::Identity();
  lid.linear() = Eigen::Quaterniond(-0.007, 0.964, -0.266, 0.0).normalized().toRotationMatrix();
  lid.translation() = Eigen::Vector3d(-0.010, -0.045, 0.081);
  const PoseCheck off = v.check(lid);
  EXPECT_FALSE(off.confirmed) << "the lid moved " << off.moved_m << " m, turned " << off.turned_deg << " deg";
  const Candidate* best = nullptr;
  for (const Candidate& c : r.candidates) {
    if (!c.stable) continue;
    EXPECT_FALSE(c.hanging) << "a stable candidate held from above at " << c.X_WO.translation().transpose();
    if (best == nullptr) best = &c;
  }
  ASSERT_NE(best, nullptr) << "nothing stable";
  const PoseCheck k = v.check(best->X_WO);
  EXPECT_TRUE(k.confirmed) << "best at " << best->X_WO.translation().transpose() << ": moved " << k.moved_m
                           << " m, turned " << k.turned_deg << " deg";
}

// The YCB marker on an 8 degree ramp (under the friction angle, 11.3 degrees) whose fall line
// runs across the marker's own long axis, default options: the three best stable candidates
// lie along the fall line and stay put in Bullet. Started only from its resting faces, held and
// principal-axis orientations, every candidate lay across the ramp, and Bullet rolled each of
// them down it (30-49 degrees, 5-7 mm).
TEST(PhysicsValidator, YcbMarkerOnARampLiesAlongItsFallLineAndStays) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh marker = validation_test::sharedMesh("objects/marker_ycb040_1k.ply");
  // Rising along x: its fall line runs across the marker's own long axis (y).
  const double t = 8.0 * M_PI / 180;
  const Mesh ramp = buildMesh({{-0.4, -0.4, -0.4 * std::tan(t)}, {0.4, -0.4, 0.4 * std::tan(t)},
                               {0.4, 0.4, 0.4 * std::tan(t)}, {-0.4, 0.4, -0.4 * std::tan(t)}},
                              {{0, 1, 2}, {0, 2, 3}}, "ramp");
  PlannerConfig config;
  config.threads = 2;
  const PlanResult r = Planner().plan(marker, ramp, config);
  PhysicsValidator v(marker, ramp, withFriction(config.friction));
  const Eigen::Vector3d long_axis_O = marker.properties.k1();
  int checked = 0;
  for (const Candidate& c : r.candidates) {
    if (!c.stable || checked == 3) continue;
    ++checked;
    const Eigen::Vector3d axis_W = c.X_WO.linear() * long_axis_O;
    EXPECT_GT(std::abs(axis_W.x()), std::cos(15 * M_PI / 180)) << "candidate " << checked << " lies across the ramp: its long axis "
                                                             << axis_W.transpose();
    const PoseCheck k = v.check(c.X_WO);
    EXPECT_TRUE(k.confirmed) << "candidate " << checked << ": moved " << k.moved_m << " m, turned " << k.turned_deg << " deg";
  }
  EXPECT_EQ(checked, 3);
}

// ---------------------------------------------------------------- verifyTopK

// The cube on the built-in table, planned from the principal axis (any core: it rests on a face).
PlannerConfig cubePlanConfig() {
  PlannerConfig c;
  c.orientation = OrientationMode::kPrincipalAxis;
  c.max_candidates = 10;
  c.threads = 2;
  return c;
}

PlanResult cubeOnTable(const PlannerConfig& c) { return Planner().plan(cube(), scenes::table(), c); }

// A candidate the planner called stable by hand.
Candidate handMade(const Eigen::Isometry3d& X_WO, double quality) {
  Candidate k;
  k.X_WO = X_WO;
  k.quality = quality;
  k.stable = true;
  return k;
}

TEST(VerifyTopK, CubeOnTableTopCandidatesStayAndTheRestAreUnchecked) {
  const PlannerConfig c = cubePlanConfig();
  PlanResult r = cubeOnTable(c);
  ASSERT_GE(r.stableCount(), 4) << "the cube on the table has many stable floor points";
  ASSERT_TRUE(r.candidates[0].stable);
  const std::vector<Candidate> before = r.candidates;
  const VerifyStats s = verifyTopK(cube(), scenes::table(), c, r, 3, 0.0, 2);
  EXPECT_EQ(s.selected, 3);
  EXPECT_EQ(s.checked, 3);
  EXPECT_EQ(s.stayed, 3);
  EXPECT_EQ(s.demoted, 0);
  EXPECT_GT(s.per_check_ms, 0.0);
  ASSERT_EQ(r.candidates.size(), before.size());
  for (size_t i = 0; i < r.candidates.size(); ++i) {
    const PhysicsCheck& p = r.candidates[i].physics;
    // Nothing fell, so nothing moved in the ranking.
    EXPECT_TRUE(r.candidates[i].X_WO.isApprox(before[i].X_WO)) << i;
    if (i < 3) {
      EXPECT_TRUE(p.checked) << i;
      EXPECT_TRUE(p.stayed) << i << ": moved " << p.moved_m << " m, turned " << p.turned_deg;
      EXPECT_LT(p.moved_m, 0.003) << i;  // the 2 mm release gap, settled
      EXPECT_LT(p.turned_deg, 0.5) << i;
    } else {
      EXPECT_FALSE(p.checked) << i;
      EXPECT_FALSE(p.stayed) << i;
    }
  }
}

// The object tilted 30 degrees about a horizontal diagonal, its lowest corner on the table
// (z = 0) at (0.1, 0.1).
Eigen::Isometry3d onACorner(const Mesh& object) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(30.0 * M_PI / 180.0, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  double min_z = 1e9;
  for (const auto& v : object.vertices) min_z = std::min(min_z, (X * v).z());
  X.translation() = Eigen::Vector3d(0.1, 0.1, -min_z);
  return X;
}

// A cube balanced on a corner, tilted 30 degrees, injected as the best "stable" candidate ahead
// of a cube flat on the table: Bullet sees it fall (turns far more than 5 degrees); it moves
// behind the flat one, still ahead of an unstable candidate, which is not simulated.
TEST(VerifyTopK, CubeTiltedOnACornerFallsAndMovesDownTheRanking) {
  const Mesh object = cube();
  const Eigen::Isometry3d X_tilted = onACorner(object);
  Eigen::Isometry3d X_flat = Eigen::Isometry3d::Identity();
  X_flat.translation() = Eigen::Vector3d(-0.2, 0.0, 0.0);
  Candidate unstable = handMade(X_flat, 0.2);
  unstable.stable = false;

  PlanResult r;
  r.candidates = {handMade(X_tilted, 0.9), handMade(X_flat, 0.8), unstable};
  const VerifyStats s = verifyTopK(object, scenes::table(), cubePlanConfig(), r, 5, 0.0, 2);
  EXPECT_EQ(s.selected, 2);  // the unstable one does not count
  EXPECT_EQ(s.checked, 2);
  EXPECT_EQ(s.stayed, 1);
  EXPECT_EQ(s.demoted, 1);
  ASSERT_EQ(r.candidates.size(), 3u);
  // New order: flat (stayed), tilted (fell), unstable (not simulated).
  EXPECT_DOUBLE_EQ(r.candidates[0].quality, 0.8);
  EXPECT_TRUE(r.candidates[0].physics.checked);
  EXPECT_TRUE(r.candidates[0].physics.stayed);
  const PhysicsCheck& fell = r.candidates[1].physics;
  EXPECT_DOUBLE_EQ(r.candidates[1].quality, 0.9);
  EXPECT_TRUE(fell.checked);
  EXPECT_FALSE(fell.stayed);
  EXPECT_GT(fell.turned_deg, 5.0) << "moved " << fell.moved_m << " m";
  EXPECT_TRUE(r.candidates[1].stable) << "the planner's verdict is kept";
  EXPECT_DOUBLE_EQ(r.candidates[2].quality, 0.2);
  EXPECT_FALSE(r.candidates[2].physics.checked);
  // Each keeps its place in the planner's ranking.
  EXPECT_EQ(r.candidates[0].physics.planner_rank, 1);
  EXPECT_EQ(fell.planner_rank, 0);
  EXPECT_EQ(r.candidates[2].physics.planner_rank, 2);
}

// The same two candidates checked in both engines (Engines::kBoth): each engine's own verdict is
// kept, the cube on its corner falls in both, the flat one stays in both, and stayed is both.
TEST(VerifyTopK, BothEnginesGiveTheirOwnVerdictsAndStayedNeedsBoth) {
  const Mesh object = cube();
  const Eigen::Isometry3d X_tilted = onACorner(object);
  Eigen::Isometry3d X_flat = Eigen::Isometry3d::Identity();
  X_flat.translation() = Eigen::Vector3d(-0.2, 0.0, 0.0);
  PlanResult r;
  r.candidates = {handMade(X_tilted, 0.9), handMade(X_flat, 0.8)};
  const VerifyStats s =
      verifyTopK(object, scenes::table(), cubePlanConfig(), r, 5, 0.0, 2, {}, Engines::kBoth);
  EXPECT_EQ(s.checked, 2);
  EXPECT_EQ(s.stayed, 1);
  EXPECT_EQ(s.bullet_stayed, 1);
  EXPECT_EQ(s.mujoco_stayed, 1);
  ASSERT_EQ(r.candidates.size(), 2u);
  const PhysicsCheck& flat = r.candidates[0].physics;
  const PhysicsCheck& fell = r.candidates[1].physics;
  EXPECT_EQ(fell.planner_rank, 0);
  EXPECT_TRUE(flat.bullet_checked && flat.bullet_stayed && flat.mujoco_checked && flat.mujoco_stayed && flat.stayed);
  EXPECT_TRUE(fell.bullet_checked && fell.mujoco_checked);
  EXPECT_FALSE(fell.bullet_stayed);
  EXPECT_FALSE(fell.mujoco_stayed);
  EXPECT_FALSE(fell.stayed);
  EXPECT_GT(fell.mujoco_turned_deg, 5.0) << "MuJoCo: moved " << fell.mujoco_moved_m << " m";
  // MuJoCo alone: its numbers stand in moved_m / turned_deg, Bullet is not asked.
  PlanResult m;
  m.candidates = {handMade(X_flat, 0.8)};
  verifyTopK(object, scenes::table(), cubePlanConfig(), m, 1, 0.0, 1, {}, Engines::kMujoco);
  EXPECT_FALSE(m.candidates[0].physics.bullet_checked);
  EXPECT_TRUE(m.candidates[0].physics.mujoco_stayed && m.candidates[0].physics.stayed);
  EXPECT_EQ(m.candidates[0].physics.moved_m, m.candidates[0].physics.mujoco_moved_m);
  EXPECT_EQ(enginesFromString("both"), Engines::kBoth);
  EXPECT_THROW(enginesFromString("ode"), std::invalid_argument);
}

TEST(VerifyTopK, KLargerThanTheCandidatesChecksEveryStableOne) {
  PlannerConfig c = cubePlanConfig();
  c.max_candidates = 4;
  PlanResult r = cubeOnTable(c);
  ASSERT_FALSE(r.candidates.empty());
  const VerifyStats s = verifyTopK(cube(), scenes::table(), c, r, 50, 0.0, 2);
  EXPECT_EQ(s.selected, r.stableCount());
  EXPECT_EQ(s.checked, r.stableCount());
  for (const Candidate& k : r.candidates) EXPECT_EQ(k.physics.checked, k.stable);
  // Nothing to check: no stable candidate, k = 0.
  PlanResult none;
  EXPECT_EQ(verifyTopK(cube(), scenes::table(), c, none, 5, 0.0, 2).checked, 0);
  EXPECT_EQ(verifyTopK(cube(), scenes::table(), c, r, 0, 0.0, 2).checked, 0);
  for (const Candidate& k : r.candidates) EXPECT_FALSE(k.physics.checked) << "k = 0 resets";
}

// One check of the cube takes a few ms (2 s simulated, or 0.6 s with the early accept): a 1 ms
// budget leaves time for at most one start per thread, and such a check is interrupted.
TEST(VerifyTopK, TinyBudgetChecksFewer) {
  const PlannerConfig c = cubePlanConfig();
  PlanResult r = cubeOnTable(c);
  ASSERT_GE(r.stableCount(), 8);
  PlanResult full = r;
  const VerifyStats all = verifyTopK(cube(), scenes::table(), c, full, 8, 0.0, 2);
  EXPECT_EQ(all.checked, 8);
  const VerifyStats few = verifyTopK(cube(), scenes::table(), c, r, 8, 1.0, 2);
  EXPECT_EQ(few.selected, 8);
  EXPECT_LE(few.checked, 2);
  EXPECT_LT(few.total_ms, 0.5 * all.total_ms) << "the budget did not cut the work";
  int checked = 0;
  for (const Candidate& k : r.candidates) checked += k.physics.checked;
  EXPECT_EQ(checked, few.checked);
  // A cancel before the start: nothing is simulated.
  const VerifyStats cancelled =
      verifyTopK(cube(), scenes::table(), c, r, 8, 0.0, 2, [] { return false; });
  EXPECT_EQ(cancelled.checked, 0);
}

// One validator's shapes shared by two threads give exactly the single-thread results.
TEST(VerifyTopK, TwoThreadsGiveTheSameVerdicts) {
  const PlannerConfig c = cubePlanConfig();
  PlanResult one = cubeOnTable(c), two = one;
  verifyTopK(cube(), scenes::table(), c, one, 6, 0.0, 1);
  verifyTopK(cube(), scenes::table(), c, two, 6, 0.0, 2);
  ASSERT_EQ(one.candidates.size(), two.candidates.size());
  for (size_t i = 0; i < one.candidates.size(); ++i) {
    EXPECT_EQ(one.candidates[i].physics.checked, two.candidates[i].physics.checked) << i;
    EXPECT_EQ(one.candidates[i].physics.stayed, two.candidates[i].physics.stayed) << i;
    EXPECT_EQ(one.candidates[i].physics.moved_m, two.candidates[i].physics.moved_m) << i;
    EXPECT_EQ(one.candidates[i].physics.turned_deg, two.candidates[i].physics.turned_deg) << i;
  }
}

TEST(VerifyTopK, RemainingBudget) {
  EXPECT_EQ(remainingBudgetMs(0.0, 50.0), 0.0);  // no budget: no limit
  EXPECT_DOUBLE_EQ(remainingBudgetMs(100.0, 30.0), 70.0);
  const double spent = remainingBudgetMs(100.0, 150.0);
  EXPECT_GT(spent, 0.0) << "a spent budget must not read as no limit";
  EXPECT_LT(spent, 1e-3);
}

// A flat L, 8 mm thick (y), as a J-hook's flank: an arm 6 cm along x and a tip 4 cm up (z),
// 1 cm wide, one planar face each side. In one piece, its hull fills the corner between arm
// and tip, where a handle hung on the arm passes (MuJoCo threw the YCB mug off a J-hook from
// there); with piece_min_fill no piece reaches into the corner.
Mesh flatL() {
  const double a = 0.06, h = 0.04, t = 0.01, w = 0.008;
  const std::vector<Eigen::Vector2d> o{{0, 0}, {a, 0}, {a, t}, {t, t}, {t, h}, {0, h}};  // x, z
  std::vector<Eigen::Vector3d> v;
  for (const double y : {0.0, w})
    for (const auto& p : o) v.emplace_back(p.x(), y, p.y());
  std::vector<std::vector<int>> f;
  for (int k = 1; k + 1 < 6; ++k) f.push_back({0, k, k + 1}), f.push_back({6, 6 + k + 1, 6 + k});  // outward
  for (int k = 0; k < 6; ++k) f.push_back({k, 6 + k, 6 + (k + 1) % 6, (k + 1) % 6});
  return buildMesh(v, f, "flat L");
}

// Whether (x, z) lies inside the convex outline of the points seen along y (monotone chain).
bool insideOutlineXZ(const std::vector<Eigen::Vector3d>& pts, double x, double z) {
  std::vector<Eigen::Vector2d> p;
  for (const auto& q : pts) p.emplace_back(q.x(), q.z());
  std::sort(p.begin(), p.end(), [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  auto turn = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> h;
  for (int pass = 0; pass < 2; ++pass) {
    const size_t start = h.size();
    for (const auto& q : p) {
      while (h.size() >= start + 2 && turn(h[h.size() - 2], h.back(), q) <= 0) h.pop_back();
      h.push_back(q);
    }
    h.pop_back();
    std::reverse(p.begin(), p.end());
  }
  if (h.size() < 3) return false;
  for (size_t i = 0; i < h.size(); ++i)
    if (turn(h[i], h[(i + 1) % h.size()], Eigen::Vector2d(x, z)) <= 0) return false;
  return true;
}

TEST(ConvexPieces, ACutAgainPieceDoesNotFillTheCornerOfAFlatL) {
  const Mesh L = flatL();
  ValidatorConfig c;
  c.piece_max_triangles = 1000;
  c.piece_max_size = 0.2;  // the whole face in one group
  auto reachesCorner = [&](double min_fill) {
    c.piece_min_fill = min_fill;
    int n = 0;
    for (const auto& piece : convexPieces(L, c)) n += insideOutlineXZ(piece, 0.03, 0.02);
    return n;
  };
  EXPECT_GT(reachesCorner(0.0), 0) << "the test would pass on nothing: one piece per face does not fill the corner";
  EXPECT_EQ(reachesCorner(0.8), 0);
}

// A horizontal bar 8 mm thick under MuJoCo's floor rule (piece_full_depth_along up): its top's
// slab reaches to the bar's underside, not 2 cm below it, where a handle hung on the bar passes.
// A floor piece as wide as the slab is thick keeps the 2 cm (a true contact normal).
TEST(ConvexPieces, AThinBarsTopSlabEndsAtItsUnderside) {
  ValidatorConfig c;
  c.piece_thickness = 0.02;
  c.piece_full_depth_along = Eigen::Vector3d::UnitZ();
  auto lowest = [&](const Mesh& m) {
    double z = 1;
    for (const auto& piece : convexPieces(m, c))
      for (const auto& p : piece) z = std::min(z, p.z());
    return z;
  };
  EXPECT_GT(lowest(scenes::box(0.10, 0.008, 0.008, {0, 0, 0.004})), -0.001);  // the bar: 0 to 8 mm
  EXPECT_LT(lowest(scenes::box(0.10, 0.10, 0.003, {0, 0, 0.0015})), -0.015);   // a 3 mm floor: 2 cm slabs
}

// The YCB plate stands in the shared dish rack at mu 0.2 (what PlannerShared.PlateStandsInDishRack
// asks of the planner). Dropped upright into the slot between the peg rows at y = 0.024 and
// y = -0.032 m, leaning 10 degrees either way, it comes to rest standing: its foot on the floor
// against one row's pegs, its face on the other row's tops (13 or 34 degrees from the vertical,
// the friction-free wedge of a ladder whose foot is held), and released again 2 mm above that
// rest it stays. (Of 60 such drops, 3 leans x 5 offsets x both faces x both sides, Bullet kept
// 50; doc/validation.md, "Bullet keeps the plate standing in the rack".)
TEST(PhysicsValidator, PlateStandsInTheDishRackSlot) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh plate = validation_test::sharedMesh("objects/plate_ycb029_1k.ply");
  const Mesh rack = validation_test::sharedMesh("areas/dish_rack.ply");
  ValidatorConfig vc;
  vc.friction = 0.2;
  const PhysicsValidator bullet(plate, rack, vc);
  const Eigen::Vector3d c_O = plate.properties.center_of_mass;
  const double x0 = -0.008, y0 = -0.004;  // m: between two pegs of each row, mid-slot
  double floor = 0.0;                      // the rack's base under the slot
  for (const Eigen::Vector3d& v : rack.vertices)
    if (std::abs(v.x() - x0) < 0.1 && std::abs(v.y() - y0) < 0.012) floor = std::max(floor, v.z());
  for (const double side : {-1.0, 1.0}) {
    // The plate's normal (its z) horizontal along y, then leaning 10 degrees about x.
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = (Eigen::AngleAxisd(side * 10.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) *
                  Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX())).toRotationMatrix();
    X.translation() = Eigen::Vector3d(x0, y0, 0.0) - X.linear() * c_O;
    double low = 1e300;
    for (const Eigen::Vector3d& v : plate.vertices) low = std::min(low, (X * v).z());
    X.translation().z() += floor + 0.004 - low;  // its foot 4 mm over the base
    const DropResult d = bullet.drop(X);
    ASSERT_TRUE(d.at_rest) << "side " << side;
    const Eigen::Vector3d n = d.X_WO_rest.linear().col(2);
    EXPECT_LT(std::abs(n.z()), std::sin(40.0 * M_PI / 180.0)) << "side " << side << ": not standing";
    EXPECT_GT((d.X_WO_rest * c_O).z(), floor + 0.1) << "side " << side << ": it fell over";
    const PoseCheck k = bullet.check(d.X_WO_rest);
    EXPECT_TRUE(k.confirmed) << "side " << side << ": moved " << k.moved_m << " m, turned " << k.turned_deg << " deg";
  }
}

// What a marker does in the YCB pen cup (8 cm across inside, 7.5 cm tall), the pose the planner
// should find there (PlannerShared.MarkerGoesIntoThePenCup): let go upright onto the cup's floor,
// it does not stand on its flat end (the floor's facets tilt 1-3 degrees under its 2 cm cap) but
// tips over until it leans across the cup, its foot in the corner of floor and wall, its body on
// the opposite rim, about 48 degrees from vertical, and stays there.
TEST(PhysicsValidator, MarkerLetGoUprightInThePenCupLeansAcrossIt) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh marker = validation_test::sharedMesh("objects/marker_ycb040_1k.ply");
  const Mesh cup = validation_test::sharedMesh("areas/pen_cup_ycb065j_1k.ply");
  const PhysicsValidator bullet(marker, cup, withFriction(0.2));
  const Eigen::Vector3d k1 = marker.properties.k1(), c_O = marker.properties.center_of_mass;
  const double rim = cup.properties.bounds_max.z(), floor = 0.008;  // m: the inner floor's height
  for (const double y : {0.0, 0.01}) {
    Eigen::Isometry3d X = pose(Eigen::Quaterniond::FromTwoVectors(k1, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                               Eigen::Vector3d::Zero());
    X.translation() = Eigen::Vector3d(0.0, y, 0.0) - X.linear() * c_O;
    double low = 1e300;
    for (const Eigen::Vector3d& v : marker.vertices) low = std::min(low, (X * v).z());
    X.translation().z() += floor + 0.002 - low;  // upright, its end 2 mm over the floor
    const DropResult d = bullet.drop(X);
    const double lean = std::acos(std::abs((d.X_WO_rest.linear() * k1).z())) * 180.0 / M_PI;
    EXPECT_GT(lean, 40.0) << "y " << y;
    EXPECT_LT(lean, 55.0) << "y " << y;
    double lo = 1e300, hi = -1e300;
    for (const Eigen::Vector3d& v : marker.vertices) {
      lo = std::min(lo, (d.X_WO_rest * v).z());
      hi = std::max(hi, (d.X_WO_rest * v).z());
    }
    EXPECT_LT(lo, floor + 0.003) << "y " << y << ": its foot on the floor, deep below the rim";
    EXPECT_GT(hi, rim) << "y " << y << ": leaning out over the rim";
    const PoseCheck k = bullet.check(d.X_WO_rest);
    EXPECT_TRUE(k.confirmed) << "y " << y << ": moved " << k.moved_m << " m, turned " << k.turned_deg << " deg";
  }
}

}  // namespace
}  // namespace validation
}  // namespace place_planner
