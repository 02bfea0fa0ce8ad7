// The MuJoCo validator (the suites' second engine) on cases whose answer is known by hand, and
// against Bullet on a real scene.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/model/mesh.h"
#include "place_planner/planner.h"
#include "place_planner/validation/mujoco_validator.h"
#include "place_planner/validation/physics_validator.h"
#include "validation_test_helpers.h"

namespace place_planner {
namespace validation {
namespace {

Eigen::Isometry3d tiltedX(double deg, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X.translation() = t;
  return X;
}

// The mesh with every triangle's winding reversed (built here, not by the validator under test).
Mesh woundTheOtherWay(const Mesh& m) {
  std::vector<std::vector<int>> polygons;
  for (const auto& t : m.triangles) polygons.push_back({t[0], t[2], t[1]});
  return buildMesh(m.vertices, polygons, "wound the other way");
}

ValidatorConfig withFriction(double mu) {
  ValidatorConfig c;
  c.friction = mu;
  return c;
}

// The 10 cm cube (its frame at the centre of its bottom face) flat on the table stays; on a
// corner it falls.
TEST(MujocoValidator, CubeFlatStaysAndCubeOnAnEdgeFalls) {
  MujocoValidator v(scenes::byName("cube"), scenes::table(), withFriction(0.2));
  EXPECT_GE(v.objectPieces(), 6);  // a face rests on several pieces: several contacts
  const PoseCheck flat = v.check(Eigen::Isometry3d::Identity());
  EXPECT_TRUE(flat.confirmed) << "moved " << flat.moved_m << " m, turned " << flat.turned_deg << " deg";
  EXPECT_LT(flat.moved_m, 0.003);  // the 2 mm release gap
  EXPECT_LT(flat.turned_deg, 0.5);
  // Turned 30 degrees about x, resting on the edge y = -5 cm: the centre of mass is beyond it.
  const Eigen::Isometry3d edge = tiltedX(30.0, Eigen::Vector3d(0, 0.05 - 0.05 * std::cos(M_PI / 6), 0.05 * std::sin(M_PI / 6)));
  const PoseCheck r = v.check(edge);
  EXPECT_FALSE(r.confirmed);
  EXPECT_GT(r.turned_deg, 10.0);
}

// A scan of an area may be wound facing into the table (the shared real scan of a tissue box
// is): the cube flat on a plane whose triangles face down stays as on one facing up. Before the
// area was turned over, its slabs were thickened upwards, and the cube let go inside them was
// thrown 2.4 cm.
TEST(MujocoValidator, KeepsACubeOnAnAreaWoundFacingDown) {
  const Mesh plane = scenes::plane(0.6, 0.6);
  const Mesh flipped = woundTheOtherWay(plane);
  ASSERT_LT(flipped.patch_normals.front().z(), -0.99);
  for (const Mesh* area : {&plane, &flipped}) {
    MujocoValidator v(scenes::byName("cube"), *area, withFriction(0.2));
    const PoseCheck k = v.check(Eigen::Isometry3d::Identity());
    EXPECT_TRUE(k.confirmed) << area->patch_normals.front().z() << ": moved " << k.moved_m << " m, turned "
                             << k.turned_deg << " deg";
    EXPECT_LT(k.moved_m, 0.003);
  }
  // A closed area is kept as it is: the table's underside faces down by right.
  MujocoValidator table(scenes::byName("cube"), scenes::table(), withFriction(0.2));
  EXPECT_TRUE(table.check(Eigen::Isometry3d::Identity()).confirmed);
}

// A mesh wound inwards (a reconstruction's normals flipped) is the same body: the YCB mug
// upright on the table, and the cube on a table wound inwards, stay in both engines as wound
// outwards. Before the pieces were turned outwards, their slabs stood out of the mug and Bullet
// and MuJoCo kept none of its three best poses on books_stack.
TEST(MujocoValidator, AMeshWoundInwardsIsTheSameBody) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh table = scenes::table();
  // Upright, its base on the table (the mug's frame is at its base).
  double low = 1e300;
  for (const Eigen::Vector3d& v : mug.vertices) low = std::min(low, v.z());
  const Eigen::Isometry3d upright(Eigen::Translation3d(0, 0, -low));
  for (const Mesh& object : {mug, woundTheOtherWay(mug)}) {
    const PoseCheck b = PhysicsValidator(object, table, withFriction(0.2)).check(upright);
    EXPECT_TRUE(b.confirmed) << "Bullet: moved " << b.moved_m << " m, turned " << b.turned_deg << " deg";
    const PoseCheck m = MujocoValidator(object, table, withFriction(0.2)).check(upright);
    EXPECT_TRUE(m.confirmed) << "MuJoCo: moved " << m.moved_m << " m, turned " << m.turned_deg << " deg";
  }
  const PoseCheck cube = MujocoValidator(scenes::byName("cube"), woundTheOtherWay(table), withFriction(0.2)).check(Eigen::Isometry3d::Identity());
  EXPECT_TRUE(cube.confirmed) << "the table wound inwards: moved " << cube.moved_m << " m";
}

// The friction law on a slope, both sides of tan(slope) = mu, as Bullet's test of the same.
TEST(MujocoValidator, CubeOnASlopeSticksOrSlidesByFriction) {
  struct Case {
    double slope_deg, mu;
    bool sticks;
  };
  for (const Case& k : {Case{20.0, 0.3, false}, Case{20.0, 0.4, true}, Case{30.0, 0.2, false}, Case{5.0, 0.2, true}}) {
    MujocoValidator v(scenes::byName("cube"), scenes::plane(1.0, 1.0, k.slope_deg), withFriction(k.mu));
    const PoseCheck r = v.check(tiltedX(k.slope_deg));
    EXPECT_EQ(r.confirmed, k.sticks) << k.slope_deg << " deg at mu " << k.mu << ": moved " << r.moved_m << " m";
    if (!k.sticks) EXPECT_GT(r.moved_m, 0.01);
  }
}

// A can lying across a 10 degree slope's fall line rolls down it however rough the slope;
// lying along the fall line at mu 0.8 (tan 10 = 0.18) it stays.
TEST(MujocoValidator, CanRollsAcrossASlopeAndStaysAlongIt) {
  const Mesh can = scenes::cylinder(0.03, 0.12, 32);  // axis z, centred at its origin
  MujocoValidator v(can, scenes::plane(1.0, 1.0, 10.0), withFriction(0.8));
  const Eigen::Isometry3d slope = tiltedX(10.0);
  auto lying = [&](const Eigen::Vector3d& axis) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    // On a side facet (turned half a facet about its axis), the facet's distance above the slope.
    X.linear() = slope.linear() * Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix() *
                 Eigen::AngleAxisd(M_PI / 32, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    X.translation() = slope.linear() * Eigen::Vector3d(0, 0, 0.03 * std::cos(M_PI / 32));
    return X;
  };
  const PoseCheck across = v.check(lying(Eigen::Vector3d::UnitX()));
  EXPECT_FALSE(across.confirmed);
  EXPECT_GT(across.moved_m, 0.01);
  const PoseCheck along = v.check(lying(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(along.confirmed) << "moved " << along.moved_m << " m, turned " << along.turned_deg << " deg";
  // Bullet the same.
  const PhysicsValidator bullet(can, scenes::plane(1.0, 1.0, 10.0), withFriction(0.8));
  EXPECT_FALSE(bullet.check(lying(Eigen::Vector3d::UnitX())).confirmed);
  EXPECT_TRUE(bullet.check(lying(Eigen::Vector3d::UnitY())).confirmed);
}

// A truncated cone (9 cm base, 2 cm top, 9 cm tall) standing on its base stays in both
// engines. Its side's slabs, thickened along the side's inward normal (21 degrees below
// horizontal), reached 3.6 mm below the base at the rim until they were kept inside the cone's
// hull (clipToHull); MuJoCo then stood the cone on their corners and tipped it 21 degrees.
TEST(MujocoValidator, ConeOnItsBaseStaysItsSlabsInsideItsHull) {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> faces;
  std::vector<int> bottom, top;
  const int n = 32;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    v.emplace_back(0.045 * std::cos(a), 0.045 * std::sin(a), 0.0);
    v.emplace_back(0.010 * std::cos(a), 0.010 * std::sin(a), 0.09);
  }
  for (int k = 0; k < n; ++k) {
    const int a = 2 * k, b = 2 * ((k + 1) % n);
    faces.push_back({a, b, b + 1, a + 1});
    bottom.insert(bottom.begin(), a);
    top.push_back(a + 1);
  }
  faces.push_back(bottom);
  faces.push_back(top);
  const Mesh cone = buildMesh(v, faces, "cone");
  std::vector<std::vector<Eigen::Vector3d>> pieces = convexPieces(cone, ValidatorConfig{});
  clipToHull(pieces, cone.vertices);
  for (const auto& piece : pieces)
    for (const Eigen::Vector3d& p : piece) EXPECT_GE(p.z(), -1e-6);  // m: not below the base
  MujocoValidator mujoco(cone, scenes::table(), withFriction(0.2));
  const PoseCheck m = mujoco.check(Eigen::Isometry3d::Identity());
  EXPECT_TRUE(m.confirmed) << "moved " << m.moved_m << " m, turned " << m.turned_deg << " deg";
  EXPECT_LT(m.turned_deg, 1.0);
  const PhysicsValidator bullet(cone, scenes::table(), withFriction(0.2));
  EXPECT_TRUE(bullet.check(Eigen::Isometry3d::Identity()).confirmed);
}

// A triangle of a tenth of a millimetre seeds no slab: its normal is the mesh's noise. The
// full-resolution YCB mug has such slivers at its rim, and one, thickened 1 cm along its
// normal, reached 8 mm out through the rim: stood on its rim, MuJoCo threw the mug 4 cm.
TEST(MujocoValidator, SliversSeedNoSlabAndTheMugStandsOnItsRim) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025.ply");
  const std::vector<std::vector<Eigen::Vector3d>> pieces = mujocoObjectPieces(mug);  // the model's own
  std::vector<std::vector<Eigen::Vector3d>> inside = pieces;
  clipToHull(inside, mug.vertices);  // each point moved onto the mug's hull where outside it
  double worst = 0.0;
  for (size_t i = 0; i < pieces.size(); ++i)
    for (size_t k = 0; k < pieces[i].size(); ++k) worst = std::max(worst, (pieces[i][k] - inside[i][k]).norm());
  EXPECT_LT(worst, 0.002) << "a slab point " << worst << " m outside the mug's convex hull";
  // Upside down on its rim on the table, released 2 mm above: it stays in both engines.
  Eigen::Isometry3d X = tiltedX(180.0);
  double low = 1e9;
  for (const Eigen::Vector3d& v : mug.vertices) low = std::min(low, (X * v).z());
  X.translation().z() = -low;
  const ValidatorConfig vc = withFriction(0.2);
  const PoseCheck m = MujocoValidator(mug, scenes::table(), vc).check(X);
  EXPECT_TRUE(m.confirmed) << "MuJoCo: moved " << m.moved_m << " m, turned " << m.turned_deg << " deg";
  EXPECT_TRUE(PhysicsValidator(mug, scenes::table(), vc).check(X).confirmed);
}

// The two engines agree on the planner's best poses of the 1k mug on the table, and on a
// pose that is not stable.
TEST(MujocoValidator, AgreesWithBulletOnTheMugsBestPoses) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const Mesh mug = validation_test::sharedMesh("objects/mug_ycb025_1k.ply");
  const Mesh table = scenes::table();
  PlannerConfig pc;
  pc.max_candidates = 3;
  const PlanResult plan = Planner().plan(mug, table, pc);
  ASSERT_GE(plan.stableCount(), 1);
  const ValidatorConfig vc = withFriction(pc.friction);
  const PhysicsValidator bullet(mug, table, vc);
  const MujocoValidator mujoco(mug, table, vc);
  for (const Candidate& c : plan.candidates) {
    if (!c.stable) continue;
    const PoseCheck b = bullet.check(c.X_WO), m = mujoco.check(c.X_WO);
    EXPECT_TRUE(b.confirmed);
    EXPECT_TRUE(m.confirmed) << "MuJoCo: moved " << m.moved_m << " m, turned " << m.turned_deg << " deg";
  }
  // The best pose turned 40 degrees about a horizontal axis and lifted clear: both drop it.
  Eigen::Isometry3d X = plan.candidates.front().X_WO;
  X.linear() = Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix() * X.linear();
  X.translation().z() += 0.05;
  EXPECT_FALSE(bullet.check(X).confirmed);
  EXPECT_FALSE(mujoco.check(X).confirmed);
}

}  // namespace
}  // namespace validation
}  // namespace place_planner
