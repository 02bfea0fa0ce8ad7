// Resting faces of an object (Section IV-A, generalised): the facets of its convex hull on
// which it can stand on a plane. Frame: the object's mesh frame O.
#pragma once
#include <Eigen/Core>
#include <array>
#include <vector>

#include "place_planner/model/mesh.h"
#include "place_planner/infra/stop_signal.h"

namespace place_planner {

struct ConvexHull3 {
  std::vector<Eigen::Vector3d> points;       // the input points (hull vertices index into them)
  std::vector<std::array<int, 3>> faces;     // counter-clockwise seen from outside
  std::vector<Eigen::Vector3d> normals;      // outward, unit
};

// Incremental convex hull. Points inside the hull of their extremes along 26 directions are
// dropped first (Akl-Toussaint), so a 16k-vertex scan costs a few ms. Fewer than 4 points
// off one plane give an empty hull.
ConvexHull3 convexHull3d(const std::vector<Eigen::Vector3d>& points, const StopSignal* stop = nullptr);

struct RestingFace {
  Eigen::Vector3d normal_O;          // outward normal of the facet: it points along gravity at rest
  double tipping_angle = 0.0;        // rad: tilt that tips the object off the facet (the margin)
  double margin = 0.0;               // m: distance of the projected centre of mass from the edge
  double area = 0.0;                 // m^2 of the facet's support polygon
};

// Facets (coplanar hull faces merged, within `merge_deg`) on which the centre of mass projects
// inside with at least `min_tipping_angle` (rad) to spare, best margin first: what trimesh's
// compute_stable_poses and Dex-Net rank for a plane. A ball has none.
std::vector<RestingFace> restingFaces(const Mesh& object, double min_tipping_angle,
                                      double merge_deg = 4.0, const StopSignal* stop = nullptr);

}  // namespace place_planner
