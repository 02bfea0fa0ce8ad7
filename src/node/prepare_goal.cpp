#include "place_planner/ros/prepare_goal.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "place_planner/ros/conversions.h"
#include "place_planner/infra/scenes.h"

namespace place_planner {
namespace {

using Result = PlacePlanResult;

// Tolerance on |q| - 1 for quaternions in the goal; beyond it the goal is rejected rather than
// silently normalised. A zero quaternion (an unset message field) is read as identity.
constexpr double kUnitQuaternionTolerance = 1e-3;
// The physics check runs one Bullet simulation per candidate: more is a mistake, not a request.
constexpr int kMaxVerifyTopK = 100;

Eigen::Isometry3d poseFromGoal(const geometry_msgs::Pose& pose, const std::string& field) {
  const auto& q = pose.orientation;
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  const auto& p = pose.position;
  if (!std::isfinite(norm) || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    throw GoalError(Result::INVALID_GOAL, field + " has a non-finite value");
  }
  if (norm == 0.0) {
    geometry_msgs::Pose identity = pose;
    identity.orientation.w = 1.0;
    return fromMsg(identity);
  }
  if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
    std::ostringstream os;
    os << field << ".orientation is not a unit quaternion (norm " << norm << ")";
    throw GoalError(Result::INVALID_GOAL, os.str());
  }
  return fromMsg(pose);
}

Mesh mappedBy(Mesh mesh, const Eigen::Isometry3d& X) {
  if (X.matrix() == Eigen::Matrix4d::Identity()) return mesh;
  return transformed(mesh, X.rotation(), X.translation());
}

// Does the goal's value replace the parameter? (PlacePlan.action: the flag, or, for goals from
// before the flags, a value that is neither 0 nor NaN.)
bool overrides(bool use, double value) { return use || (value != 0.0 && !std::isnan(value)); }
bool overrides(bool use, int value) { return use || value != 0; }

// Where a goal's mesh comes from: a PolygonMesh or a shape_msgs/Mesh, its vertices in `frame`.
struct MeshSource {
  const pcl_msgs::PolygonMesh* polygon = nullptr;
  const shape_msgs::Mesh* shape = nullptr;
  std::string frame;
  std::string name;  // "object mesh", "object shape", ... for error messages
};

// The mesh a goal plans with: its own PolygonMesh, its own shape, or the latest from a topic.
MeshSource chooseMesh(const pcl_msgs::PolygonMesh& in_goal, const shape_msgs::Mesh& shape_in_goal,
                      const std::string& shape_frame_in_goal,
                      const pcl_msgs::PolygonMeshConstPtr& from_topic,
                      const shape_msgs::MeshConstPtr& shape_from_topic, const std::string& shape_frame_param,
                      const std::string& what, const std::string& field, const std::string& shape_field,
                      const std::string& topic, const std::string& shape_topic) {
  MeshSource s;
  const std::string shape_name = what.substr(0, what.size() - 4) + "shape";  // "object mesh" -> "object shape"
  if (!in_goal.polygons.empty()) {
    s.polygon = &in_goal;
    s.frame = in_goal.header.frame_id;
    s.name = what;
  } else if (!shape_in_goal.triangles.empty()) {
    s.shape = &shape_in_goal;
    s.frame = shape_frame_in_goal;
    s.name = shape_name;
  } else if (from_topic) {
    s.polygon = from_topic.get();
    s.frame = from_topic->header.frame_id;
    s.name = what;
  } else if (shape_from_topic) {
    s.shape = shape_from_topic.get();
    s.frame = shape_frame_param;
    s.name = shape_name;
  } else {
    throw GoalError(Result::NO_MESH, what + ": the goal's " + field + " and " + shape_field +
                                         " are empty and nothing was received on " + topic + " or " +
                                         shape_topic);
  }
  return s;
}

void read(const MeshSource& s, std::vector<Eigen::Vector3d>* vertices, std::vector<std::vector<int>>* polygons) {
  if (s.polygon) {
    fromMsg(*s.polygon, s.name, vertices, polygons);
  } else {
    fromMsg(*s.shape, s.name, vertices, polygons);
  }
}

}  // namespace

const char* errorCodeName(uint8_t code) {
  switch (code) {
    case Result::SUCCESS: return "SUCCESS";
    case Result::NO_STABLE_POSE: return "NO_STABLE_POSE";
    case Result::INVALID_MESH: return "INVALID_MESH";
    case Result::NO_MESH: return "NO_MESH";
    case Result::TF_ERROR: return "TF_ERROR";
    case Result::INVALID_GOAL: return "INVALID_GOAL";
    case Result::PREEMPTED: return "PREEMPTED";
    case Result::TIMED_OUT: return "TIMED_OUT";
    case Result::INTERNAL_ERROR: return "INTERNAL_ERROR";
    default: return "UNKNOWN";
  }
}

Mesh areaAdditions(const PlacePlanGoal& goal, const PlacedObjects& placed, int* count) {
  Mesh added = goal.reset_area ? Mesh() : placed.added_W;
  *count = goal.reset_area ? 0 : placed.count;
  if (!goal.add_to_area) return added;
  if (!placed.has_last_plan) {
    throw GoalError(Result::INVALID_GOAL, "goal: add_to_area is set, but no goal was planned before to take "
                                          "its candidate add_candidate from");
  }
  const int n = static_cast<int>(placed.last_X_WO.size());
  if (goal.add_candidate < 0 || goal.add_candidate >= n) {
    throw GoalError(Result::INVALID_GOAL, "goal: add_candidate = " + std::to_string(goal.add_candidate) +
                                              " is out of range (the previous plan has " + std::to_string(n) +
                                              " candidates" + (n > 0 ? ": 0 .. " + std::to_string(n - 1) : "") + ")");
  }
  const Eigen::Isometry3d& X = placed.last_X_WO[goal.add_candidate];
  const Mesh object_W = transformed(placed.last_object_O, X.rotation(), X.translation());
  *count += 1;
  return added.vertices.empty() ? object_W : scenes::merge({added, object_W}, "objects added to the area");
}

PreparedGoal prepareGoal(const PlacePlanGoal& goal, const TopicMeshes& topics,
                         const NodeConfig& params, const FrameLookup& lookup, const Mesh* added_W) {
  const std::string& W = params.planning_frame;
  // X_WF of `frame`; `what` names the field that needed it.
  const auto X_W = [&](const std::string& frame, const std::string& what) -> Eigen::Isometry3d {
    if (frame.empty() || frame == W) return Eigen::Isometry3d::Identity();
    try {
      return lookup(frame);
    } catch (const std::exception& e) {
      throw GoalError(Result::TF_ERROR, what + ": no transform from frame '" + frame +
                                            "' to planning frame '" + W + "' (" + e.what() + ")");
    }
  };

  PreparedGoal out;
  const MeshSource object =
      chooseMesh(goal.object_mesh, goal.object_shape, goal.object_shape_frame, topics.object,
                 topics.object_shape, params.object_shape_frame, "object mesh", "object_mesh",
                 "object_shape", topics.object_topic, topics.object_shape_topic);
  const MeshSource area =
      chooseMesh(goal.placement_area_mesh, goal.placement_area_shape, goal.placement_area_shape_frame,
                 topics.area, topics.area_shape, params.placement_area_shape_frame,
                 "placement area mesh", "placement_area_mesh", "placement_area_shape", topics.area_topic,
                 topics.area_shape_topic);

  // Frames. X_WO: where the object's mesh frame is now.
  const Eigen::Isometry3d X_WO =
      X_W(goal.object_pose.header.frame_id, "object_pose") * poseFromGoal(goal.object_pose.pose, "object_pose.pose");
  const Eigen::Isometry3d X_WA = X_W(area.frame, area.name);
  // Object vertices are in the mesh's frame M when set, else in O.
  const Eigen::Isometry3d X_OM =
      object.frame.empty() ? Eigen::Isometry3d::Identity()
                           : Eigen::Isometry3d(X_WO.inverse() * X_W(object.frame, object.name));

  // Validated in the frame they came in (so an index or coordinate in a message names the element
  // as sent), then mapped.
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> polygons;
  try {
    read(object, &vertices, &polygons);
    out.object_O = mappedBy(buildMesh(vertices, polygons, object.name), X_OM);
    read(area, &vertices, &polygons);
    out.area_W = mappedBy(buildMesh(vertices, polygons, area.name), X_WA);
    // Objects placed before (add_to_area) become part of the area.
    if (added_W && !added_W->vertices.empty()) out.area_W = scenes::merge({out.area_W, *added_W}, area.name);
  } catch (const MeshError& e) {
    throw GoalError(Result::INVALID_MESH, e.what());
  }

  // Config: the parameters, overridden by the goal (PlacePlan.action's use_* rules).
  PlannerConfig& c = out.config;
  c = params.planner;
  // Orientation "keep" starts from the object's current orientation; the others turn it least.
  c.start_orientation = Eigen::Quaterniond(X_WO.rotation());
  const auto direction = [&](const geometry_msgs::Vector3Stamped& v, const char* field,
                             Eigen::Vector3d* value) {
    const Eigen::Vector3d d = fromMsg(v.vector);
    if (!d.allFinite()) throw GoalError(Result::INVALID_GOAL, std::string("goal: ") + field + " is not finite");
    if (d.norm() == 0.0) return;
    *value = X_W(v.header.frame_id, field).rotation() * d;
  };
  direction(goal.gravity, "gravity", &c.gravity);
  direction(goal.approach, "approach", &c.approach);
  if (overrides(goal.use_friction, goal.friction)) c.friction = goal.friction;
  if (overrides(goal.use_floor_point_spacing, goal.floor_point_spacing)) {
    c.floor_point_spacing = goal.floor_point_spacing;
  }
  if (overrides(goal.use_max_rotations, goal.max_rotations)) c.max_rotations = goal.max_rotations;
  if (overrides(goal.use_max_candidates, goal.max_candidates)) c.max_candidates = goal.max_candidates;
  if (overrides(goal.use_min_quality, goal.min_quality)) c.min_quality = goal.min_quality;
  if (overrides(goal.use_time_budget, goal.time_budget_s)) {
    // Checked here, not by validate(): the goal's field is in seconds, the core's in ms.
    if (!(std::isfinite(goal.time_budget_s) && goal.time_budget_s >= 0)) {
      std::ostringstream os;
      os << "goal: time_budget_s = " << goal.time_budget_s << " is out of range (>= 0 s, 0 = no budget)";
      throw GoalError(Result::INVALID_GOAL, os.str());
    }
    c.time_budget_ms = goal.time_budget_s * 1000.0;
  }
  out.verify_top_k = params.verify_top_k;
  if (overrides(goal.use_verify_top_k, goal.verify_top_k)) out.verify_top_k = std::max(0, goal.verify_top_k);
  if (out.verify_top_k > kMaxVerifyTopK) {
    throw GoalError(Result::INVALID_GOAL, "goal: verify_top_k = " + std::to_string(goal.verify_top_k) +
                                              " is out of range (0 .. 100; 0 or < 0 = off)");
  }
  // Manipulation (doc/manipulation.md): ranking, edge clearance, blocked candidates.
  if (overrides(goal.use_min_edge_clearance, goal.min_edge_clearance)) c.min_edge_clearance = goal.min_edge_clearance;
  if (goal.use_keep_colliding || goal.keep_colliding) c.keep_colliding = goal.keep_colliding;
  if (!goal.prefer_near.header.frame_id.empty() || fromMsg(goal.prefer_near.point).norm() != 0.0) {
    const Eigen::Vector3d p = fromMsg(goal.prefer_near.point);
    if (!p.allFinite()) throw GoalError(Result::INVALID_GOAL, "goal: prefer_near is not finite");
    c.prefer_near = X_W(goal.prefer_near.header.frame_id, "prefer_near") * p;
  }
  try {
    if (!goal.orientation_mode.empty()) c.orientation = orientationModeFromString(goal.orientation_mode);
    if (!goal.rank_order.empty()) c.rank_order = rankOrderFromName(goal.rank_order);
    if (!goal.placement.empty()) c.placement = placementKindFromString(goal.placement);
    validate(c);  // names the field: "friction = -1 is out of range (...)"
  } catch (const std::invalid_argument& e) {
    throw GoalError(Result::INVALID_GOAL, std::string("goal: ") + e.what());
  }
  if (goal.has_region) {
    if (goal.region_max.header.frame_id != goal.region_min.header.frame_id) {
      throw GoalError(Result::INVALID_GOAL, "goal: region_min is in frame '" +
                                                goal.region_min.header.frame_id + "' but region_max in '" +
                                                goal.region_max.header.frame_id + "'");
    }
    const Eigen::Vector3d lo = fromMsg(goal.region_min.point), hi = fromMsg(goal.region_max.point);
    if (!lo.allFinite() || !hi.allFinite() || (lo.array() > hi.array()).any()) {
      throw GoalError(Result::INVALID_GOAL, "goal: region_min must be finite and <= region_max");
    }
    // The box is axis-aligned in its own frame R: W gets the axis-aligned box around its 8
    // transformed corners.
    const Eigen::Isometry3d X_WR = X_W(goal.region_min.header.frame_id, "region_min");
    c.region_min = Eigen::Vector3d::Constant(INFINITY);
    c.region_max = Eigen::Vector3d::Constant(-INFINITY);
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d corner(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(),
                                   k & 4 ? hi.z() : lo.z());
      const Eigen::Vector3d p_W = X_WR * corner;
      c.region_min = c.region_min.cwiseMin(p_W);
      c.region_max = c.region_max.cwiseMax(p_W);
    }
  }
  if (goal.has_grasp) {
    out.has_grasp = true;
    out.X_OG = poseFromGoal(goal.grasp, "grasp");
    // The core checks the node's gripper (params.planner.gripper, null: none) at this grasp.
    c.has_grasp = true;
    c.grasp = out.X_OG;
  }
  return out;
}

}  // namespace place_planner
