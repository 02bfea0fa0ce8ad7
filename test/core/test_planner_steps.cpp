// Each step of the planner on hand-checkable cases.
#include <algorithm>

#include "place_planner/model/area_up.h"
#include "place_planner/infra/backend.h"
#include "place_planner/search/contact_points.h"
#include "place_planner/search/floor_points.h"
#include "place_planner/kernels/batched_steps.h"
#include "place_planner/kernels/geometry.h"
#include "place_planner/planner.h"
#include "place_planner/search/pre_orientation.h"
#include "place_planner/search/start_orientations.h"
#include "place_planner/judgement/quality.h"
#include "place_planner/judgement/contact_forces.h"
#include "place_planner/judgement/stability.h"
#include "place_planner/judgement/penetration.h"
#include "place_planner/judgement/ranking.h"
#include "place_planner/model/scene.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/search/tilt_axis.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {
constexpr double kAngleTol = 1e-9;  // closed forms: exact up to rounding
double deg(double rad) { return rad * 180.0 / M_PI; }
}  // namespace

TEST(TiltAngle, VertexOntoPlaneMatchesClosedForm) {
  // v = (1, 0, 0) about +y through the origin onto the plane z = -0.5: z(theta) = -sin(theta).
  const V3 A = v3(-5, -5, -0.5), B = v3(5, -5, -0.5), C = v3(0, 5, -0.5);
  double out[2];
  const int n = vertexTriangleAngles(v3(1, 0, 0), v3(0, 0, 0), v3(0, 1, 0), A, B, C, 1e-9, out);
  ASSERT_EQ(n, 2);
  const double lo = std::min(out[0], out[1]), hi = std::max(out[0], out[1]);
  EXPECT_NEAR(lo, M_PI / 6, kAngleTol);      // asin(0.5)
  EXPECT_NEAR(hi, 5 * M_PI / 6, kAngleTol);  // the circle leaves the plane again
  // Outside the patch: a small triangle far away in x gives no angle.
  EXPECT_EQ(vertexTriangleAngles(v3(1, 0, 0), v3(0, 0, 0), v3(0, 1, 0), v3(3, -1, -0.5),
                                 v3(4, -1, -0.5), v3(3.5, 1, -0.5), 1e-9, out),
            0);
  // A plane the circle cannot reach.
  EXPECT_EQ(vertexTriangleAngles(v3(1, 0, 0), v3(0, 0, 0), v3(0, 1, 0), v3(-5, -5, -2),
                                 v3(5, -5, -2), v3(0, 5, -2), 1e-9, out),
            0);
}

TEST(TiltAngle, EdgeEdgeCylinder) {
  const V3 P0 = v3(1, 0, -1), P1 = v3(1, 0, 1);  // parallel to the axis: cylinder r = 1
  EXPECT_EQ(revolutionOf(P0, P1).kind, 1);
  double out[4];
  const int n = edgeEdgeAnglesAxis(P0, P1, v3(0.6, -2, 0), v3(0.6, 2, 0), out);
  ASSERT_EQ(n, 2);
  const double lo = std::min(out[0], out[1]), hi = std::max(out[0], out[1]);
  EXPECT_NEAR(lo, std::atan2(0.8, 0.6), kAngleTol);
  EXPECT_NEAR(hi, 2 * M_PI - std::atan2(0.8, 0.6), kAngleTol);
}

TEST(TiltAngle, EdgeEdgeCone) {
  const V3 P0 = v3(0, 0, 0), P1 = v3(1, 0, 1);  // meets the axis: cone r = z
  EXPECT_EQ(revolutionOf(P0, P1).kind, 2);
  double out[4];
  const int n = edgeEdgeAnglesAxis(P0, P1, v3(0, -2, 0.5), v3(0, 2, 0.5), out);
  ASSERT_EQ(n, 2);
  EXPECT_NEAR(std::min(out[0], out[1]), M_PI / 2, kAngleTol);
  EXPECT_NEAR(std::max(out[0], out[1]), 3 * M_PI / 2, kAngleTol);
}

TEST(TiltAngle, EdgeEdgeHyperboloid) {
  const V3 P0 = v3(1, -1, -1), P1 = v3(1, 1, 1);  // skew: r^2 = 1 + z^2
  EXPECT_EQ(revolutionOf(P0, P1).kind, 3);
  double out[4];
  const int n = edgeEdgeAnglesAxis(P0, P1, v3(-3, 0, 1), v3(3, 0, 1), out);
  ASSERT_EQ(n, 2);
  // From (1, 1) at z = 1 to (+-sqrt 2, 0): -45 and +135 degrees.
  EXPECT_NEAR(deg(std::min(out[0], out[1])), 135.0, 1e-7);
  EXPECT_NEAR(deg(std::max(out[0], out[1])), 315.0, 1e-7);
}

TEST(TiltAngle, EdgeEdgeAnnulus) {
  const V3 P0 = v3(1, 0, 0), P1 = v3(2, 0, 0);  // horizontal: annulus 1 <= r <= 2
  EXPECT_EQ(revolutionOf(P0, P1).kind, 0);
  double out[4];
  const int n = edgeEdgeAnglesAxis(P0, P1, v3(0, 1.5, -1), v3(0, 1.5, 1), out);
  ASSERT_EQ(n, 1);
  EXPECT_NEAR(out[0], M_PI / 2, kAngleTol);
  // A fixed segment outside the annulus' radii never meets it.
  EXPECT_EQ(edgeEdgeAnglesAxis(P0, P1, v3(0, 2.5, -1), v3(0, 2.5, 1), out), 0);
}

TEST(TiltAngle, EdgeEdgeGeneralAxisAgreesWithRotation) {
  // Off-origin axis: q0q1 is built through a point of p0p1 turned by 0.7 rad, so 0.7 must be
  // among the angles, and every angle returned makes the segments' lines meet.
  const V3 s = v3(0.3, -0.2, 0.1), d = normalized(v3(0.2, 0.1, 1));
  const V3 p0 = v3(1.0, 0.1, 0.0), p1 = v3(1.2, 0.4, 0.5);
  const V3 m = rotateAbout(0.5 * (p0 + p1), s, d, 0.7);
  const V3 q0 = m - v3(0.3, 0.1, -0.2), q1 = m + v3(0.3, 0.1, -0.2);
  double out[4];
  const int n = edgeEdgeAngles(p0, p1, q0, q1, s, d, out);
  ASSERT_GE(n, 1);
  bool found = false;
  for (int i = 0; i < n; ++i) found |= std::abs(out[i] - 0.7) < 1e-9;
  EXPECT_TRUE(found);
  for (int i = 0; i < n; ++i) {
    const V3 a = rotateAbout(p0, s, d, out[i]), b = rotateAbout(p1, s, d, out[i]);
    // Distance between the segments' lines at the solution is zero.
    const V3 nn = cross(b - a, q1 - q0);
    EXPECT_NEAR(dot(q0 - a, normalized(nn)), 0.0, 1e-9);
  }
}

TEST(FirstContact, CubeAbovePlaneAndEdgeCrossing) {
  const Mesh cube = scenes::box(0.1, 0.1, 0.1);
  const Mesh plane = scenes::plane(1, 1);
  const ObjectModel om = buildObjectModel(cube, 0.002);
  const AreaModel am = buildAreaModel(plane, {0, 0, -1}, 0.003, 0.005, 0.005);
  Rigid X{{1, 0, 0, 0, 1, 0, 0, 0, 1}, v3(0.1, 0.05, 0.35)};  // bottom at z = 0.3
  EXPECT_NEAR(firstContactDistance(view(om), view(am), X, v3(0, 0, -1), 1.0), 0.3, 1e-12);
  EXPECT_GE(firstContactDistance(view(om), view(am), X, v3(0, 0, -1), 0.2), kInf);  // beyond tmax
  // Edge against edge: a segment moving down onto a crossing segment.
  EXPECT_NEAR(edgeEdgeTranslation(v3(-1, 0, 1), v3(1, 0, 1), v3(0, -1, 0), v3(0, 1, 0), v3(0, 0, -1)),
              1.0, 1e-12);
  EXPECT_GE(edgeEdgeTranslation(v3(-1, 0, 1), v3(1, 0, 1), v3(2, -1, 0), v3(2, 1, 0), v3(0, 0, -1)), kInf);
}

TEST(FloorPoints, GridOverTableAndLowestN) {
  const AreaModel am = buildAreaModel(scenes::table(), {0, 0, -1}, 0.003, 0.006, 0.006);
  FloorPointParams p;
  p.d_vis = v3(0, 0, -1);
  p.spacing = 0.1;
  const FloorPoints fp = floorPoints(am, p);
  EXPECT_EQ(fp.points.size(), 11u * 9u);  // 1.0 x 0.8 m at 0.1 m
  for (const V3& q : fp.points) EXPECT_NEAR(q.z, 0.0, 1e-9);  // the top, not the underside
  // Box-like area: the lowest points are the inside bottom, not the rim.
  const AreaModel box = buildAreaModel(scenes::openBox(), {0, 0, -1}, 0.003, 0.006, 0.006);
  p.spacing = 0.02;
  p.lowest_n = 10;
  const FloorPoints low = floorPoints(box, p);
  ASSERT_EQ(low.points.size(), 10u);
  for (const V3& q : low.points) EXPECT_NEAR(q.z, 0.01, 1e-9);
  // Small areas refine the spacing until min_points rays hit.
  p.lowest_n = 0;
  p.spacing = 1.0;
  p.min_points = 16;
  EXPECT_GE(floorPoints(am, p).points.size(), 16u);
}

TEST(PreOrientation, PrincipalAxisAlongApproach) {
  const Mesh pen = scenes::pen();
  // Lying pen: k1 along z in its frame; a start orientation laying it along x.
  const Eigen::Matrix3d R_start = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto R = preOrientations(pen.properties, R_start, Eigen::Vector3d(0, 0, -1), OrientationMode::kPrincipalAxis);
  ASSERT_EQ(R.size(), 1u);
  EXPECT_NEAR(std::abs((R[0] * pen.properties.k1()).z()), 1.0, 1e-9);
  EXPECT_EQ(preOrientations(pen.properties, R_start, Eigen::Vector3d(0, 0, -1), OrientationMode::kAllAxes).size(), 6u);
  EXPECT_TRUE(preOrientations(pen.properties, R_start, Eigen::Vector3d(0, 0, -1), OrientationMode::kKeep)[0].isApprox(R_start));
}

// The fall line of a ramp, modulo 90 degrees about gravity; none on a level table, a ramp under
// 2 degrees, or ground sloping every way.
TEST(PreOrientation, SlopeDirectionIsTheRampsFallLine) {
  auto model = [](const Mesh& m) { return buildAreaModel(m, Eigen::Vector3d(0, 0, -1), 0.002, 0.0035, 0.0035); };
  auto turned = [](Mesh m, double deg) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    std::vector<Eigen::Vector3d> v;
    for (const auto& p : m.vertices) v.push_back(R * p);
    std::vector<std::vector<int>> f;
    for (const auto& t : m.triangles) f.push_back({t[0], t[1], t[2]});
    return buildMesh(v, f, "turned");
  };
  // Tilted about x: the fall line runs along y, 90 = 0 degrees modulo 90; turned by 30 about z.
  const auto along = areaSlopeDirection(model(scenes::plane(0.8, 0.8, 8.0)));
  ASSERT_TRUE(along.has_value());
  EXPECT_LT(std::min(*along, M_PI / 2 - *along), 1e-6);
  const auto turned30 = areaSlopeDirection(model(turned(scenes::plane(0.8, 0.8, 8.0), 30.0)));
  ASSERT_TRUE(turned30.has_value());
  EXPECT_NEAR(*turned30, 30 * M_PI / 180, 1e-6);
  EXPECT_FALSE(areaSlopeDirection(model(scenes::plane(0.8, 0.8, 1.0))).has_value());
  EXPECT_FALSE(areaSlopeDirection(model(scenes::table())).has_value());
  // A bowl-shaped hollow (ground sloping towards its centre from every side).
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  const int n = 24;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -0.4 + 0.8 * i / n, y = -0.4 + 0.8 * j / n;
      v.emplace_back(x, y, 0.3 * (x * x + y * y));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      f.push_back({a, a + 1, a + n + 2});
      f.push_back({a, a + n + 2, a + n + 1});
    }
  EXPECT_FALSE(areaSlopeDirection(model(buildMesh(v, f, "hollow"))).has_value());
}

TEST(TiltAxis, LayoutsAndAxes) {
  const Eigen::Vector3d dg(0, 0, -1), com(0, 0, 0.1);
  std::vector<ContactPoint> one = {{{0.01, 0, 0}, {0, 0, 1}}};
  // One contact: k1 x d_g.
  TiltAxis a = tiltAxis(one, com, Eigen::Vector3d(1, 0, 0), dg, 1e-3, 0);
  EXPECT_EQ(a.layout, ContactLayout::kSingle);
  EXPECT_NEAR(std::abs(a.d_A.y()), 1.0, 1e-12);
  // k1 parallel to gravity: (contact - com) x d_g.
  a = tiltAxis(one, com, Eigen::Vector3d(0, 0, 1), dg, 1e-3, 0);
  EXPECT_NEAR(std::abs(a.d_A.y()), 1.0, 1e-12);
  // Both parallel: a reproducible axis perpendicular to gravity.
  std::vector<ContactPoint> below = {{{0, 0, 0}, {0, 0, 1}}};
  a = tiltAxis(below, com, Eigen::Vector3d(0, 0, 1), dg, 1e-3, 42);
  EXPECT_NEAR(a.d_A.z(), 0.0, 1e-12);
  EXPECT_TRUE(a.d_A.isApprox(tiltAxis(below, com, Eigen::Vector3d(0, 0, 1), dg, 1e-3, 42).d_A));
  // Collinear contacts: their line.
  std::vector<ContactPoint> line = {{{0, 0, 0}, {0, 0, 1}}, {{0.05, 0.05, 0}, {0, 0, 1}}, {{0.1, 0.1, 0}, {0, 0, 1}}};
  a = tiltAxis(line, com, Eigen::Vector3d(1, 0, 0), dg, 1e-3, 0);
  EXPECT_EQ(a.layout, ContactLayout::kCollinear);
  EXPECT_NEAR(std::abs(a.d_A.dot(Eigen::Vector3d(1, 1, 0).normalized())), 1.0, 1e-9);
  line.push_back({{0.1, 0, 0}, {0, 0, 1}});
  EXPECT_EQ(tiltAxis(line, com, Eigen::Vector3d(1, 0, 0), dg, 1e-3, 0).layout, ContactLayout::kIndependent);
  // A short line along x with the centre of mass beyond its end along it (a pen's foot in a
  // cup's corner): it tips over that end about y, not about the line.
  const std::vector<ContactPoint> foot = {{{0, 0, 0}, {0, 0, 1}}, {{0.01, 0, 0}, {-1, 0, 0}}, {{0.02, 0, 0}, {0, 0, 1}}};
  a = tiltAxis(foot, Eigen::Vector3d(0.08, 0.001, 0.05), Eigen::Vector3d(1, 0, 0), dg, 1e-3, 0);
  EXPECT_EQ(a.layout, ContactLayout::kSingle);
  EXPECT_NEAR(std::abs(a.d_A.y()), 1.0, 1e-3);
  EXPECT_NEAR(a.s_A.x(), 0.02, 1e-3);
  // The centre of mass across the same line: it turns about the line.
  a = tiltAxis(foot, Eigen::Vector3d(0.01, 0.05, 0.05), Eigen::Vector3d(1, 0, 0), dg, 1e-3, 0);
  EXPECT_EQ(a.layout, ContactLayout::kCollinear);
  EXPECT_NEAR(std::abs(a.d_A.x()), 1.0, 0.05);
}

TEST(Stability, SquareFootprintQualityAndFailure) {
  // Unit-square footprint (0.1 m), centre of mass 0.05 m above its centre: a cube lying flat.
  std::vector<ContactPoint> sq;
  for (double x : {-0.05, 0.05})
    for (double y : {-0.05, 0.05}) sq.push_back({{x, y, 0}, {0, 0, 1}});
  StabilityParams p;
  Stability s = evaluateStability(sq, Eigen::Vector3d(0, 0, 0.05), p);
  EXPECT_TRUE(s.planar);
  EXPECT_TRUE(s.stable);
  EXPECT_NEAR(s.quality, 1.0 - 1.0 / 65.0, 1e-9);  // s = (0.05/0.1)^2/16 = 1/64
  EXPECT_GE(s.quality, 0.9);
  EXPECT_NEAR(s.tipping_angle, M_PI / 4, 1e-9);
  EXPECT_EQ(s.hull.size(), 4u);
  // Centre of mass beyond the edge x = 0.05: tips towards +x about the farthest contact.
  s = evaluateStability(sq, Eigen::Vector3d(0.08, 0, 0.05), p);
  EXPECT_FALSE(s.stable);
  EXPECT_EQ(s.failure, Failure::kTip);
  EXPECT_GT(s.d_f.x(), 0.99);
  EXPECT_NEAR(s.pivot.x(), 0.05, 1e-12);
  // Half way to the edge: Q = 1 - 0.5 - 1/65.
  s = evaluateStability(sq, Eigen::Vector3d(0.025, 0, 0.05), p);
  EXPECT_NEAR(s.quality, 0.5 - 1.0 / 65.0, 1e-9);
}

TEST(Stability, SlopeFrictionAndEquilibrium) {
  StabilityParams p;  // mu = 0.2: friction angle 11.3 degrees
  for (double slope_deg : {5.0, 20.0}) {
    const double a = slope_deg * M_PI / 180;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
    std::vector<ContactPoint> sq;
    for (double x : {-0.05, 0.05})
      for (double y : {-0.05, 0.05}) sq.push_back({R * Eigen::Vector3d(x, y, 0), R * Eigen::Vector3d(0, 0, 1)});
    const Stability s = evaluateStability(sq, R * Eigen::Vector3d(0, 0, 0.05), p);
    EXPECT_TRUE(s.planar);
    EXPECT_EQ(s.stable, slope_deg < 11.3) << slope_deg;
    if (!s.stable) {
      EXPECT_EQ(s.failure, Failure::kSlide);
      EXPECT_LT(s.d_f.z(), 0.0);  // down the slope
    }
  }
  // Equilibrium (non-planar case): a block in a V of two 20 degree slopes is held.
  std::vector<ContactPoint> v = {
      {{0, -0.05, 0.0}, Eigen::Vector3d(0, std::sin(0.35), std::cos(0.35))},
      {{0, 0.05, 0.0}, Eigen::Vector3d(0, -std::sin(0.35), std::cos(0.35))},
      {{0.05, -0.05, 0.0}, Eigen::Vector3d(0, std::sin(0.35), std::cos(0.35))},
      {{0.05, 0.05, 0.0}, Eigen::Vector3d(0, -std::sin(0.35), std::cos(0.35))}};
  EXPECT_TRUE(equilibrium(v, Eigen::Vector3d(0.025, 0, 0.05), Eigen::Vector3d(0, 0, -1), 0.2));
  // One side alone cannot hold it at mu = 0.2.
  v.resize(1);
  v.push_back({{0.05, -0.05, 0.0}, Eigen::Vector3d(0, std::sin(0.35), std::cos(0.35))});
  EXPECT_FALSE(equilibrium(v, Eigen::Vector3d(0.025, 0, 0.05), Eigen::Vector3d(0, 0, -1), 0.2));
}

TEST(Quality, HullHelpers) {
  const auto h = convexHull2d({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}, {1, 0.5}});
  EXPECT_EQ(h.size(), 4u);
  EXPECT_NEAR(polygonArea(h), 1.0, 1e-12);
  EXPECT_TRUE(polygonCentroid(h).isApprox(Eigen::Vector2d(0.5, 0.5)));
  EXPECT_NEAR(signedBoundaryDistance(h, {0.5, 0.25}), 0.25, 1e-12);
  EXPECT_NEAR(signedBoundaryDistance(h, {1.5, 0.5}), -0.5, 1e-12);
  EXPECT_NEAR(boundaryDistanceAlong(h, {0.5, 0.5}, {1, 0}), 0.5, 1e-12);
  EXPECT_EQ(quality({{0, 0}, {1, 0}}, {0, 0}, 0.1), -1.0);  // degenerate hull
  EXPECT_NEAR(quality(h, {0.5, 0.5}, 0.0), 1.0, 1e-12);      // centred, lying flat: Q = 1
}

TEST(ContactPoints, ReduceIsOrderIndependent) {
  std::vector<SphereContact> raw;
  for (int i = 0; i < 50; ++i) raw.push_back({v3(0.001 * i, 0, 0), v3(0, 0, 1), 1});
  raw.push_back({v3(5, 5, 5), v3(0, 0, 1), 0});  // invalid: ignored
  auto a = reduceContacts(raw, 0.01);
  std::reverse(raw.begin(), raw.end());
  auto b = reduceContacts(raw, 0.01);
  ASSERT_EQ(a.size(), 5u);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].p_W.isApprox(b[i].p_W, 1e-12));
}

TEST(SphereModel, SpacingAndGridHeights) {
  const Mesh plane = scenes::plane(0.1, 0.1);
  const AreaModel am = buildAreaModel(plane, {0, 0, -1}, 0.005, 0.01, 0.01);
  // 0.1 m square at 1 cm spacing: about 100 interior spheres plus edges and corners.
  EXPECT_GT(am.spheres.centres.size(), 90u);
  EXPECT_LT(am.spheres.centres.size(), 200u);
  for (const V3& c : am.spheres.centres) EXPECT_NEAR(c.z, 0.0, 1e-12);
  // Every non-empty cell's height is the plane plus the collision distance.
  for (size_t k = 0; k < am.grid.max_z.size(); ++k)
    if (am.grid.start[k + 1] > am.grid.start[k]) EXPECT_NEAR(am.grid.max_z[k], 0.01, 1e-12);
}

// The contact height cull (HeightGrid::max_contact_z, in gridMayCollide and sphereContact) drops
// only object spheres that make no contact: the contacts of poses touching and hovering up to
// 4 mm above pegs, a box's walls and binder edges are those of every object sphere tested with
// the collision-distance height alone (max_z).
TEST(SphereModel, ContactHeightCullKeepsEveryContact) {
  auto host = [](const auto& v) { return v.empty() ? nullptr : v.data(); };  // views of host arrays
  const Mesh object = scenes::mug();
  const ObjectModel om = buildObjectModel(object, 0.0015);
  const ObjectView ov = makeObjectView(om, host);
  int contacts = 0, culled = 0;
  for (const Mesh& area : {scenes::dishRack(), scenes::openBox(), scenes::binderStack()}) {
    const AreaModel am = buildAreaModel(area, {0, 0, -1}, 0.003, 0.005, 0.005);
    const AreaView av = makeAreaView(am, host);
    AreaView reference = av;
    reference.grid.max_contact_z = am.grid.max_z.data();  // cull by the collision distance only
    const V3 mid = 0.5 * (am.bounds.lo + am.bounds.hi);
    for (int k = 0; k < 40; ++k) {
      // Tilted up to 40 degrees about a horizontal axis, over a spiral of points on the area.
      const double a = 0.7 * k, rad = 0.004 * k;
      Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
      X.linear() = Eigen::AngleAxisd(M_PI / 180 * (k % 5) * 10, Eigen::Vector3d(std::cos(a), std::sin(a), 0)).toRotationMatrix();
      X.translation() = Eigen::Vector3d(mid.x + rad * std::cos(a), mid.y + rad * std::sin(a), am.bounds.hi.z + 0.2);
      const double t = firstContactDistance(ov, av, toRigid(X), v3(0, 0, -1), 1.0);
      if (t >= kInf) continue;
      for (double up : {0.0, 0.0002, 0.001, 0.004}) {
        Rigid T = toRigid(X);
        T.t = T.t + v3(0, 0, up - t);
        const V3 com = apply(T, ov.com);
        std::vector<int> kept, all;
        forEachSphereNearArea(ov, av, T, [&](int s) {
          if (sphereContact(av, apply(T, ov.mesh.sphere_centres[s]), rotate(T, ov.mesh.sphere_normals[s]), com).valid)
            kept.push_back(s);
        });
        for (int s = 0; s < ov.mesh.num_spheres; ++s) {
          const SphereContact c = sphereContact(reference, apply(T, ov.mesh.sphere_centres[s]), rotate(T, ov.mesh.sphere_normals[s]), com);
          if (c.valid) all.push_back(s);
        }
        std::sort(kept.begin(), kept.end());
        ASSERT_EQ(kept, all) << "pose " << k << " lifted " << up;
        contacts += static_cast<int>(all.size());
      }
    }
    for (size_t c = 0; c < am.grid.max_z.size(); ++c) culled += am.grid.max_contact_z[c] < am.grid.max_z[c] - 1e-3;
  }
  EXPECT_GT(contacts, 1000);  // the poses touch
  EXPECT_GT(culled, 1000);    // and the cull is tighter than the collision distance in most cells
}

// L-shaped prism: the cross-section has one reflex corner at (1, 1), whose vertical edge
// (vertices 3 and 9) is the only valley. Polygons wound outward; reversed when inside_out;
// without its top cap (an open sheet) when open.
namespace {
// L-shaped prism, wound outward: the cross-section's reflex corner at (1, 1) gives the only
// valley edge (vertices 3 and 9). inside_out reverses every polygon; open drops the top cap.
Mesh lPrism(bool inside_out = false, bool open = false) {
  const std::vector<Eigen::Vector2d> l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::vector<Eigen::Vector3d> v;
  for (double z : {0.0, 1.0})
    for (const auto& p : l) v.emplace_back(p.x(), p.y(), z);
  std::vector<std::vector<int>> faces = {{5, 4, 3, 2, 1, 0}};
  if (!open) faces.push_back({6, 7, 8, 9, 10, 11});
  for (int i = 0; i < 6; ++i) faces.push_back({i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i});
  if (inside_out)
    for (auto& f : faces) std::reverse(f.begin(), f.end());
  return buildMesh(v, faces, "l_prism");
}
}  // namespace

// Edge/edge candidates (scene.h): on a solid, a valley edge is dropped (only ridges can touch
// across); on an open sheet it is kept; the winding's sign does not matter.
TEST(FeatureEdges, RidgesOnlyOnSolids) {
  auto reflexEdgeKept = [](const Mesh& m) {
    for (const auto& e : featureEdges(m))
      if ((e[0] == 3 && e[1] == 9) || (e[0] == 9 && e[1] == 3)) return true;
    return false;
  };
  const Mesh solid = lPrism();
  // 6 top + 6 bottom + 6 vertical edges; the fan diagonals of the caps are flat.
  EXPECT_EQ(featureEdges(solid).size(), 17u);
  EXPECT_FALSE(reflexEdgeKept(solid));

  const Mesh inside_out = lPrism(true);
  EXPECT_EQ(featureEdges(inside_out).size(), 17u);
  EXPECT_FALSE(reflexEdgeKept(inside_out));

  // Without its top cap the prism is an open sheet: both sides can be touched.
  const Mesh open = lPrism(false, true);
  EXPECT_EQ(featureEdges(open).size(), 18u);
  EXPECT_TRUE(reflexEdgeKept(open));
}

// A table seen from a tilted camera: the largest flat region's normal is recovered, turned to
// the side where the box on it stands, and the planner warns under the default gravity.
TEST(AreaUp, TiltedSceneIsRecognised) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 0.2, 0).normalized()).toRotationMatrix();
  const Mesh scene = transformed(scenes::merge({scenes::plane(0.8, 0.6), scenes::box(0.1, 0.1, 0.2, {0.1, 0, 0.1})}),
                                 R, Eigen::Vector3d(0.1, -0.2, 0.3));
  const UpEstimate e = estimateUp(scene);
  EXPECT_GT(e.up.dot(R * Eigen::Vector3d::UnitZ()), std::cos(1.0 * M_PI / 180.0));
  EXPECT_GT(e.share, 0.5);
  EXPECT_LT(upFacingShare(scene, Eigen::Vector3d::UnitZ()), 0.05);
  EXPECT_NEAR(upFacingShare(scenes::table(), Eigen::Vector3d::UnitZ()), 1.0, 0.3);

  PlannerConfig c;
  c.max_candidates = 3;
  const PlanResult wrong = Planner().plan(scenes::box(0.05, 0.05, 0.05), scene, c);
  // Said first; a second warning says the closed box, with nothing stable as a scan, was
  // planned again as exact (closed_scan).
  ASSERT_FALSE(wrong.warnings.empty());
  EXPECT_NE(wrong.warnings[0].find("is gravity right?"), std::string::npos);
  c.gravity = -e.up;
  const PlanResult right = Planner().plan(scenes::box(0.05, 0.05, 0.05), scene, c);
  EXPECT_TRUE(right.warnings.empty());
  ASSERT_FALSE(right.candidates.empty());
  EXPECT_TRUE(right.candidates[0].stable);
}

// Orientation is judged per connected piece: an L-prism wound inside out merged with a box
// wound outward still loses only its valley.
TEST(FeatureEdges, OrientationPerPiece) {
  const Mesh l_prism = lPrism(true);
  const Mesh big_box = scenes::box(4, 4, 4, {10, 0, 0});  // outward, much larger volume
  const Mesh both = scenes::merge({l_prism, big_box});
  // 17 of the prism's 18 edges and the box's 12.
  EXPECT_EQ(featureEdges(both).size(), 17u + 12u);
}

// The penetration guard measures depth along the surface's normal: a vertex 1 mm inside a
// 60 degree slope lies 2 mm below it straight up, and is 1 mm deep.
TEST(Penetration, DepthAlongTheSurfaceNormal) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(60 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Mesh slab = transformed(scenes::box(0.2, 0.2, 0.02), R, Eigen::Vector3d::Zero());
  const Eigen::Vector3d n = R * Eigen::Vector3d::UnitZ();  // the slope's outward normal
  const AreaModel am = buildAreaModel(slab, {0, 0, -1}, 0.002, 0.0035, 0.0035);
  const ObjectModel om = buildObjectModel(scenes::box(0.004, 0.004, 0.004), 0.0005);
  for (double inside : {0.0005, 0.001, 0.002}) {
    // The cube's corner deepest along -n: 2 mm (|n_x| + |n_y| + |n_z|) from its centre.
    const double reach = 0.002 * (n.cwiseAbs().sum());
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = (0.01 - inside + reach) * n;
    EXPECT_NEAR(penetrationDepth(om, am, toRigid(X)), inside, 1e-4) << inside;
  }
}

// A vertex inside a vertical post is seen by the sideways rays: straight up it meets the post's
// top far above (an overhang to the upward ray alone), which a swing into a mug tree's trunk
// would otherwise pass.
TEST(Penetration, InsideAVerticalPost) {
  const Mesh post = scenes::box(0.03, 0.03, 0.40, {0, 0, 0.20});
  const AreaModel am = buildAreaModel(post, {0, 0, -1}, 0.002, 0.0035, 0.0035);
  const ObjectModel om = buildObjectModel(scenes::box(0.004, 0.004, 0.004), 0.0005);
  for (double inside : {0.001, 0.004}) {
    // The cube's side 2 mm from its centre, `inside` past the post's +x face, 20 cm up.
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Eigen::Vector3d(0.015 + 0.002 - inside, 0, 0.2);
    EXPECT_NEAR(penetrationDepth(om, am, toRigid(X)), inside, 1e-4) << inside;
  }
  // Beside the post, clear of it: none.
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(0.015 + 0.003, 0, 0.2);
  EXPECT_EQ(penetrationDepth(om, am, toRigid(X)), 0.0);
}

// A post 2.8 cm thick through the side of a 12-triangle box, 1 cm deep: no vertex of either lies
// inside the other, so the vertices see nothing; the probes on the box's long faces do
// (ObjectModel::probes), and find it about 1 cm deep.
TEST(Penetration, AThickPostThroughALongFaceIsSeenByTheProbes) {
  const Mesh post = scenes::cylinder(0.014, 0.40, 24);
  const AreaModel am = buildAreaModel(transformed(post, Eigen::Matrix3d::Identity(), {0, 0, 0.2}), {0, 0, -1},
                                      0.002, 0.0035, 0.0035);
  ObjectModel om = buildObjectModel(scenes::box(0.10, 0.10, 0.10), 0.002);
  addProbes(om, 0.008);
  ASSERT_GT(om.probes.size(), om.vertices.size());
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(0.014 + 0.05 - 0.01, 0, 0.2);  // the box's -x face 1 cm into the post
  EXPECT_EQ(penetrationDepth(om, am, toRigid(X), 0.03, false), 0.0) << "a vertex is inside";
  EXPECT_NEAR(penetrationDepth(om, am, toRigid(X)), 0.01, 0.003);
  X.translation().x() = 0.014 + 0.05 + 0.002;  // clear of it
  EXPECT_EQ(penetrationDepth(om, am, toRigid(X)), 0.0);
}

// A box 4 mm into a wall and 1.5 mm into the floor in front of it (the corner of a wall and a
// floor): the clearing shift takes it out of both, `gap` beyond each, and leaves a box already
// clear where it is. Jammed between two walls closer than it is wide, no shift clears it.
TEST(Penetration, TheClearingShiftTakesABoxOutOfAWallAndAFloor) {
  const Mesh corner = scenes::merge({scenes::box(0.4, 0.4, 0.02, {0, 0, -0.01}), scenes::box(0.02, 0.4, 0.3, {0.01, 0, 0.15})},
                                    "corner");
  const AreaModel am = buildAreaModel(corner, {0, 0, -1}, 0.002, 0.0035, 0.0035);
  ObjectModel om = buildObjectModel(scenes::box(0.06, 0.06, 0.06), 0.002);
  addProbes(om, 0.008);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(-0.03 + 0.004, 0, 0.03 - 0.0015);  // +x face 4 mm in the wall
  ASSERT_NEAR(penetrationDepth(om, am, toRigid(X)), 0.004, 5e-4);
  const double gap = 0.0005;
  const std::optional<V3> shift = clearingShift(om, am, toRigid(X), gap, 0.01);
  ASSERT_TRUE(shift) << "not clearable";
  EXPECT_NEAR(shift->x, -0.0045, 2e-4) << "out of the wall along its normal, and the gap beyond";
  EXPECT_NEAR(shift->z, 0.002, 2e-4) << "out of the floor, and the gap beyond";
  X.translation() += toEigen(*shift);
  EXPECT_LE(penetrationDepth(om, am, toRigid(X)), 1e-5);
  // Clear already: no shift.
  const std::optional<V3> none = clearingShift(om, am, toRigid(X), gap, 0.01);
  ASSERT_TRUE(none);
  EXPECT_EQ(norm(*none), 0.0);
  // Deeper than the largest shift allowed: not clearable.
  X.translation().x() += 0.0125;
  EXPECT_FALSE(clearingShift(om, am, toRigid(X), gap, 0.004));
  // Between two walls 5.5 cm apart, the 6 cm box is 2.5 mm in each: out of one is into the other.
  const Mesh slot = scenes::merge({scenes::box(0.02, 0.4, 0.3, {-0.0375, 0, 0.15}), scenes::box(0.02, 0.4, 0.3, {0.0375, 0, 0.15})},
                                  "slot");
  const AreaModel walls = buildAreaModel(slot, {0, 0, -1}, 0.002, 0.0035, 0.0035);
  X.translation() = Eigen::Vector3d(0, 0, 0.05);
  ASSERT_NEAR(penetrationDepth(om, walls, toRigid(X)), 0.0025, 5e-4);
  EXPECT_FALSE(clearingShift(om, walls, toRigid(X), gap, 0.01));
}

// A 10 cm rod tilted 45 degrees between two walls, each end 0.5 mm in a wall: out of one is
// into the other, so no shift clears it, but a turn of a degree or two about its middle
// (towards upright) does, and clearedPose takes the least such turn.
TEST(Penetration, AJammedRodIsClearedByATurnNoShiftGives) {
  ObjectModel om = buildObjectModel(scenes::box(0.10, 0.01, 0.01), 0.001);
  addProbes(om, 0.004);
  const double half = 0.5 * (0.10 + 0.01) * std::sqrt(0.5) - 0.0005;  // the walls' inner faces
  const Mesh slot = scenes::merge({scenes::box(0.02, 0.2, 0.3, {-half - 0.01, 0, 0.1}), scenes::box(0.02, 0.2, 0.3, {half + 0.01, 0, 0.1})},
                                  "slot");
  const AreaModel walls = buildAreaModel(slot, {0, 0, -1}, 0.001, 0.00175, 0.00175);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0, 0, 0.1);
  ASSERT_NEAR(penetrationDepth(om, walls, toRigid(X)), 0.0005, 2e-4);
  const double gap = 0.0005;
  EXPECT_FALSE(clearingShift(om, walls, toRigid(X), gap, 0.01)) << "a shift cleared it";
  const std::optional<Rigid> Y = clearedPose(om, walls, toRigid(X), toV3(X.translation()), gap, 0.01);
  ASSERT_TRUE(Y) << "no turn cleared it";
  EXPECT_LE(penetrationDepth(om, walls, *Y), 1e-5);
  const double turned = rotationAngle(*Y, toRigid(X)) * 180 / M_PI;
  EXPECT_GT(turned, 0.5);
  EXPECT_LE(turned, 4.0 + 1e-9);
  EXPECT_LT((toEigen(Y->t) - X.translation()).norm(), 0.005) << "moved far from where it was";
  // Already clear: the same pose back.
  const std::optional<Rigid> same = clearedPose(om, walls, *Y, Y->t, gap, 0.01);
  ASSERT_TRUE(same);
  EXPECT_EQ(rotationAngle(*same, *Y), 0.0);
}

namespace {

// A stable leaf at X_GO (G = W) scoring `quality`, on four contacts on z = 0 at +-half of its
// position along x and y.
TreeLeaf stableLeafOnFourContacts(const Eigen::Isometry3d& X_GO, double half, double quality) {
  TreeLeaf l;
  l.X_GO = toRigid(X_GO);
  l.stable = l.supported = true;
  l.quality = quality;
  for (const double cx : {-half, half})
    for (const double cy : {-half, half}) {
      ContactPoint c;
      c.p_W = Eigen::Vector3d(X_GO.translation().x() + cx, X_GO.translation().y() + cy, 0);
      c.n_area_W = Eigen::Vector3d::UnitZ();
      l.contacts.push_back(c);
    }
  return l;
}

}  // namespace

// 50 poses of a box lying on one face (down along -z of O) at a row of floor points score Q
// 0.9 and all fail their releases; 5 standing on another face (down along -x of O) score 0.7
// and hold. The checks are bounded (four times max_candidates): taken in score order they went
// to 40 lying poses and none robust was returned. While none has held, a face whose poses
// failed is tried again only after the faces not yet tried.
TEST(Ranking, AFaceWhosePosesFailedIsTriedAfterTheOthers) {
  auto leafAt = [](double x, bool standing) {
    Eigen::Isometry3d X = Eigen::Isometry3d(Eigen::Translation3d(x, 0, 0.05));
    // Standing: O's -x points down (a quarter turn about y).
    if (standing) X.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    return stableLeafOnFourContacts(X, 0.03, standing ? 0.7 : 0.9);
  };
  std::vector<TreeLeaf> leaves;
  std::vector<StartKind> kinds;
  std::vector<Eigen::Vector3d> fps;
  for (int i = 0; i < 55; ++i) {
    const bool standing = i >= 50;
    leaves.push_back(leafAt(0.1 * i, standing));
    kinds.push_back(StartKind::kRestingFace);
    fps.push_back(Eigen::Vector3d(0.1 * i, 0, 0));
  }
  RankingInput in{leaves, kinds, fps, Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(), 0.087};
  int checked = 0;
  const RobustnessCheck check = [&](const std::vector<size_t>& idx) {
    std::vector<Robustness> out;
    for (const size_t i : idx) out.push_back(Robustness{12, i >= 50 ? 12 : 3, 0.2});
    checked += static_cast<int>(idx.size());
    return out;
  };
  PlannerConfig config;  // max_candidates 10
  PlanStats stats;
  const std::vector<Candidate> c = rankCandidates(in, config, check, &stats);
  ASSERT_FALSE(c.empty());
  ASSERT_TRUE(c.front().stable) << "the standing poses were never checked";
  int standing = 0;
  for (const Candidate& k : c)
    if (k.stable) {
      EXPECT_GT(k.X_WO.translation().x(), 4.95) << "a lying pose returned stable";
      ++standing;
    }
  EXPECT_EQ(standing, 5);
  EXPECT_LE(checked, 4 * config.max_candidates) << "the checks' bound";
}

TEST(Ranking, TheLargerTippingMarginRanksFirstAmongEqualPoses) {
  // Two stable poses of a 10 cm cube on a flat top, alike in Q, contacts and robust share; one
  // tips off after 2 degrees of tilt, the other after 8. The tie-break alone (nearer the frame's
  // axis first) would put the 2-degree one first.
  auto leafAt = [](double x) {
    return stableLeafOnFourContacts(Eigen::Isometry3d(Eigen::Translation3d(x, 0, 0.05)), 0.05, 0.8);
  };
  const std::vector<TreeLeaf> leaves{leafAt(0.0), leafAt(0.4)};
  const std::vector<StartKind> kinds{StartKind::kPrincipalAxis, StartKind::kPrincipalAxis};
  const std::vector<Eigen::Vector3d> fps{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.4, 0, 0)};
  RankingInput in{leaves, kinds, fps, Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(), 0.087};
  const RobustnessCheck check = [](const std::vector<size_t>& idx) {
    std::vector<Robustness> out;
    for (const size_t i : idx) out.push_back(Robustness{12, 12, (i == 0 ? 2.0 : 8.0) * M_PI / 180});
    return out;
  };
  PlannerConfig config;
  PlanStats stats;
  const std::vector<Candidate> c = rankCandidates(in, config, check, &stats);
  ASSERT_EQ(c.size(), 2u);
  ASSERT_TRUE(c[0].stable && c[1].stable);
  EXPECT_NEAR(c[0].X_WO.translation().x(), 0.4, 1e-9);
  EXPECT_NEAR(c[0].robustness.min_tipping_angle, 8.0 * M_PI / 180, 1e-12);
}
