// the orientation search (resting faces, full tilt range), robust stability and
// stability against gravity. Each test asserts that work was done before the property.
#include <Eigen/Geometry>
#include <map>
#include <memory>

#include "place_planner/infra/backend.h"
#include "place_planner/infra/mesh_io.h"
#include "place_planner/planner.h"
#include "place_planner/search/resting_faces.h"
#include "place_planner/judgement/robustness.h"
#include "place_planner/judgement/contact_forces.h"
#include "place_planner/judgement/stability.h"
#include "place_planner/search/tree_stepper.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {

// Icosphere (subdivided icosahedron), outward wound: a ball.
Mesh icosphere(double radius, int subdivisions) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> g;
    for (const auto& tr : f) {
      const int a = midpoint(tr[0], tr[1]), b = midpoint(tr[1], tr[2]), c = midpoint(tr[2], tr[0]);
      g.push_back({tr[0], a, c});
      g.push_back({tr[1], b, a});
      g.push_back({tr[2], c, b});
      g.push_back({a, b, c});
    }
    f = g;
  }
  for (auto& p : v) p *= radius;
  std::vector<std::vector<int>> polys;
  for (const auto& tr : f) polys.push_back({tr[0], tr[1], tr[2]});
  return buildMesh(v, polys, "ball");
}

double minZ(const Mesh& m, const Candidate& c) {
  double z = 1e9;
  for (const auto& v : m.vertices) z = std::min(z, (c.X_WO * v).z());
  return z;
}

// One object over one area as the tree stepper sees it (G = W, gravity -z): the models, the CPU
// backend and a tree context (max 5 rotations, 8 local steps, 2 threads) with the collision
// distance r + r_area. Its members refer to each other: it is built in place, never copied.
struct TreeScene {
  TreeScene(const Mesh& object, const Mesh& area, double r, double r_area, double friction)
      : cd(r + r_area),
        om(buildObjectModel(object, r)),
        am(buildAreaModel(area, Eigen::Vector3d(0, 0, -1), r_area, cd, cd)),
        backend(makeCpuBackend(om, am, TiltParams{0.002, 1e-6 + 1e-4 * r}, 2)),
        ctx{om, am, *backend, StabilityParams{friction, 1.5 * cd, 3 * M_PI / 180, 0.0}, cd, 5, 8, 2} {}
  TreeScene(const TreeScene&) = delete;
  const double cd;
  const ObjectModel om;
  const AreaModel am;
  const std::unique_ptr<Backend> backend;
  TreeContext ctx;
};

// The leaves of one tree: X released and dropped along -z (at most tmax), stepped to its end.
std::vector<TreeLeaf> settle(const TreeContext& ctx, const Eigen::Isometry3d& X, const V3& com_O, double tmax) {
  TreeStepper stepper(ctx);
  stepper.addRoot(toRigid(X), 0, com_O, v3(0, 0, -1), tmax);
  std::vector<TreeLeaf> leaves;
  for (int i = 0; i < 200 && !stepper.empty(); ++i) stepper.step(leaves);
  return leaves;
}

// The leaning tests' area: a floor (top at z = 0), a wall with its face at x = 0.1 and a stop
// 15 mm tall with its face at x = -0.07.
Mesh wallAndStop() {
  return scenes::merge({scenes::box(0.6, 0.3, 0.02, {0, 0, -0.01}), scenes::box(0.02, 0.3, 0.3, {0.11, 0, 0.15}),
                        scenes::box(0.02, 0.3, 0.015, {-0.08, 0, 0.0075})},
                       "wall and stop");
}

// `rod` leaning 35 degrees towards the wall: its top corner 5 mm off it, its foot 3 mm above
// the floor.
Eigen::Isometry3d leaningOnTheWall(const Mesh& rod) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(35 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  double xmax = -1, zmin = 1;
  for (const auto& v : rod.vertices) {
    xmax = std::max(xmax, (X.linear() * v).x());
    zmin = std::min(zmin, (X.linear() * v).z());
  }
  X.translation() = Eigen::Vector3d(0.095 - xmax, 0, 0.003 - zmin);
  return X;
}

// At X the rod's foot is on the floor against the stop, its top on the wall.
void expectAgainstTheStop(const Mesh& rod, const Rigid& X) {
  double lo = 1, hi = -1, low = 1;
  for (const auto& v : rod.vertices) {
    const V3 q = apply(X, toV3(v));
    lo = std::min(lo, q.x);
    hi = std::max(hi, q.x);
    low = std::min(low, q.z);
  }
  EXPECT_NEAR(lo, -0.07, 0.004) << "its foot is not against the stop";
  EXPECT_NEAR(hi, 0.1, 0.004) << "its top is not on the wall";
  EXPECT_NEAR(low, 0.0, 0.004) << "its foot is not on the floor";
}

}  // namespace

// ------------------------------------------------------------------ resting faces (IV-A)
TEST(RestingFaces, BoxHasSix) {
  const auto faces = restingFaces(scenes::box(0.1, 0.06, 0.03), 10 * M_PI / 180);
  ASSERT_EQ(faces.size(), 6u);
  // Best margin first: lying on a 10 x 6 face (tipping about its short half-width 3 cm over a
  // 1.5 cm height) before standing on the 6 x 3 end.
  EXPECT_GT(std::abs(faces.front().normal_O.z()), 0.999);
  EXPECT_NEAR(faces.front().tipping_angle, std::atan2(0.03, 0.015), 1e-6);
  for (size_t i = 1; i < faces.size(); ++i) EXPECT_LE(faces[i].tipping_angle, faces[i - 1].tipping_angle);
}

TEST(RestingFaces, BallHasNone) {
  const Mesh ball = icosphere(0.04, 3);
  ASSERT_GT(convexHull3d(ball.vertices).faces.size(), 1000u);
  EXPECT_TRUE(restingFaces(ball, 10 * M_PI / 180).empty());
  // With no margin asked for, the facets are there: the filter is what removes them.
  EXPECT_FALSE(restingFaces(ball, 0.0).empty());
}

TEST(RestingFaces, MugIncludesUprightAndRimDown) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const auto faces = restingFaces(mug, 10 * M_PI / 180);
  bool upright = false, rim_down = false;
  for (const auto& f : faces) {
    upright |= f.normal_O.z() < -0.99;  // base facet's outward normal points down
    rim_down |= f.normal_O.z() > 0.99;
  }
  EXPECT_TRUE(upright);
  EXPECT_TRUE(rim_down);
}

// ------------------------------------------------------------------ the search
TEST(Search, MarkerReleasedOnItsEnds) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh marker = loadMesh(test::sharedData() + "/objects/marker_ycb040_1k.ply");
  const Mesh table = loadMesh(test::sharedData() + "/areas/table.ply");
  const Eigen::Vector3d ext = marker.properties.bounds_max - marker.properties.bounds_min;
  ASSERT_NEAR(ext.maxCoeff(), 0.12, 0.02) << "a 12 cm marker";
  PlannerConfig cfg;
  cfg.orientation = OrientationMode::kKeep;
  int standing_ends = 0, lying_ends = 0;
  // Released standing on each end: k1 (its long axis) along gravity.
  for (double s : {1.0, -1.0}) {
    cfg.start_orientation = Eigen::Quaterniond::FromTwoVectors(s * marker.properties.k1(), Eigen::Vector3d::UnitZ());
    const PlanResult r = Planner().plan(marker, table, cfg);
    EXPECT_GT(r.stats.tree_nodes, r.stats.floor_points_total) << "end " << s;
    bool stands = false, lies = false;
    for (const auto& c : r.candidates) {
      if (!c.stable) continue;
      const Eigen::Vector3d k1 = c.X_WO.linear() * marker.properties.k1();
      stands |= std::abs(k1.z()) > 0.9;
      lies |= std::abs(k1.z()) < 0.2;
      // Whatever is claimed stable rests on the table and held every perturbed release.
      EXPECT_NEAR(minZ(marker, c), 0.0, 0.003);
      EXPECT_EQ(c.robustness.held, c.robustness.trials);
      EXPECT_GE(c.robustness.min_tipping_angle, 3 * M_PI / 180);
    }
    standing_ends += stands;
    // On its conical tip it cannot stand: it tips over until it lies and rolls to the bottom of
    // its roll. (Whether that facet is claimed stable depends on its crests: the ones it reaches
    // from the tip rise too little to hold every tilted release; MarkerLiesStableWithDefaults
    // finds the facets that do.)
    if (!stands) {
      ASSERT_FALSE(r.candidates.empty());
      const Candidate& best = r.candidates.front();
      EXPECT_LT(std::abs((best.X_WO.linear() * marker.properties.k1()).z()), 0.2) << "the best pose lies";
      EXPECT_NEAR(minZ(marker, best), 0.0, 0.003);
      EXPECT_GT(r.stats.roll_bottoms, 0) << "it came to rest by rolling";
      lies = true;
    }
    lying_ends += lies;
  }
  // It stands on its flat cap, not on its conical tip, and ends lying from the tip.
  EXPECT_EQ(standing_ends, 1);
  EXPECT_GE(lying_ends, 1);
}

// A rod on its side rolls until its centre of mass is lowest and holds there: an elliptic rod
// released rolled 40 degrees off comes to rest on its flat side (its short axis vertical).
TEST(Search, EllipticRodRollsToItsFlatSide) {
  const Mesh rod = scenes::ellipticCylinder(0.016, 0.012, 0.10, 192);
  PlannerConfig cfg;
  cfg.orientation = OrientationMode::kKeep;
  cfg.floor_point_spacing = 0.3;
  // Lying along y of G (frame z -> -y, frame y -> z: at rest), then rolled 40 degrees off.
  cfg.start_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(40 * M_PI / 180, Eigen::Vector3d::UnitY())) *
                          Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  const PlanResult r = Planner().plan(rod, scenes::table(), cfg);
  EXPECT_GT(r.stats.roll_bottoms, 0) << "no tree came to rest by rolling";
  ASSERT_GT(r.stableCount(), 0) << "the rod never held on its flat side";
  for (const auto& c : r.candidates) {
    if (!c.stable) continue;
    EXPECT_GT(std::abs((c.X_WO.linear() * Eigen::Vector3d::UnitY()).z()), std::cos(2 * M_PI / 180))
        << "not on its flat side";
    EXPECT_NEAR(minZ(rod, c), 0.0, 0.002);
    EXPECT_EQ(c.robustness.held, c.robustness.trials);
  }
  // A round rod has no bottom: it never holds on its side.
  const PlanResult round = Planner().plan(scenes::cylinder(0.014, 0.10, 96), scenes::table(), cfg);
  EXPECT_GT(round.stats.tree_nodes, 0);
  for (const auto& c : round.candidates)
    if (c.stable) EXPECT_GT(std::abs((c.X_WO.linear() * Eigen::Vector3d::UnitZ()).z()), 0.99) << "a round rod held on its side";
}

// The mug released upright along two lines across books_stack (three scanned boxes stacked
// with offsets): where it is released over an edge it tips over it and falls, and its tree
// ends there (TreeContext::fall_tip) instead of walking down the scan's edge facet by facet.
// The cut saves work and keeps nearly every resting pose the walk finds (measured: 46 of 48;
// the walk's two more are the mug lying on its side at the bottom of a roll below an edge).
TEST(Search, MugOverTheEdgesOfBooksIsCutWhileFalling) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh books = loadMesh(test::sharedData() + "/areas/books_stack.ply");
  const TreeScene scene(mug, books, 0.0015, 0.00225, 0.2);
  struct Run {
    long nodes = 0;
    int fell = 0, stable = 0;
    std::vector<TreeLeaf> leaves;
  };
  auto run = [&](double fall_tip) {
    Run out;
    TreeContext ctx = scene.ctx;
    ctx.tree_nodes = &out.nodes;
    ctx.fall_tip = fall_tip;
    TreeStepper stepper(ctx);
    int root = 0;
    for (double y : {-0.1, 0.0, 0.1})
      for (double x = -0.28; x <= 0.28; x += 0.02, ++root) {
        Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
        X.translation() = Eigen::Vector3d(x, y, 0.3);
        stepper.addRoot(toRigid(X), root, scene.om.com, v3(0, 0, -1), 0.5);
      }
    for (int i = 0; i < 500 && !stepper.empty(); ++i) stepper.step(out.leaves);
    EXPECT_TRUE(stepper.empty());
    for (const TreeLeaf& l : out.leaves) {
      out.fell += l.fell;
      out.stable += l.stable;
      if (l.fell) EXPECT_FALSE(l.stable);
    }
    return out;
  };
  const Run cut = run(35 * M_PI / 180), walked = run(0.0);
  EXPECT_GT(cut.fell, 0) << "no tree was cut while falling";
  EXPECT_EQ(walked.fell, 0);
  EXPECT_LT(cut.nodes, 0.85 * walked.nodes) << "the cut saved little work";
  EXPECT_GT(cut.stable, 0);
  EXPECT_GE(cut.stable, 0.9 * walked.stable);
}

TEST(Search, MugOnTableWithDefaultsStandsOnItsBase) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh table = loadMesh(test::sharedData() + "/areas/table.ply");
  const PlanResult r = Planner().plan(mug, table, PlannerConfig());
  ASSERT_FALSE(r.candidates.empty());
  const Candidate& best = r.candidates.front();
  ASSERT_TRUE(best.stable);
  EXPECT_GE(best.quality, 0.9);
  // The held orientation (identity: the mug upright in its frame) breaks the tie of the two
  // flat faces: upright first.
  const Eigen::Vector3d axis = best.X_WO.linear() * Eigen::Vector3d::UnitZ();
  EXPECT_GT(axis.z(), 0.99) << "best is not upright";
  EXPECT_NEAR(minZ(mug, best), 0.0, 0.003);
  EXPECT_GT(best.robustness.trials, 0);
  // Held upside down, the least re-orientation puts it rim down.
  PlannerConfig cfg;
  cfg.start_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  const PlanResult flipped = Planner().plan(mug, table, cfg);
  ASSERT_FALSE(flipped.candidates.empty());
  ASSERT_TRUE(flipped.candidates.front().stable);
  EXPECT_LT((flipped.candidates.front().X_WO.linear() * Eigen::Vector3d::UnitZ()).z(), -0.99);
}

// The scanned marker (a 12-gon-like hull, crests 0.1-0.2 mm high either way of a facet) on the
// three flat areas (table, books_stack, bin), default options: the best candidate lies on its side, stable and
// robust (it once got no stable candidate at all: a roll bottom needed 0.5 mm crests).
TEST(Search, MarkerLiesStableWithDefaults) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh marker = loadMesh(test::sharedData() + "/objects/marker_ycb040_1k.ply");
  for (const char* area : {"table", "books_stack", "bin"}) {
    const Mesh a = loadMesh(test::sharedData() + "/areas/" + area + ".ply");
    const PlanResult r = Planner().plan(marker, a, PlannerConfig());
    ASSERT_FALSE(r.candidates.empty()) << area;
    const Candidate& best = r.candidates.front();
    EXPECT_TRUE(best.stable) << area;
    EXPECT_GE(r.stableCount(), 3) << area;
    EXPECT_LT(std::abs((best.X_WO.linear() * marker.properties.k1()).z()), 0.2) << area << ": not lying";
    EXPECT_EQ(best.robustness.held, best.robustness.trials) << area;
    EXPECT_GT(best.robustness.trials, 0) << area;
    EXPECT_GT(r.stats.roll_bottoms, 0) << area << ": it came to rest by rolling";
  }
}

TEST(Search, BallHasNoStableCandidate) {
  const Mesh ball = icosphere(0.04, 3);
  PlannerConfig cfg;
  cfg.floor_point_spacing = 0.2;
  const PlanResult r = Planner().plan(ball, scenes::table(), cfg);
  EXPECT_GT(r.stats.tree_nodes, 10);
  ASSERT_FALSE(r.candidates.empty()) << "no leaf reached";
  EXPECT_EQ(r.stableCount(), 0);
  EXPECT_EQ(r.outcome(), PlanOutcome::kNoStable);
}

TEST(Search, ApproachAgainstGravityFindsNothingBelowTheTable) {
  const Mesh cube = scenes::box(0.05, 0.05, 0.05);
  const Mesh table = scenes::table();
  PlannerConfig cfg;
  cfg.approach = Eigen::Vector3d(0, 0, 1);
  cfg.floor_point_spacing = 0.2;
  cfg.robust_check = false;  // stability against gravity alone must decide
  const PlanResult r = Planner().plan(cube, table, cfg);
  EXPECT_GT(r.stats.tree_nodes, 0);
  const double top = table.properties.bounds_max.z();
  ASSERT_FALSE(r.candidates.empty()) << "no tree reached a leaf: the test would pass on nothing";
  int below = 0;
  for (const auto& c : r.candidates) {
    below += (c.X_WO * cube.properties.center_of_mass).z() < top;
    if (c.stable) EXPECT_GT((c.X_WO * cube.properties.center_of_mass).z(), top) << "stable under the table";
  }
  EXPECT_GT(below, 0) << "the trees did reach the underside";
  // The same scene approached from above has stable poses: the check can tell them apart.
  cfg.approach = Eigen::Vector3d::Zero();
  EXPECT_GT(Planner().plan(cube, table, cfg).stableCount(), 0);
}

// ------------------------------------------------------------------ robust stability
// A 6 x 6 x 3 cm box on a 1 cm wide wall top, its centre of mass 2 mm inside the wall's edge.
TEST(Robustness, BoxNearTheEdgeOfAWallTop) {
  const Mesh box = scenes::box(0.06, 0.06, 0.03);  // centred on its origin
  const Mesh wall = scenes::box(0.01, 0.3, 0.1, {0, 0, -0.05});  // top at z = 0, x in +-5 mm
  const TreeScene scene(box, wall, 0.0005, 0.00075, 0.5);
  const TreeContext& ctx = scene.ctx;
  // Centre of mass at x = 3 mm: 2 mm inside the wall's edge at x = 5 mm; resting on the top.
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(0.003, 0, 0.015);
  const Rigid X_GO = toRigid(X);
  RobustnessParams p;
  p.shift = 0;
  p.tilt = 0;
  p.com_offset = 0;
  p.min_share = 0;  // settle every trial (no early decision) to count them
  const Robustness exact = checkRobustness({X_GO}, ctx, p).front();
  EXPECT_EQ(exact.trials, 12);
  EXPECT_EQ(exact.held, 12) << "stable at delta = 0";
  p.shift = 0.003;
  const Robustness shifted = checkRobustness({X_GO}, ctx, p).front();
  EXPECT_LT(shifted.held, 12) << "a 3 mm shift over the edge must fall";
  // The shifts along the wall (y) and away from the edge (-x) hold.
  EXPECT_GE(shifted.held, 11);
  // Decided early (every trial must hold): the first failure ends the pose's other trials.
  p.min_share = 1;
  EXPECT_LT(checkRobustness({X_GO}, ctx, p).front().held, 12);
}

// A board leaning on a wall at 35 degrees from vertical slips at mu 0.2 (a ladder needs 67
// degrees from the floor): its foot kicks out. The tree slides it away from the wall (Section
// VI's slide), not tipping it over; with a low stop behind the foot it ends leaning, its foot
// against the stop, its top on the wall (as a plate's foot meets a rack's peg row).
TEST(Search, LeaningBoardSlidesToTheStopBehindItsFoot) {
  const Mesh rod = scenes::box(0.02, 0.12, 0.25);
  TreeScene scene(rod, wallAndStop(), 0.0015, 0.00225, 0.2);
  scene.ctx.rock_settle = true;  // the planner's default
  const std::vector<TreeLeaf> leaves = settle(scene.ctx, leaningOnTheWall(rod), scene.om.com, 0.1);
  ASSERT_EQ(leaves.size(), 1u);
  const TreeLeaf& l = leaves.front();
  ASSERT_TRUE(l.stable) << "the board did not come to rest against the stop";
  expectAgainstTheStop(rod, l.X_GO);
}

// The same with a rod 1 cm wide: its contacts at the foot and on the wall lie within a tenth
// of their length of one steep line, but neither turn about that line lowers the rod without
// pushing a corner into the floor or the wall. That is no hinge: the rod is judged as resting
// there, and slides to the stop (the tree turned it about the line before, found both turns
// blocked and ended, not stable).
TEST(Search, LeaningRodOnANarrowFootIsNoHinge) {
  const Mesh rod = scenes::box(0.01, 0.01, 0.25);
  TreeScene scene(rod, wallAndStop(), 0.0015, 0.00225, 0.2);
  scene.ctx.rock_settle = true;  // the planner's default
  const std::vector<TreeLeaf> leaves = settle(scene.ctx, leaningOnTheWall(rod), scene.om.com, 0.1);
  const TreeLeaf* rest = nullptr;
  for (const TreeLeaf& l : leaves)
    if (l.stable && !rest) rest = &l;
  ASSERT_NE(rest, nullptr) << "the rod did not come to rest between the wall and the stop";
  expectAgainstTheStop(rod, rest->X_GO);
}

// A ring (torus, axis along y) dropped over a horizontal square peg with its centre 1 cm to
// the side: it lands on the peg's near corner, swings about it (the exact rotation to where its
// centre of mass is lowest, or to the next contact) and hangs with its centre of mass straight
// below the peg, held by the contact forces (beyond the paper, which cannot hang objects).
TEST(Search, RingSwingsToHangBelowAPeg) {
  const double R = 0.03, r = 0.004;
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  const int nu = 48, nv = 12;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, w = 2 * M_PI * j / nv;
      v.emplace_back((R + r * std::cos(w)) * std::cos(u), r * std::sin(w), (R + r * std::cos(w)) * std::sin(u));
    }
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const int a = i * nv + j, b = ((i + 1) % nu) * nv + j, c = ((i + 1) % nu) * nv + (j + 1) % nv,
                d = i * nv + (j + 1) % nv;
      f.push_back({a, d, c, b});
    }
  const Mesh torus = buildMesh(v, f, "ring");
  Mesh peg = scenes::box(0.008, 0.12, 0.008, {0, 0, 0.2});  // top at z = 0.204
  TreeScene scene(torus, peg, 0.0008, 0.0012, 0.2);
  scene.ctx.rock_settle = true;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(0.01, 0, 0.208 - (R - r));  // inner top 4 mm over the peg
  const std::vector<TreeLeaf> leaves = settle(scene.ctx, X, scene.om.com, 0.05);
  ASSERT_EQ(leaves.size(), 1u);
  const TreeLeaf& l = leaves.front();
  const Eigen::Vector3d com = toEigen(apply(l.X_GO, scene.om.com));
  ASSERT_TRUE(l.stable) << "the ring does not hang on the peg";
  EXPECT_LE(std::abs(com.x()), 0.005) << "its centre of mass is not below the peg";
  EXPECT_LT(com.z(), 0.2 - 0.02) << "not hanging";
  for (const ContactPoint& c : l.contacts) EXPECT_GT(c.p_W.z(), 0.195) << "a contact below the peg's top";
  // Without the peg's top under it (the ring released beside the peg) nothing holds it.
  X.translation().x() = 0.05;
  for (const TreeLeaf& b : settle(scene.ctx, X, scene.om.com, 0.05)) EXPECT_FALSE(b.stable);
}

// Rock settle (TreeContext::rock_settle, PlannerConfig::rock_settle): the mug standing on the
// dish rack's domed peg tops, released tilted 3 degrees, lands propped on pegs a millimetre away
// (within the contact tolerance) and the static test holds it there, 3 degrees off: without the
// rock the tilted trials fail and the pose is not robust. Rocked about its centre of mass it
// finds lower and comes back upright, so every trial holds.
TEST(Robustness, MugTiltedOnPegTopsRocksBackUpright) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh rack = loadMesh(test::sharedData() + "/areas/dish_rack.ply");
  TreeScene scene(mug, rack, 0.0014, 0.0021, 0.2);  // the planner's radii for the mug
  TreeContext& ctx = scene.ctx;
  const ObjectModel& om = scene.om;
  auto release = [&](bool rock, double tilt_deg) {
    ctx.rock_settle = rock;
    TreeStepper stepper(ctx);
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = Eigen::AngleAxisd(tilt_deg * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
    X.translation() = Eigen::Vector3d(-0.207, -0.242, 0.2);  // upright over a corner's peg tops
    stepper.addRoot(toRigid(X), 0, om.com, v3(0, 0, -1), 0.3);
    std::vector<TreeLeaf> leaves;
    for (int i = 0; i < 100 && !stepper.empty(); ++i) stepper.step(leaves);
    EXPECT_EQ(leaves.size(), 1u);
    return leaves.empty() ? TreeLeaf{} : leaves.front();
  };
  auto tilt = [](const TreeLeaf& l) {
    return std::acos(std::clamp(rotate(l.X_GO, v3(0, 0, 1)).z, -1.0, 1.0)) * 180 / M_PI;
  };
  const TreeLeaf upright = release(true, 0);
  ASSERT_TRUE(upright.stable) << "the mug does not stand on the peg tops";
  EXPECT_GT(toEigen(apply(upright.X_GO, om.com)).z(), 0.1) << "not on the peg tops";
  EXPECT_LT(tilt(upright), 1.0);
  // Released 3 degrees off: propped where it landed without the rock, back upright with it.
  // Without the rock it is not held upright: held propped where it landed, or not held at all
  // (the contact forces see that its blended normals on the domes do not carry it there).
  const TreeLeaf propped = release(false, 3), rocked = release(true, 3);
  EXPECT_TRUE(!propped.stable || tilt(propped) > 2.5) << "held upright without the rock";
  ASSERT_TRUE(rocked.stable);
  EXPECT_LT(tilt(rocked), 1.5);
  // So the pose is robust with the rock, and its tilted trials fail without it.
  RobustnessParams p;
  p.min_share = 0;  // settle every trial, to count them
  ctx.rock_settle = false;
  const Robustness strict = checkRobustness({upright.X_GO}, ctx, p).front();
  ctx.rock_settle = true;
  const Robustness settled = checkRobustness({upright.X_GO}, ctx, p).front();
  EXPECT_LT(strict.held, 12);
  EXPECT_EQ(settled.held, 12);
}

// On a flat table a rock about the centre of mass only lifts a pose: rock settle (on by default)
// skips such supports and leaves every candidate where the static test put it.
TEST(Robustness, RockSettleLeavesFlatTablePosesAlone) {
  for (const char* name : {"cube", "mug"}) {
    const Mesh object = scenes::byName(name);
    PlannerConfig cfg;
    cfg.floor_point_spacing = 0.2;
    ASSERT_TRUE(cfg.rock_settle) << "on by default";
    const PlanResult rocked = Planner().plan(object, scenes::table(), cfg);
    cfg.rock_settle = false;
    const PlanResult still = Planner().plan(object, scenes::table(), cfg);
    ASSERT_GT(rocked.stableCount(), 0) << name;
    ASSERT_EQ(rocked.candidates.size(), still.candidates.size()) << name;
    for (size_t i = 0; i < rocked.candidates.size(); ++i) {
      EXPECT_EQ(rocked.candidates[i].stable, still.candidates[i].stable) << name << " " << i;
      EXPECT_LT((rocked.candidates[i].X_WO.translation() - still.candidates[i].X_WO.translation()).norm(), 1e-9)
          << name << " " << i;
    }
  }
}

TEST(Stability, WedgeNeedsSqueezeAndIsNotStable) {
  // A body held only by two vertical walls (normals +-x), nothing below: gravity needs
  // friction forces that come only from squeeze (at least weight / mu in total).
  const std::vector<ContactPoint> wedge = {{{-0.02, 0, 0}, {1, 0, 0}}, {{0.02, 0, 0}, {-1, 0, 0}},
                                           {{-0.02, 0.01, 0}, {1, 0, 0}}, {{0.02, 0.01, 0}, {-1, 0, 0}}};
  const Eigen::Vector3d com(0, 0.005, 0);
  EXPECT_FALSE(equilibrium(wedge, com, Eigen::Vector3d(0, 0, -1), 0.2));
  // With unbounded squeeze the same contacts balance gravity: the bound is what rejects it.
  EXPECT_TRUE(equilibrium(wedge, com, Eigen::Vector3d(0, 0, -1), 0.2, 1e6));
  // A floor loads its contacts with the weight alone.
  const std::vector<ContactPoint> floor = {{{-0.02, -0.02, 0}, {0, 0, 1}}, {{0.02, -0.02, 0}, {0, 0, 1}},
                                           {{0, 0.02, 0}, {0, 0, 1}}};
  EXPECT_TRUE(equilibrium(floor, Eigen::Vector3d(0, 0, 0.01), Eigen::Vector3d(0, 0, -1), 0.2));
}

// A line of contacts along a round body's side on a slope (the line level, across the fall
// line): steeper than the friction angle it slides down the slope before any turn; on a slope
// friction holds, the tree turns it about the line as before (no slide).
TEST(Stability, ALineOnASlopeSteeperThanFrictionSlidesDownIt) {
  auto lineOn = [](double slope_deg) {
    const double a = slope_deg * M_PI / 180;
    const Eigen::Vector3d n(0, -std::sin(a), std::cos(a));  // rising towards +y
    std::vector<ContactPoint> c;
    for (double x = -0.05; x <= 0.05 + 1e-9; x += 0.01) c.push_back({{x, 0, 0}, n, n});
    return std::make_pair(c, Eigen::Vector3d(Eigen::Vector3d(0, 0, 0) + 0.03 * n));
  };
  const auto [steep, com_steep] = lineOn(35);
  const Stability s = evaluateStability(steep, com_steep, StabilityParams{});
  EXPECT_FALSE(s.stable);
  EXPECT_TRUE(s.slips);
  EXPECT_EQ(s.failure, Failure::kSlide);
  // Down the slope, in its plane: towards -y and down, at right angles to the normal.
  EXPECT_LT(s.d_f.y(), -0.5);
  EXPECT_LT(s.d_f.z(), -0.5);
  EXPECT_NEAR(s.d_f.dot(s.plane_normal), 0.0, 1e-9);
  const auto [gentle, com_gentle] = lineOn(5);  // atan 0.2 = 11.3 degrees
  const Stability g = evaluateStability(gentle, com_gentle, StabilityParams{});
  EXPECT_FALSE(g.stable);
  EXPECT_FALSE(g.slips);
  // Two slopes facing each other (a trough) hold by friction and wedging: no slide down either.
  auto both = steep;
  for (const auto& p : steep) both.push_back({{p.p_W.x(), -0.05, 0}, {0, -p.n_W.y(), p.n_W.z()}, {0, -p.n_W.y(), p.n_W.z()}});
  EXPECT_FALSE(evaluateStability(both, Eigen::Vector3d(0, -0.025, 0.03), StabilityParams{}).slips);
}

TEST(Stability, ContactsFromAboveNeverHold) {
  // The cube under a table top: contacts on its top face, normals pointing down at it.
  std::vector<ContactPoint> c;
  for (double x : {-0.02, 0.02})
    for (double y : {-0.02, 0.02}) c.push_back({{x, y, 0.05}, {0, 0, -1}});
  const Stability s = evaluateStability(c, Eigen::Vector3d(0, 0, 0.025), StabilityParams{});
  EXPECT_FALSE(s.stable);
  for (auto& p : c) p.n_W = Eigen::Vector3d(0, 0, 1);  // the same contacts from below hold
  EXPECT_TRUE(evaluateStability(c, Eigen::Vector3d(0, 0, 0.075), StabilityParams{}).stable);
}

// The caught rule (RobustnessParams::recheck_caught, on in the planner's defaults) must not
// let a tilted release on a flat table count as caught: there the board comes back flat,
// 12 / 12 either way, and the rule's end-pose recheck is never needed.
TEST(Robustness, CaughtRuleKeepsFlatTableStrict) {
  const Mesh board = scenes::box(0.10, 0.10, 0.01);
  const Mesh table = scenes::box(0.5, 0.5, 0.02, {0, 0, -0.01});
  const TreeScene scene(board, table, 0.0005, 0.00075, 0.5);
  const TreeContext& ctx = scene.ctx;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(0, 0, 0.005);
  RobustnessParams p;
  p.min_share = 0;  // settle every trial
  EXPECT_EQ(checkRobustness({toRigid(X)}, ctx, p).front().held, 12);
  p.recheck_caught = true;
  EXPECT_EQ(checkRobustness({toRigid(X)}, ctx, p).front().held, 12);
}
