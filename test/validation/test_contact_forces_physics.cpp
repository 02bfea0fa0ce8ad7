// The contact-force model (judgement/contact_forces.h) against the Bullet validator on cases
// with a closed-form answer: both must agree on each side of the limit.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "place_planner/infra/scenes.h"
#include "place_planner/judgement/contact_forces.h"
#include "place_planner/validation/physics_validator.h"

namespace place_planner {
namespace validation {
namespace {

// A 30 cm rod (2 x 2 cm section) at angle theta from the floor, its lower edge on the floor and
// its upper edge against a wall whose face is the plane x = 0.
struct Ladder {
  Eigen::Isometry3d X_WO = Eigen::Isometry3d::Identity();
  std::vector<ContactPoint> contacts;  // W
  Eigen::Vector3d com_W;
};
constexpr double kHalfLength = 0.15, kHalfThickness = 0.01;

Ladder ladder(double theta) {
  Ladder l;
  const double a = kHalfLength, b = kHalfThickness;
  l.X_WO.linear() = Eigen::AngleAxisd(-theta, Eigen::Vector3d::UnitY()).toRotationMatrix();
  l.X_WO.translation() = Eigen::Vector3d(-(a * std::cos(theta) + b * std::sin(theta)), 0, a * std::sin(theta) + b * std::cos(theta));
  l.com_W = l.X_WO.translation();
  for (double y : {-b, b}) {
    l.contacts.push_back({l.X_WO * Eigen::Vector3d(-a, y, -b), Eigen::Vector3d::UnitZ()});
    l.contacts.push_back({l.X_WO * Eigen::Vector3d(a, y, -b), -Eigen::Vector3d::UnitX()});
  }
  return l;
}

Mesh floorAndWall() {
  return scenes::merge({scenes::plane(1.2, 1.0), scenes::box(0.05, 1.0, 0.6, Eigen::Vector3d(0.025, 0, 0.3))}, "floor_and_wall");
}

// The ladder with friction mu at floor and wall holds when tan(theta) >= (1 - mu^2) / (2 mu):
// 67.4 degrees for mu = 0.2 (the planner's default), 56.6 for 0.3. Measured with this validator
// in 5 degree steps: mu 0.2 falls at 65 and holds from 70; mu 0.3 falls at 55, creeps 1.2 cm at
// 60 and holds from 65. (At mu 0.5 and 0.8 Bullet's rod creeps 1-2 cm down the wall below 60
// degrees, far above their critical angles of 37 and 13: a limit of the engine's edge contact,
// not of the statics; those are not compared.)
TEST(ContactForcesPhysics, LadderAgreesWithBulletOnBothSidesOfTheFrictionLimit) {
  const Mesh rod = scenes::box(2 * kHalfLength, 2 * kHalfThickness, 2 * kHalfThickness);
  const Mesh area = floorAndWall();
  for (const auto& [mu, margin_deg] : {std::pair<double, double>{0.2, 8.0}, {0.3, 10.0}}) {
    const double critical = std::atan((1 - mu * mu) / (2 * mu));
    ValidatorConfig c;
    c.friction = mu;
    const PhysicsValidator bullet(rod, area, c);
    for (double delta_deg : {-margin_deg, margin_deg}) {
      const double theta = critical + delta_deg * M_PI / 180.0;
      const Ladder l = ladder(theta);
      const bool holds = delta_deg > 0;
      // The rod's edges touch the floor and the wall: no penetration, no gap.
      EXPECT_NEAR(l.contacts[0].p_W.z(), 0.0, 1e-9);
      EXPECT_NEAR(l.contacts[1].p_W.x(), 0.0, 1e-9);
      EXPECT_EQ(equilibrium(l.contacts, l.com_W, Eigen::Vector3d(0, 0, -1), mu), holds)
          << "force model, mu " << mu << " at " << theta * 180 / M_PI << " deg";
      const PoseCheck r = bullet.check(l.X_WO);
      EXPECT_EQ(r.confirmed, holds) << "Bullet, mu " << mu << " at " << theta * 180 / M_PI << " deg: moved "
                                    << r.moved_m << " m, turned " << r.turned_deg << " deg";
    }
  }
}

}  // namespace
}  // namespace validation
}  // namespace place_planner
