// Node parameters: PlannerConfig (include/place_planner/config.h) field for field, plus the few
// settings that only the ROS layer has (voxblox_ros/ros_params.h style). config/place_planner.yaml
// mirrors both structs; a missing parameter keeps the struct default. Times are in seconds
// (time_budget_s; the struct's time_budget_ms is filled from it).
#pragma once
#include <map>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "place_planner/config.h"

namespace place_planner {

struct NodeConfig {
  std::string planning_frame = "world";  // frame of the placement area and of every answer
  double tf_timeout = 0.5;               // s, wait for a transform before TF_ERROR
  double feedback_period = 0.05;         // s, at most this long between feedback messages
  int marker_candidates = 10;            // object outlines drawn (best first)
  int marker_text_count = 3;             // "Q = ..." labels for the best few
  // Bullet check of the best K stable candidates after each plan (validation::verifyTopK), within
  // what is left of the time budget; a goal's verify_top_k overrides it. 0 = off.
  int verify_top_k = 0;
  // Which engines check them (validation::Engines): "bullet", "mujoco" or "both" (a candidate's
  // physics_stayed then needs both).
  std::string verify_engines = "bullet";
  // The gripper (doc/manipulation.md), loaded once at startup into planner.gripper when
  // gripper_links is set: the URDF from ~urdf_file when set, else the parameter named
  // robot_description_param (searched up from the private namespace, as ROS tools do).
  std::string robot_description_param = "robot_description";
  std::string urdf_file;                              // "" = use robot_description_param
  std::vector<std::string> gripper_links;             // first = the gripper frame F; empty = no gripper
  std::map<std::string, double> gripper_joint_positions;  // rad or m; unlisted joints at 0
  std::string gripper_mesh_dir;  // relative mesh paths of the URDF: "" = urdf_file's folder (or cwd)
  // Frames of the shape_msgs/Mesh topics (no header of their own): "" = O for the object
  // (like an object_mesh without frame id), "" = the planning frame for the area.
  std::string object_shape_frame;
  std::string placement_area_shape_frame;
  PlannerConfig planner;
};

// Reads the parameters from nh (the node's private namespace). Throws std::invalid_argument
// naming the parameter for a wrong type ("parameter /place_planner/gravity must be a list of 3
// numbers"), an unknown enum value, or a value out of range (place_planner::validate(), e.g.
// "parameter /place_planner/friction = -0.1 is out of range (0 <= friction <= 10)").
// With gripper_links set, the gripper is loaded here: a missing or bad URDF, an unknown link
// or joint, or an unreadable mesh is an std::invalid_argument naming the parameter and the link.
NodeConfig loadNodeConfig(const ros::NodeHandle& nh);

// "quality" | "lowest" | "nearest"; throws std::invalid_argument ("rank_order = 'x' is unknown ...").
RankOrder rankOrderFromName(const std::string& name);
const char* rankOrderName(RankOrder order);

}  // namespace place_planner
