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
#include <vector>

#include <pcl_msgs/PolygonMesh.h>
#include <shape_msgs/Mesh.h>

#include "place_planner/PlacePlanAction.h"
#include "place_planner/model/mesh.h"
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
// goals whose meshes are empty. Per mesh at most one of the PolygonMesh and the shape_msgs/Mesh
// is set: the one received last (the node drops the other). The shapes carry no header: their
// vertices are in NodeConfig::object_shape_frame / placement_area_shape_frame.
struct TopicMeshes {
  pcl_msgs::PolygonMeshConstPtr object, area;
  shape_msgs::MeshConstPtr object_shape, area_shape;
  std::string object_topic = "object_mesh", area_topic = "placement_area_mesh";
  std::string object_shape_topic = "object_shape", area_shape_topic = "placement_area_shape";
};

// Objects one after another (goal fields reset_area, add_to_area, add_candidate): what the
// node keeps between goals.
struct PlacedObjects {
  Mesh added_W;    // objects merged into the area so far, in W (empty: none)
  int count = 0;   // ... how many
  bool has_last_plan = false;          // a goal planned (whatever its outcome)
  Mesh last_object_O;                  // that goal's object, in O
  std::vector<Eigen::Isometry3d> last_X_WO;  // its candidates' poses, ranked
};

// reset_area first (drops added_W), then add_to_area (the last plan's object at candidate
// add_candidate, merged in): the objects this goal's area gets, and their count in *count.
// Changes nothing; the node keeps the result once the goal is valid. Throws GoalError
// INVALID_GOAL naming add_to_area (no previous plan) or add_candidate (out of range).
Mesh areaAdditions(const PlacePlanGoal& goal, const PlacedObjects& placed, int* count);

// X_WF: the pose of `frame` in the planning frame. Called only for frames other than "" and the
// planning frame (both are W). Throws (tf2::TransformException or any std::exception) when there
// is no transform; prepareGoal turns that into TF_ERROR naming the field and the frame.
using FrameLookup = std::function<Eigen::Isometry3d(const std::string& frame)>;

// Throws GoalError: NO_MESH (empty goal mesh, nothing on the topic), TF_ERROR (lookup failed),
// INVALID_MESH (a mesh cannot be read or built: names the mesh and element), INVALID_GOAL (a field
// out of range, a non-unit quaternion, a bad region: names the field, e.g. "goal: friction = -1
// is out of range (0 <= friction <= 10)"). The use_* rules of the overrides are those of
// PlacePlan.action: flag true -> the value as given (0 is 0); flag false -> the parameter when
// the value is 0 or NaN, the value otherwise (older goals, sent before the flags existed).
// added_W (optional): objects placed earlier (add_to_area), in W, merged into the placement
// area. The goal's mesh wins over its shape, which wins over the topics.
PreparedGoal prepareGoal(const PlacePlanGoal& goal, const TopicMeshes& topics,
                         const NodeConfig& params, const FrameLookup& lookup,
                         const Mesh* added_W = nullptr);

}  // namespace place_planner
