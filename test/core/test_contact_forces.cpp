// The contact-force model (judgement/contact_forces.h) and the stability it decides
// (judgement/stability.h, non-planar case): closed-form statics on both sides of each limit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "place_planner/judgement/contact_forces.h"
#include "place_planner/judgement/stability.h"

namespace place_planner {
namespace {

const Eigen::Vector3d kGravity(0, 0, -1);

// A rod of length l at angle theta from the floor, its foot on the floor (normal +z) and its top
// against a wall at x = 0 (normal -x); two contacts each end, 2 cm apart across the rod.
std::vector<ContactPoint> ladder(double theta, double l, Eigen::Vector3d* com) {
  const Eigen::Vector3d foot(-l * std::cos(theta), 0, 0), top(0, 0, l * std::sin(theta));
  *com = 0.5 * (foot + top);
  std::vector<ContactPoint> c;
  for (double y : {-0.01, 0.01}) {
    c.push_back({foot + Eigen::Vector3d(0, y, 0), Eigen::Vector3d::UnitZ()});
    c.push_back({top + Eigen::Vector3d(0, y, 0), -Eigen::Vector3d::UnitX()});
  }
  return c;
}

TEST(ContactForces, LadderHoldsExactlyAboveTheFrictionAngle) {
  // A uniform ladder with friction mu at floor and wall holds when tan(theta) >= (1 - mu^2) / (2 mu).
  for (double mu : {0.3, 0.5, 0.7}) {
    const double critical = std::atan((1 - mu * mu) / (2 * mu));
    for (double delta_deg : {-3.0, -1.0, 1.0, 3.0}) {
      const double theta = critical + delta_deg * M_PI / 180.0;
      Eigen::Vector3d com;
      const auto c = ladder(theta, 0.4, &com);
      EXPECT_EQ(equilibrium(c, com, kGravity, mu), delta_deg > 0)
          << "mu " << mu << " theta " << theta * 180 / M_PI << " deg (critical " << critical * 180 / M_PI << ")";
    }
  }
  // Without the wall the rod falls whatever its angle.
  Eigen::Vector3d com;
  auto c = ladder(1.2, 0.4, &com);
  c.erase(std::remove_if(c.begin(), c.end(), [](const ContactPoint& p) { return p.n_W.z() < 0.5; }), c.end());
  EXPECT_FALSE(equilibrium(c, com, kGravity, 0.7));
}

TEST(ContactForces, SlippingLadderKicksItsFootAwayFromTheWall) {
  // mu 0.2: the ladder holds from 67.4 degrees. Below, wide cones would hold it, so friction
  // alone fails: it slips, its foot away from the wall (-x), and the stability's local step
  // slides it that way, lifted straight up first.
  const double mu = 0.2;
  Eigen::Vector3d com;
  const ForceModelParams prm{mu, 8, 3.0};
  for (double theta_deg : {50.0, 60.0, 65.0}) {
    const auto c = ladder(theta_deg * M_PI / 180.0, 0.4, &com);
    const Eigen::Vector3d d = slipDirection(c, com, prm);
    EXPECT_LT(d.x(), -0.99) << theta_deg;
    EXPECT_NEAR(d.z(), 0.0, 1e-12);
    StabilityParams sp;
    sp.friction = mu;
    const Stability s = evaluateStability(c, com, sp);
    EXPECT_FALSE(s.stable);
    EXPECT_TRUE(s.slips) << theta_deg;
    EXPECT_EQ(s.failure, Failure::kSlide);
    EXPECT_LT(s.d_f.x(), -0.99);
  }
  // Above the critical angle it holds: no slip.
  auto c = ladder(72.0 * M_PI / 180.0, 0.4, &com);
  EXPECT_EQ(slipDirection(c, com, prm).norm(), 0.0);
  // Without the wall no friction holds it (it falls, it does not slip).
  c.erase(std::remove_if(c.begin(), c.end(), [](const ContactPoint& p) { return p.n_W.z() < 0.5; }), c.end());
  EXPECT_EQ(slipDirection(c, com, prm).norm(), 0.0);
}

TEST(ContactForces, RingHangsOnAPegWithItsCentreOfMassBelow) {
  // A ring on a horizontal peg (along y): two contacts on the peg's top, across the ring's
  // thickness, pushing up. Its centre of mass 3 cm below.
  StabilityParams sp;  // mu 0.2
  auto ring = [](double slope_deg) {
    // The peg sloping down towards +y: its top's normal leans towards +y.
    const double a = slope_deg * M_PI / 180;
    const Eigen::Vector3d n(0, std::sin(a), std::cos(a));
    return std::vector<ContactPoint>{{{0, -0.003, 0}, n}, {{0, 0.003, 0}, n}};
  };
  const Stability below = evaluateStability(ring(0), Eigen::Vector3d(0, 0, -0.03), sp);
  EXPECT_TRUE(below.hanging);
  EXPECT_TRUE(below.stable) << "a ring straight below a horizontal peg hangs";
  EXPECT_GT(below.tipping_angle, 0.0);
  // 1 cm to the side: gravity turns it about the peg; not in equilibrium (it swings).
  const Stability aside = evaluateStability(ring(0), Eigen::Vector3d(0.01, 0, -0.03), sp);
  EXPECT_TRUE(aside.hanging);
  EXPECT_FALSE(aside.balanced);
  EXPECT_FALSE(aside.stable);
  EXPECT_GT(aside.d_f.x(), 0.9) << "it swings towards its centre of mass";
  // A peg sloping down 5 degrees holds it (with the half friction angle's margin, 5.7 degrees,
  // under atan 0.2 = 11.3); past atan mu it slides off.
  EXPECT_TRUE(evaluateStability(ring(5), Eigen::Vector3d(0, 0, -0.03), sp).stable);
  for (double slope : {12.0, 20.0}) {
    const Stability off = evaluateStability(ring(slope), Eigen::Vector3d(0, 0, -0.03), sp);
    EXPECT_FALSE(off.balanced) << slope;
    EXPECT_FALSE(off.stable) << slope;
  }
}

// A dome held from above by a ring of 12 contacts (radius 5 cm, their normals leaning 50 degrees
// outwards from the vertical: a bowl upside down over a cup's rim). The normals meet 4.2 cm
// below the ring: the dome turns about that point as it slides on the ring. Its centre of mass
// below that point, it hangs there as a pendulum; above it (a shallow bowl), the forces still
// balance, but a tilt lowers the centre of mass and it slides off the ring's side: not stable.
// A loop on a peg, whose normals are too near parallel to meet, is judged as before (above).
TEST(ContactForces, ADomeOverARingHangsOnlyWithItsCentreOfMassBelowWhereItsNormalsMeet) {
  StabilityParams sp;  // mu 0.2
  const double r = 0.05, lean = 50.0 * M_PI / 180;
  std::vector<ContactPoint> ring;
  for (int k = 0; k < 12; ++k) {
    const Eigen::Vector3d out(std::cos(k * M_PI / 6), std::sin(k * M_PI / 6), 0);
    ring.push_back({r * out, std::sin(lean) * out + std::cos(lean) * Eigen::Vector3d::UnitZ()});
  }
  const double meet = -r / std::tan(lean);  // -0.042
  const Stability deep = evaluateStability(ring, Eigen::Vector3d(0, 0, meet - 0.01), sp);
  EXPECT_TRUE(deep.hanging);
  EXPECT_TRUE(deep.balanced);
  EXPECT_TRUE(deep.stable) << "its centre of mass 1 cm below where the normals meet";
  const Stability shallow = evaluateStability(ring, Eigen::Vector3d(0, 0, meet + 0.01), sp);
  EXPECT_TRUE(shallow.hanging);
  EXPECT_TRUE(shallow.balanced) << "the ring's forces balance gravity";
  EXPECT_FALSE(shallow.stable) << "its centre of mass 1 cm above where the normals meet";
}

// Hung on a peg (along x) with a wall behind (at +y, facing -y) that it touches below the peg
// (a mug at the root of a coat peg): contacts below the centre of mass that only push sideways
// keep it hanging. Its centre of mass 5 mm off straight below the peg, away from the wall, turns
// it into the wall, which holds it (the peg's friction takes the wall's push); without the wall,
// or with its centre of mass on the wall's side (a wall cannot pull), it swings.
TEST(ContactForces, HangingObjectLeansOnAWallBelowItsPeg) {
  StabilityParams sp;  // mu 0.2
  const std::vector<ContactPoint> peg{{{-0.003, 0, 0}, {0, 0, 1}}, {{0.003, 0, 0}, {0, 0, 1}}};
  std::vector<ContactPoint> with_wall = peg;
  with_wall.push_back({{0, 0.03, -0.05}, {0, -1, 0}});
  const Stability leaning = evaluateStability(with_wall, Eigen::Vector3d(0, -0.005, -0.04), sp);
  EXPECT_TRUE(leaning.hanging);
  EXPECT_TRUE(leaning.stable) << "held by its peg and the wall";
  const Stability free = evaluateStability(peg, Eigen::Vector3d(0, -0.005, -0.04), sp);
  EXPECT_TRUE(free.hanging);
  EXPECT_FALSE(free.stable) << "5 mm off straight below its peg, with no wall";
  const Stability pulled = evaluateStability(with_wall, Eigen::Vector3d(0, 0.005, -0.04), sp);
  EXPECT_FALSE(pulled.stable) << "the wall would have to pull";
  // A floor contact below the centre of mass (its normal up) is no wall: not hanging.
  std::vector<ContactPoint> floor = peg;
  floor.push_back({{0, 0, -0.08}, {0, 0, 1}});
  EXPECT_FALSE(evaluateStability(floor, Eigen::Vector3d(0, -0.005, -0.04), sp).hanging);
  // Nor is an object that only touches a wall, above and below its centre of mass.
  const std::vector<ContactPoint> wall{{{0, 0.03, 0.02}, {0, -1, 0}}, {{0, 0.03, -0.02}, {0, -1, 0}}};
  EXPECT_FALSE(evaluateStability(wall, Eigen::Vector3d(0, 0, 0), sp).hanging);
}

// A loop hung on a ridge of a faceted peg (along x) touches both facets there, whose normals
// lean 40 degrees either way; a wall at +y below. Its centre of mass 15 mm off straight below
// the ridge, away from the wall: the wall pushes it with 0.3 of its weight, which the two
// facets take together. Merged into one contact with their mean normal (straight up), friction
// alone (mu 0.2) could not: the force model keeps contacts of unlike normals apart.
TEST(ContactForces, ALoopsContactsOnBothFacetsOfItsPegKeepTheirNormals) {
  StabilityParams sp;  // mu 0.2
  const double a = 40 * M_PI / 180;
  std::vector<ContactPoint> c;
  for (double x : {-0.003, 0.003})
    for (double side : {-1.0, 1.0}) c.push_back({{x, 0, 0}, {0, side * std::sin(a), std::cos(a)}});
  c.push_back({{0, 0.03, -0.05}, {0, -1, 0}});
  const Stability s = evaluateStability(c, Eigen::Vector3d(0, -0.015, -0.04), sp);
  EXPECT_TRUE(s.hanging);
  EXPECT_TRUE(s.stable) << "held by both facets and the wall";
  // A ridge with both facets leaning the same way (one cone, tilted) does not hold it.
  for (auto& p : c)
    if (p.n_W.z() > 0) p.n_W = Eigen::Vector3d(0, -std::sin(a), std::cos(a));
  EXPECT_FALSE(evaluateStability(c, Eigen::Vector3d(0, -0.015, -0.04), sp).stable);
}

// A 4 cm box whose lower edges touch two walls at `wall_deg` from the horizontal (a V-groove).
std::vector<ContactPoint> vGroove(double wall_deg, bool both_walls) {
  const double a = wall_deg * M_PI / 180.0;
  std::vector<ContactPoint> c;
  for (double y : {-0.02, 0.02}) {
    c.push_back({{-0.02, y, 0}, {std::sin(a), 0, std::cos(a)}});
    if (both_walls) c.push_back({{0.02, y, 0}, {-std::sin(a), 0, std::cos(a)}});
  }
  return c;
}

TEST(ContactForces, GravityWedgesABoxBetweenSteepWallsButNotAgainstOne) {
  StabilityParams p;  // mu 0.2
  const Eigen::Vector3d com(0, 0, 0.02);
  for (double wall : {45.0, 60.0, 70.0}) {
    const Stability both = evaluateStability(vGroove(wall, true), com, p);
    EXPECT_TRUE(both.stable) << wall << " degree walls";
    EXPECT_FALSE(evaluateStability(vGroove(wall, false), com, p).stable) << wall << " degree wall alone";
  }
  // Parallel vertical walls hold only by a squeeze of at least weight / mu: not relied on.
  EXPECT_FALSE(evaluateStability(vGroove(90.0, true), com, p).stable);
}

TEST(ContactForces, SphereRestsInACupNotOnOnePoint) {
  const double R = 0.03;
  const Eigen::Vector3d com = Eigen::Vector3d::Zero();
  StabilityParams p;
  // In a cup whose bottom is narrower than the sphere it rests on a ring of contacts, normals
  // through its centre, 30 degrees from vertical.
  std::vector<ContactPoint> ring;
  for (int k = 0; k < 8; ++k) {
    const double phi = 2 * M_PI * k / 8, beta = 30.0 * M_PI / 180.0;
    const Eigen::Vector3d q(std::sin(beta) * std::cos(phi), std::sin(beta) * std::sin(phi), -std::cos(beta));
    ring.push_back({R * q, -q});
  }
  EXPECT_TRUE(evaluateStability(ring, com, p).stable);
  // The same ring off-centre (the sphere against one side of the cup): one side only, it rolls.
  std::vector<ContactPoint> side(ring.begin(), ring.begin() + 3);
  EXPECT_FALSE(evaluateStability(side, com, p).stable);
  // On a table: one contact under its centre. Gravity alone is balanced (an unstable equilibrium),
  // the smallest tilt is not.
  const std::vector<ContactPoint> point = {{{0, 0, -R}, {0, 0, 1}}};
  EXPECT_TRUE(equilibrium(point, com, kGravity, 0.2));
  EXPECT_FALSE(evaluateStability(point, com, p).stable);
}

TEST(ContactForces, LineOfContactsHoldsOnlyWithTheCentreOfMassOnIt) {
  // A cylinder on its side: contacts along a line (x axis), on a floor.
  std::vector<ContactPoint> line;
  for (double x : {-0.05, 0.0, 0.05}) line.push_back({{x, 0, 0}, {0, 0, 1}});
  EXPECT_TRUE(equilibrium(line, Eigen::Vector3d(0, 0, 0.02), kGravity, 0.2));
  EXPECT_FALSE(equilibrium(line, Eigen::Vector3d(0, 0.002, 0.02), kGravity, 0.2));
  EXPECT_FALSE(evaluateStability(line, Eigen::Vector3d(0, 0, 0.02), StabilityParams{}).stable);
}

// The settle of an unbalanced pose (ContactForces::unbalanced): it never drives a contact into
// its surface, gravity does work along it, and it is zero where gravity is balanced.
TEST(ContactForces, UnbalancedWrenchStartsASettleThatPushesNoContactIn) {
  // A box on a floor point and against a wall (x = 0, normal -x), its centre of mass beyond
  // the floor point away from the wall: it tips away from the wall.
  std::vector<ContactPoint> c = {{{-0.02, 0, 0}, {0, 0, 1}}, {{0, 0, 0.03}, {-1, 0, 0}}};
  const Eigen::Vector3d com(-0.03, 0, 0.02);
  const ContactForces f(c, com, ForceModelParams{0.2, 8, 3.0});
  ASSERT_FALSE(f.balances(kGravity));
  Eigen::Vector3d v, w;
  f.unbalanced(kGravity, &v, &w);
  ASSERT_GT(v.norm() + w.norm(), 1e-6);
  EXPECT_LT(v.z(), 0) << "the centre of mass does not sink";
  for (const ContactPoint& p : c) {
    const Eigen::Vector3d vel = v + w.cross(p.p_W - com);
    EXPECT_GE(vel.dot(p.n_W), -1e-6) << "the settle pushes a contact into its surface";
  }
  // It tips about its floor point away from the wall: a turn about -y lowers the centre of
  // mass, which lies beyond the floor point on -x.
  EXPECT_LT(w.y(), 0);
  // The same box with its centre of mass over its floor point, leaning nowhere: balanced.
  const ContactForces g({{{-0.02, -0.01, 0}, {0, 0, 1}}, {{-0.02, 0.01, 0}, {0, 0, 1}},
                         {{0, 0, 0.03}, {-1, 0, 0}}, {{-0.04, 0, 0}, {0, 0, 1}}},
                        Eigen::Vector3d(-0.025, 0, 0.02), ForceModelParams{0.2, 8, 3.0});
  ASSERT_TRUE(g.balances(kGravity));
  g.unbalanced(kGravity, &v, &w);
  EXPECT_EQ(v.norm() + w.norm(), 0.0);
}

TEST(ContactForces, CubeSlidesOnASlopeSteeperThanTheFrictionAngle) {
  // The planar case's closed form (slope < atan mu) and the force model agree.
  const double mu = 0.4;
  for (double slope_deg : {15.0, 20.0, 23.0, 26.0, 30.0}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(slope_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    std::vector<ContactPoint> c;
    for (double x : {-0.02, 0.02})
      for (double y : {-0.02, 0.02}) c.push_back({R * Eigen::Vector3d(x, y, 0), R.col(2)});
    const Eigen::Vector3d com = R * Eigen::Vector3d(0, 0, 0.01);
    // The pyramid's edges lie on the cone in the slope's direction here (edge at +-x of the
    // contact frame), so the model is exact: holds below atan(0.4) = 21.8 degrees.
    EXPECT_EQ(equilibrium(c, com, kGravity, mu), slope_deg < 21.8) << slope_deg;
    StabilityParams p;
    p.friction = mu;
    EXPECT_EQ(evaluateStability(c, com, p).stable, slope_deg < 21.8) << slope_deg;
  }
}

TEST(ContactForces, PushOnAFlatTopIsTheTippingMarginOrFriction) {
  // A box of half-width w with its centre of mass at height h resists a push of w / h before it
  // tips (with friction enough), and mu before it slides.
  auto box = [](double w) {
    std::vector<ContactPoint> c;
    for (double x : {-w, w})
      for (double y : {-w, w}) c.push_back({{x, y, 0}, {0, 0, 1}});
    return c;
  };
  const ForceModelParams sticky{2.0, 8, 3.0};
  const ContactForces low(box(0.04), Eigen::Vector3d(0, 0, 0.02), sticky);    // w / h = 2 -> capped at 1
  const ContactForces tall(box(0.02), Eigen::Vector3d(0, 0, 0.08), sticky);   // w / h = 0.25
  const ContactForces mid(box(0.03), Eigen::Vector3d(0, 0, 0.05), sticky);    // w / h = 0.6
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  EXPECT_NEAR(low.pushResistance(x), 1.0, 1e-9);
  EXPECT_NEAR(tall.pushResistance(x), 0.25, 0.01);
  EXPECT_NEAR(mid.pushResistance(x), 0.6, 0.01);
  // Low and wide resists more than tall and narrow, over all directions too.
  const PushResistance pl = pushResistance(box(0.04), Eigen::Vector3d(0, 0, 0.02), sticky);
  const PushResistance pt = pushResistance(box(0.02), Eigen::Vector3d(0, 0, 0.08), sticky);
  EXPECT_GT(pl.min, pt.min + 0.5);
  // With mu = 0.2 both slide first: the push is friction's, mu cos(pi / 8) at worst.
  const ContactForces slippery(box(0.04), Eigen::Vector3d(0, 0, 0.02), ForceModelParams{0.2, 8, 3.0});
  EXPECT_NEAR(slippery.pushResistance(x), 0.2, 0.2 * (1 - std::cos(M_PI / 8)) + 0.01);
  // Nothing holds without gravity balanced: a box beside its support.
  EXPECT_EQ(ContactForces(box(0.02), Eigen::Vector3d(0.05, 0, 0.02), sticky).pushResistance(x), 0.0);
}

TEST(ContactForces, BoxInASlotResistsALargerPushThanOnAFlatTop) {
  // A 4 x 4 x 10 cm box standing on a floor; in a slot, walls 4 cm apart (normals +-x) touch
  // its sides 2 cm up.
  std::vector<ContactPoint> flat;
  for (double x : {-0.02, 0.02})
    for (double y : {-0.02, 0.02}) flat.push_back({{x, y, 0}, {0, 0, 1}});
  std::vector<ContactPoint> slot = flat;
  for (double y : {-0.02, 0.02}) {
    slot.push_back({{-0.02, y, 0.02}, {1, 0, 0}});
    slot.push_back({{0.02, y, 0.02}, {-1, 0, 0}});
  }
  const Eigen::Vector3d com(0, 0, 0.05);
  const ForceModelParams prm{0.2, 8, 3.0};
  const PushResistance on_top = pushResistance(flat, com, prm);
  const PushResistance in_slot = pushResistance(slot, com, prm);
  EXPECT_GT(in_slot.by_direction[0], on_top.by_direction[0] + 0.3);  // across the slot
  EXPECT_GT(in_slot.mean, on_top.mean + 0.1);
  EXPECT_GE(in_slot.min, on_top.min - 0.01);  // along the slot: friction, as on the top
  EXPECT_GT(on_top.min, 0.1);
}

}  // namespace
}  // namespace place_planner
