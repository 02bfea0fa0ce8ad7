#include "place_planner/config.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace place_planner {
namespace {

template <typename T>
void require(bool ok, const char* field, T value, const char* range) {
  if (ok) return;
  std::ostringstream os;
  os << field << " = " << value << " is out of range (" << range << ")";
  throw std::invalid_argument(os.str());
}

void requireVector(const Eigen::Vector3d& v, const char* field, bool allow_zero) {
  const bool finite = v.allFinite();
  const bool nonzero = v.norm() > 1e-9;
  if (finite && (allow_zero || nonzero)) return;
  std::ostringstream os;
  os << field << " = (" << v.x() << ", " << v.y() << ", " << v.z() << ") is invalid ("
     << (finite ? "must not be zero" : "must be finite") << ")";
  throw std::invalid_argument(os.str());
}

}  // namespace

void validate(const PlannerConfig& c) {
  requireVector(c.gravity, "gravity", false);
  requireVector(c.approach, "approach", true);
  require(std::isfinite(c.friction) && c.friction >= 0 && c.friction <= 10, "friction", c.friction,
          "0 <= friction <= 10");
  require(std::isfinite(c.floor_point_spacing) && c.floor_point_spacing > 1e-4, "floor_point_spacing",
          c.floor_point_spacing, "> 0.0001 m");
  require(c.min_floor_points >= 1 && c.min_floor_points <= 100000, "min_floor_points",
          c.min_floor_points, "1 .. 100000");
  require(c.lowest_n >= 0, "lowest_n", c.lowest_n, ">= 0");
  require(c.max_rotations >= 0 && c.max_rotations <= 12, "max_rotations", c.max_rotations, "0 .. 12");
  require(std::isfinite(c.sphere_radius) && c.sphere_radius >= 0, "sphere_radius", c.sphere_radius,
          ">= 0, 0 = derived");
  require(std::isfinite(c.grid_cell_size) && c.grid_cell_size >= 0, "grid_cell_size",
          c.grid_cell_size, ">= 0, 0 = derived");
  require(std::isfinite(c.time_budget_ms) && c.time_budget_ms >= 0, "time_budget_ms",
          c.time_budget_ms, ">= 0, 0 = none");
  require(c.max_candidates >= 1 && c.max_candidates <= 100000, "max_candidates", c.max_candidates, "1 .. 100000");
  require(c.threads >= 0 && c.threads <= 256, "threads", c.threads, "0 .. 256, 0 = all");
  require(c.max_local_optimisation_steps >= 0 && c.max_local_optimisation_steps <= 50,
          "max_local_optimisation_steps", c.max_local_optimisation_steps, "0 .. 50");
  require(std::isfinite(c.min_support_width) && c.min_support_width >= 0, "min_support_width",
          c.min_support_width, ">= 0 m");
  require(std::isfinite(c.min_tipping_angle_deg) && c.min_tipping_angle_deg >= 0 &&
              c.min_tipping_angle_deg < 90,
          "min_tipping_angle_deg", c.min_tipping_angle_deg, "0 .. 90");
  require(std::abs(c.start_orientation.norm() - 1.0) < 1e-3, "start_orientation",
          c.start_orientation.norm(), "a unit quaternion");
  require(std::isfinite(c.min_quality) && c.min_quality <= 1, "min_quality", c.min_quality, "<= 1");
  require(std::isfinite(c.merge_distance) && c.merge_distance >= 0, "merge_distance",
          c.merge_distance, ">= 0");
  require(c.max_resting_faces >= 0 && c.max_resting_faces <= 64, "max_resting_faces",
          c.max_resting_faces, "0 .. 64");
  require(std::isfinite(c.robust_shift) && c.robust_shift >= 0 && c.robust_shift <= 0.05,
          "robust_shift", c.robust_shift, "0 .. 0.05 m");
  require(std::isfinite(c.robust_tilt_deg) && c.robust_tilt_deg >= 0 && c.robust_tilt_deg <= 20,
          "robust_tilt_deg", c.robust_tilt_deg, "0 .. 20");
  require(std::isfinite(c.robust_com_offset) && c.robust_com_offset >= 0 && c.robust_com_offset <= 0.3,
          "robust_com_offset", c.robust_com_offset, "0 .. 0.3 (share of the object's size)");
  require(std::isfinite(c.robust_min_share) && c.robust_min_share >= 0 && c.robust_min_share <= 1,
          "robust_min_share", c.robust_min_share, "0 .. 1");
  require(std::isfinite(c.robust_min_share_hanging) && c.robust_min_share_hanging >= 0 &&
              c.robust_min_share_hanging <= 1,
          "robust_min_share_hanging", c.robust_min_share_hanging, "0 .. 1");
  require(c.max_triangles >= 100 && c.max_triangles <= 50000000, "max_triangles", c.max_triangles,
          "100 .. 50000000");
  require(c.max_floor_points >= 1 && c.max_floor_points <= 1000000, "max_floor_points",
          c.max_floor_points, "1 .. 1000000");
  require(c.min_floor_points <= c.max_floor_points, "min_floor_points", c.min_floor_points,
          "<= max_floor_points");
  require(c.max_tree_nodes >= 100, "max_tree_nodes", c.max_tree_nodes, ">= 100");
  require(std::isfinite(c.max_model_mb) && c.max_model_mb >= 1, "max_model_mb", c.max_model_mb, ">= 1 MB");
  require(std::isfinite(c.max_object_size) && c.max_object_size > 0, "max_object_size",
          c.max_object_size, "> 0 m");
  require(std::isfinite(c.max_area_size) && c.max_area_size > 0, "max_area_size", c.max_area_size,
          "> 0 m");
  require(std::isfinite(c.max_gripper_tilt_deg) && c.max_gripper_tilt_deg >= 0 && c.max_gripper_tilt_deg <= 180,
          "max_gripper_tilt_deg", c.max_gripper_tilt_deg, "0 .. 180");
  require(std::isfinite(c.gripper_min_clearance) && c.gripper_min_clearance >= 0, "gripper_min_clearance",
          c.gripper_min_clearance, ">= 0 m");
  for (auto [name, v] : {std::pair<const char*, double>{"approach_distance", c.approach_distance},
                         {"approach_min_distance", c.approach_min_distance},
                         {"retreat_distance", c.retreat_distance},
                         {"retreat_min_distance", c.retreat_min_distance},
                         {"min_edge_clearance", c.min_edge_clearance}})
    require(std::isfinite(v) && v >= 0 && v <= 2, name, v, "0 .. 2 m");
  require(c.approach_min_distance <= c.approach_distance, "approach_min_distance", c.approach_min_distance,
          "<= approach_distance");
  require(c.retreat_min_distance <= c.retreat_distance, "retreat_min_distance", c.retreat_min_distance,
          "<= retreat_distance");
  requireVector(c.prefer_near, "prefer_near", true);
  require(c.grasp.matrix().allFinite() && std::abs(c.grasp.linear().determinant() - 1.0) < 1e-3, "grasp",
          c.grasp.linear().determinant(), "a rigid transform (rotation determinant 1)");
  require(std::isfinite(c.scan_noise) && c.scan_noise >= 0 && c.scan_noise <= 0.05, "scan_noise", c.scan_noise,
          "0 .. 0.05 m");
  require(std::isfinite(c.scan_unseen_reach) && c.scan_unseen_reach >= 0 && c.scan_unseen_reach <= 0.05,
          "scan_unseen_reach", c.scan_unseen_reach, "0 .. 0.05 m");
  require(std::isfinite(c.merge_angle_deg) && c.merge_angle_deg >= 0, "merge_angle_deg",
          c.merge_angle_deg, ">= 0");
}

OrientationMode orientationModeFromString(const std::string& s) {
  if (s == "auto" || s.empty()) return OrientationMode::kAuto;
  if (s == "principal_axis") return OrientationMode::kPrincipalAxis;
  if (s == "keep") return OrientationMode::kKeep;
  if (s == "all_axes") return OrientationMode::kAllAxes;
  throw std::invalid_argument("orientation_mode = '" + s +
                              "' is unknown (use auto, principal_axis, keep or all_axes)");
}

PlacementKind placementKindFromString(const std::string& s, const std::string& field) {
  if (s == "any" || s.empty()) return PlacementKind::kAny;
  if (s == "standing") return PlacementKind::kStanding;
  if (s == "hanging") return PlacementKind::kHanging;
  throw std::invalid_argument(field + " = '" + s + "' is unknown (use any, standing or hanging)");
}

const char* toString(PlacementKind k) {
  switch (k) {
    case PlacementKind::kStanding: return "standing";
    case PlacementKind::kHanging: return "hanging";
    default: return "any";
  }
}

std::string toString(OrientationMode m) {
  switch (m) {
    case OrientationMode::kKeep: return "keep";
    case OrientationMode::kAllAxes: return "all_axes";
    case OrientationMode::kAuto: return "auto";
    default: return "principal_axis";
  }
}

}  // namespace place_planner
