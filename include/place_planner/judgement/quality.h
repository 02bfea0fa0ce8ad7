// Support polygon geometry and the quality measure Q (Section VI). 2D, in the plane P of the
// contacts (or the plane perpendicular to gravity for the projected support).
#pragma once
#include <Eigen/Core>
#include <vector>

namespace place_planner {

// Convex hull, counter-clockwise, no collinear points (Andrew's monotone chain). Fewer than 3
// distinct non-collinear points give a degenerate hull (size < 3).
std::vector<Eigen::Vector2d> convexHull2d(std::vector<Eigen::Vector2d> pts);
double polygonArea(const std::vector<Eigen::Vector2d>& hull);
Eigen::Vector2d polygonCentroid(const std::vector<Eigen::Vector2d>& hull);  // c_Omega
// Signed distance of p from the hull's boundary: > 0 inside, < 0 outside.
double signedBoundaryDistance(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p);
// Smallest width of a convex polygon (rotating calipers over its edges); 0 when degenerate.
double polygonWidth(const std::vector<Eigen::Vector2d>& hull);
// l_Omega: distance from `from` (inside) to the boundary along unit `dir`.
double boundaryDistanceAlong(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& from,
                             const Eigen::Vector2d& dir);

// Least-squares plane of 3D points: their centroid, the unit normal (least scatter; either
// sign), the direction of the next least scatter, the farthest any point lies off the plane and
// along that direction (a spread near 0: the points lie on a line).
struct PlaneFit {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(), second = Eigen::Vector3d::UnitX();
  double off = 0, spread = 0;
};
PlaneFit fitPlane(const std::vector<Eigen::Vector3d>& pts);

// Q = 1 - d(c^_O, c^_Omega) / l^_Omega - s / (1 + s),  s = (h / sqrt(A(Omega)))^2 / 16.
// The paper's second term d(c_O, Omega) / A(Omega) divides a length by an area; we use the
// dimensionless height-to-footprint ratio h / sqrt(A) instead, squashed into [0, 1) so that
// Q <= 1 with Q = 1 only for a centred footprint of an object lying flat (h -> 0); a cube
// resting on a face scores 1 - 1/65 = 0.985, a box standing on its 5 x 9 cm end with its
// centre of mass 9 cm up 0.88, and only footprints four times narrower than the height
// (h / sqrt(A) > 4.9) fall below 0.3 even when centred.
// c_hat_O: projected centre of mass; h: height of c_O above the plane. Degenerate hull: -1.
double quality(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& c_hat_O, double h);

}  // namespace place_planner
