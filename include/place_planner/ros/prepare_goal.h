// A PlacePlan goal converted for the core: meshes in their frames, the planner config with the
// goal's overrides, the grasp. No ROS graph here: the latest topic meshes and a frame lookup
// come in as arguments, so it is unit-tested without a running node (test_prepare_goal.cpp).
// Frames: W is the planning frame, O the object's mesh frame, G the gripper frame.
// (Namespace place_planner, not place_planner::ros: inside place_planner, `ros::` must keep
// naming roscpp.)
#pragma once
#include <Eigen/Geometry>
#include <functional>
#include <stdexcept>
#include <string>

#include <pcl_msgs/PolygonMesh.h>

#include "place_planner/PlacePlanAction.h"
#include "place_planner/mesh.h"
#include "place_planner/config.h"
#include "place_planner/ros/params.h"

namespace place_planner {

// A goal that cannot be planned: the result's error_code and the message the caller gets.
struct GoalError : std::runtime_error {
  GoalError(uint8_t c, const std::string& what) : std::runtime_error(what), code(c) {}
  uint8_t code;
};

// "SUCCESS", "INVALID_GOAL", ... for a PlacePlanResult error code; "UNKNOWN" otherwise.
const char* errorCodeName(uint8_t code);

struct PreparedGoal {
  Mesh object_O;  // in the object's mesh frame O
  Mesh area_W;    // in the planning frame W
  PlannerConfig config;   // the parameters with the goal's overrides; validate()d
  int verify_top_k = 0;   // Bullet check of the best K stable candidates (0 = off)
  bool has_grasp = false;
  Eigen::Isometry3d X_OG = Eigen::Isometry3d::Identity();  // the grasp, when has_grasp
};

// The latest meshes received on the node's topics (null: none yet) and the topics' names, for
// goals whose meshes are empty.
struct TopicMeshes {
  pcl_msgs::PolygonMeshConstPtr object, area;
  std::string object_topic = "object_mesh", area_topic = "placement_area_mesh";
};

// X_WF: the pose of `frame` in the planning frame. Called only for frames other than "" and the
// planning frame (both are W). Throws (tf2::TransformException or any std::exception) when there
// is no transform; prepareGoal turns that into TF_ERROR naming the field and the frame.
using FrameLookup = std::function<Eigen::Isometry3d(const std::string& frame)>;

// Throws GoalError: NO_MESH (empty goal mesh, nothing on the topic), TF_ERROR (lookup failed),
// INVALID_MESH (a mesh cannot be read or built: names the mesh and element), INVALID_GOAL (a field
// out of range, a non-unit quaternion, a bad region: names the field, e.g. "goal: friction = -1
// is out of range (0 <= friction <= 10)"). The use_* rules of the overrides are those of
// PlacePlan.action: flag true -> the value as given (0 is 0); flag false -> the parameter when
// the value is 0 or NaN, the value otherwise (goals before issue 10).
PreparedGoal prepareGoal(const PlacePlanGoal& goal, const TopicMeshes& topics,
                         const NodeConfig& params, const FrameLookup& lookup);

}  // namespace place_planner
