// The kernels' culling (BVHs walked together, the height grid over the object's sphere BVH)
// must not change a result: each kernel against the same computation over every pair.
#include <algorithm>
#include <cmath>

#include "place_planner/infra/backend.h"
#include "place_planner/infra/scenes.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {

struct Fixture {
  ObjectModel om = buildObjectModel(scenes::mug(), 0.0015);
  AreaModel am = buildAreaModel(scenes::dishRack(), {0, 0, -1}, 0.00225, 0.00375, 0.00375);
  ObjectView o = view(om);
  AreaView a = view(am);
};

// Poses of the mug low over the pegs (some touching, some penetrating, some clear).
std::vector<Rigid> poses(const Fixture& f) {
  std::vector<Rigid> out;
  const V3 c = 0.5 * (f.am.bounds.lo + f.am.bounds.hi);
  for (int i = 0; i < 24; ++i) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = Eigen::AngleAxisd(0.37 * i, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    X.translation() = Eigen::Vector3d(c.x - 0.12 + 0.011 * i, c.y - 0.05 + 0.004 * i,
                                      f.am.bounds.hi.z + 0.01 - 0.004 * (i % 7));
    out.push_back(toRigid(X));
  }
  return out;
}

}  // namespace

TEST(Kernels, FirstContactDistanceMatchesAllPairs) {
  Fixture f;
  const V3 d = v3(0, 0, -1);
  const double tmax = 0.5;
  for (const Rigid& X : poses(f)) {
    double best = tmax;
    const auto& om = f.om;
    const auto& am = f.am;
    for (const V3& v0 : om.vertices)
      for (const auto& t : am.triangles)
        best = std::min(best, rayTriangle(apply(X, v0), d, am.vertices[t[0]], am.vertices[t[1]],
                                          am.vertices[t[2]]));
    for (const V3& w : am.vertices)
      for (const auto& t : om.triangles)
        best = std::min(best, rayTriangle(applyInv(X, w), -rotateInv(X, d), om.vertices[t[0]],
                                          om.vertices[t[1]], om.vertices[t[2]]));
    for (const auto& e : om.edges)
      for (const auto& g : am.edges)
        best = std::min(best, edgeEdgeTranslation(apply(X, om.vertices[e[0]]), apply(X, om.vertices[e[1]]),
                                                  am.vertices[g[0]], am.vertices[g[1]], d));
    const double expected = best < tmax ? best : kInf;
    const double got = firstContactDistance(f.o, f.a, X, d, tmax);
    if (expected >= kInf) {
      EXPECT_GE(got, kInf);
    } else {
      EXPECT_NEAR(got, expected, 1e-12);
    }
  }
}

TEST(Kernels, EdgeEdgeAngleMatchesAllPairs) {
  Fixture f;
  const TiltParams tp{0.002, 1e-6};
  const double max_angle = angleWindowEnd(kNumAngleWindows - 1);
  int found = 0;
  for (const Rigid& X : poses(f)) {
    // Axis through the mug's lowest vertex, horizontal.
    V3 low = apply(X, f.om.vertices[0]);
    for (const V3& v : f.om.vertices)
      if (apply(X, v).z < low.z) low = apply(X, v);
    const V3 s_A = low, d_A = normalized(v3(1, 0.3, 0));
    const AxisFrame frame = axisFrame(s_A, d_A);
    for (int sigma : {1, -1}) {
      double best = kInf;
      for (const auto& e : f.om.edges)
        for (const auto& g : f.am.edges) {
          double out[4];
          const int m = edgeEdgeAnglesAxis(toAxis(frame, apply(X, f.om.vertices[e[0]])),
                                           toAxis(frame, apply(X, f.om.vertices[e[1]])),
                                           toAxis(frame, f.am.vertices[g[0]]),
                                           toAxis(frame, f.am.vertices[g[1]]), out);
          for (int q = 0; q < m; ++q) {
            const double th = directed(out[q], sigma);
            if (th > tp.min_angle && th <= max_angle) best = std::min(best, th);
          }
        }
      const double got = edgeEdgeAngle(f.o, f.a, X, s_A, d_A, sigma, tp);
      if (best >= kInf) {
        EXPECT_GE(got, kInf);
      } else {
        ++found;
        EXPECT_NEAR(got, best, 1e-12);
      }
    }
  }
  EXPECT_GT(found, 5);  // the poses do meet pegs
}

TEST(Kernels, ContactCullingKeepsEveryContact) {
  Fixture f;
  auto cpu = makeCpuBackend(f.om, f.am, TiltParams{0.002, 1e-6}, 2);
  const std::vector<Rigid> X = poses(f);
  std::vector<std::vector<SphereContact>> culled;
  cpu->contactPoints(X, culled);
  int touching = 0;
  for (size_t i = 0; i < X.size(); ++i) {
    std::vector<SphereContact> all;
    for (size_t s = 0; s < f.om.spheres.centres.size(); ++s) {
      const SphereContact c = sphereContact(f.a, apply(X[i], f.om.spheres.centres[s]),
                                            rotate(X[i], f.om.spheres.normals[s]), apply(X[i], f.o.com));
      if (c.valid) all.push_back(c);
    }
    auto key = [](const SphereContact& c) { return std::make_tuple(c.p.x, c.p.y, c.p.z, c.n.x, c.n.y, c.n.z); };
    auto byKey = [&](const SphereContact& a, const SphereContact& b) { return key(a) < key(b); };
    std::vector<SphereContact> got = culled[i];
    std::sort(all.begin(), all.end(), byKey);
    std::sort(got.begin(), got.end(), byKey);
    ASSERT_EQ(got.size(), all.size()) << "pose " << i;
    for (size_t k = 0; k < all.size(); ++k) EXPECT_TRUE(key(got[k]) == key(all[k])) << "pose " << i;
    touching += !all.empty();
  }
  EXPECT_GT(touching, 3);  // the poses do touch the rack
}

// The area's own normal at a contact weighs each face by how squarely it faces the object's
// surface: a mug's side (facing +y) touching a board's lower edge is pushed by the board's face
// (-y), not held up by its underside, which is at right angles to the side and, turned towards
// the centre of mass above it, would point up and read as a floor.
TEST(Kernels, AnObjectsSideOnABoardsLowerEdgeMeetsTheBoardsFace) {
  const AreaModel am = buildAreaModel(scenes::mugRack(), {0, 0, -1}, 0.00225, 0.00375, 0.00375);
  const AreaView a = view(am);
  // The board's face is y = 0, its lower edge z = 0.34 (the nearest peg 1 cm away in x, 6 cm
  // up); the side reaches 2 mm under the board, where the underside's spheres are in reach.
  const V3 s = v3(0.05, 0.002, 0.34), n_side = v3(0, 1, 0), com = v3(0.05, -0.04, 0.36);
  const SphereContact c = sphereContact(a, s, n_side, com);
  ASSERT_TRUE(c.valid);
  EXPECT_LT(c.na.y, -0.9);
  EXPECT_LT(std::abs(c.na.z), 0.3) << "the area's normal there leans " << c.na.z << " up: a floor, not a wall";
}

// A wall's normal keeps its side where the object faces it, wherever the centre of mass lies:
// a ring round a post 24 mm thick has its centre of mass inside the post, and the post pushes
// the ring out (sphereContact turns other normals towards the centre of mass). Above the
// contact or below it, the same.
TEST(Kernels, AWallFacingTheObjectPushesItOutEvenWithTheCentreOfMassBehindIt) {
  const AreaModel am = buildAreaModel(scenes::cylinder(0.012, 0.36, 16), {0, 0, -1}, 0.00225, 0.00375, 0.00375);
  const AreaView a = view(am);
  // The ring's inner face touching the post's vertical edge at -x, facing +x (at the post).
  const V3 s = v3(-0.0121, 0, 0.05), n_in = v3(1, 0, 0);
  for (const double com_z : {0.04, 0.06}) {
    const SphereContact inside = sphereContact(a, s, n_in, v3(0.002, 0, com_z));
    ASSERT_TRUE(inside.valid);
    EXPECT_LT(inside.n.x, -0.9) << "centre of mass inside the post, " << (com_z > 0.05 ? "above" : "below");
    const SphereContact outside = sphereContact(a, s, n_in, v3(-0.03, 0, com_z));
    ASSERT_TRUE(outside.valid);
    EXPECT_LT(outside.n.x, -0.9) << "centre of mass beside the post";
  }
}
