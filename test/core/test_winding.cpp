// Winding each piece of the area outwards (model/winding.h).
#include <algorithm>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/model/mesh.h"
#include "place_planner/model/winding.h"
#include "place_planner/planner.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {

// The same surface with every polygon's winding reversed (its normals turned inwards).
Mesh reversed(const Mesh& m) {
  std::vector<std::vector<int>> polygons = m.patches;
  for (auto& p : polygons) std::reverse(p.begin(), p.end());
  return buildMesh(m.vertices, polygons, "reversed");
}

// Share of the surface (by area) whose triangles' normals point along dir(triangle centroid).
template <class Dir>
double share(const Mesh& m, Dir dir) {
  double along = 0, all = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
    const Eigen::Vector3d n2 = (b - a).cross(c - a);
    all += n2.norm();
    if (n2.dot(dir((a + b + c) / 3)) > 0) along += n2.norm();
  }
  return along / all;
}
double outwardShare(const Mesh& m) {
  return share(m, [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(p - m.properties.center_of_mass); });
}
double shareFacing(const Mesh& m, const Eigen::Vector3d& d) {
  return share(m, [&](const Eigen::Vector3d&) { return d; });
}

const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

}  // namespace

TEST(Winding, AClosedMeshWoundInwardsIsTurned) {
  const Mesh box = scenes::box(0.1, 0.2, 0.05);
  ASSERT_NEAR(outwardShare(box), 1.0, 1e-12);
  EXPECT_FALSE(woundInwards(box, kUp));
  const Mesh inwards = reversed(box);
  ASSERT_NEAR(outwardShare(inwards), 0.0, 1e-12);
  EXPECT_TRUE(woundInwards(inwards, kUp));
  // A closed mesh is judged by its volume, whatever way gravity points, or with none.
  EXPECT_TRUE(woundInwards(inwards, -kUp));
  EXPECT_TRUE(woundInwards(inwards, Eigen::Vector3d::Zero()));
  const Mesh out = reversedWinding(inwards);
  EXPECT_NEAR(outwardShare(out), 1.0, 1e-12);
  // Its patches with it: each patch normal points out of the box again.
  for (size_t k = 0; k < out.patches.size(); ++k) {
    const Eigen::Vector3d c = out.vertices[out.patches[k][0]];
    EXPECT_GT(out.patch_normals[k].dot(c - out.properties.center_of_mass), 0.0) << "patch " << k;
  }
}

// A cavity inside a solid (a closed piece wound inwards, as a signed-distance reconstruction
// leaves them) is no mesh wound inwards: the whole is judged.
TEST(Winding, ACavityKeepsItsInwardWinding) {
  const Mesh outer = scenes::box(0.2, 0.2, 0.2), inner = reversed(scenes::box(0.05, 0.05, 0.05));
  std::vector<Eigen::Vector3d> v = outer.vertices;
  std::vector<std::vector<int>> polygons = outer.patches;
  for (const auto& p : inner.patches) {
    std::vector<int> q;
    for (int i : p) q.push_back(i + static_cast<int>(outer.vertices.size()));
    polygons.push_back(q);
  }
  v.insert(v.end(), inner.vertices.begin(), inner.vertices.end());
  const Mesh solid = buildMesh(v, polygons, "solid with a cavity");
  EXPECT_FALSE(woundInwards(solid, kUp));
  EXPECT_TRUE(woundInwards(reversed(solid), kUp));
}

TEST(Winding, AnOpenSheetFacesUpAndAWallIsNotJudged) {
  const Mesh floor = scenes::plane(0.4, 0.3);  // faces +z
  ASSERT_NEAR(shareFacing(floor, kUp), 1.0, 1e-12);
  EXPECT_FALSE(woundInwards(floor, kUp));
  EXPECT_TRUE(woundInwards(reversed(floor), kUp));
  EXPECT_FALSE(woundInwards(reversed(floor), Eigen::Vector3d::Zero()));  // no up: not judged
  // A wall (tilted 90 degrees): it faces neither up nor down; either side may be the seen one.
  EXPECT_FALSE(woundInwards(scenes::plane(0.4, 0.3, 90.0), kUp));
  EXPECT_FALSE(woundInwards(reversed(scenes::plane(0.4, 0.3, 90.0)), kUp));
}

// The shared rack wound inwards plans as the rack does: the same stable poses (the reversed
// polygons are fanned from another corner, so ties among them may rank in another order).
// Wound inwards and planned as given, the YCB mug had no stable pose on it, against four.
TEST(PlannerShared, AnAreaWoundInwardsPlansAsWoundOutwards) {
  PP_REQUIRE_SHARED_DATA();
  const Mesh mug = loadMesh(test::sharedData() + "/objects/mug_ycb025_1k.ply");
  const Mesh rack = loadMesh(test::sharedData() + "/areas/dish_rack.ply");
  PlannerConfig cfg;
  const PlanResult out = Planner().plan(mug, rack, cfg);
  const PlanResult in = Planner().plan(mug, reversed(rack), cfg);
  ASSERT_GT(out.stableCount(), 0);
  // Said in a warning, the answer's only change.
  auto saysWound = [](const PlanResult& r) {
    return std::any_of(r.warnings.begin(), r.warnings.end(),
                       [](const std::string& w) { return w.find("wound inwards") != std::string::npos; });
  };
  EXPECT_TRUE(saysWound(in));
  EXPECT_FALSE(saysWound(out));
  EXPECT_EQ(in.stableCount(), out.stableCount());
  for (const Candidate& c : in.candidates) {
    if (!c.stable) continue;
    bool found = false;
    for (const Candidate& d : out.candidates)
      found = found || (d.stable && (c.X_WO.translation() - d.X_WO.translation()).norm() < 0.002 &&
                        Eigen::AngleAxisd(c.X_WO.linear().transpose() * d.X_WO.linear()).angle() < 2 * M_PI / 180);
    EXPECT_TRUE(found) << "a stable pose at " << c.X_WO.translation().transpose() << " that the rack wound outwards lacks";
  }
}

// A closed object wound inwards is wound outwards: the built-in mug with a loop hangs on the
// built-in mug rack (wound inwards and planned as given: no stable pose on any rack).
TEST(Winding, AnObjectWoundInwardsHangsAsWoundOutwards) {
  PlannerConfig cfg;
  cfg.threads = 2;
  cfg.max_candidates = 3;
  const Mesh mug = scenes::loopMug(), rack = scenes::mugRack();
  const PlanResult out = Planner().plan(mug, rack, cfg);
  const PlanResult in = Planner().plan(reversed(mug), rack, cfg);
  ASSERT_GT(out.stableCount(), 0);
  ASSERT_TRUE(out.candidates.front().hanging);
  // (Reversed polygons are fanned across their other diagonal, so the sphere models differ and
  // the poses need not be the same ones.)
  ASSERT_GT(in.stableCount(), 0);
  EXPECT_TRUE(in.candidates.front().hanging);
  EXPECT_TRUE(std::any_of(in.warnings.begin(), in.warnings.end(),
                          [](const std::string& w) { return w.find("object mesh: wound inwards") == 0; }));
}
