// The place_planner ROS 1 node: a thin adapter over place_planner::Planner.
//   action server  ~place_plan   (place_planner/PlacePlan; goals run on actionlib's own thread)
//   subscribes     object_mesh, placement_area_mesh   (pcl_msgs/PolygonMesh, remappable)
//   publishes      ~markers (visualization_msgs/MarkerArray, latched), ~candidates (PoseArray, latched)
// Frames (doc/node.md): W = ~planning_frame. The placement area mesh is brought into W by tf2.
// The object's mesh frame O is located by goal.object_pose; the object mesh's vertices are in
// header.frame_id when that is set (tf2 -> W, then object_pose^-1 -> O) and in O when it is empty.
#pragma once
#include <memory>
#include <mutex>
#include <string>

#include <actionlib/server/simple_action_server.h>
#include <pcl_msgs/PolygonMesh.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "place_planner/PlacePlanAction.h"
#include "place_planner/planner.h"
#include "place_planner/ros/params.h"

namespace place_planner {

class PlacePlannerNode {
 public:
  // Loads and validates the parameters from pnh: throws std::invalid_argument naming the bad one
  // before anything is advertised.
  PlacePlannerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

 private:
  struct Prepared;  // a goal converted for the core: meshes, config, grasp

  void execute(const PlacePlanGoalConstPtr& goal);
  Prepared prepare(const PlacePlanGoal& goal);
  // X_WF: pose of `frame` in the planning frame (identity for "" and the planning frame itself).
  // Throws a TF_ERROR naming `what` and the frame.
  Eigen::Isometry3d lookup(const std::string& frame, const std::string& what) const;
  bool onProgress(const Progress& progress);
  void onFeedbackTimer();
  // Publishes when feedback_period has passed since the last feedback.
  void publishFeedback(const Progress& progress);

  ros::NodeHandle nh_, pnh_;
  NodeConfig config_;
  Planner planner_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Subscriber object_sub_, area_sub_;
  ros::Publisher marker_pub_, candidates_pub_;
  ros::WallTimer feedback_timer_;

  std::mutex mesh_mutex_;  // the latest meshes from the topics
  pcl_msgs::PolygonMeshConstPtr latest_object_, latest_area_;

  std::mutex feedback_mutex_;  // progress of the running goal; shared with the feedback timer
  bool planning_ = false;
  Progress progress_;
  ros::WallTime plan_start_, last_feedback_;

  // Last: it starts serving as soon as it is constructed.
  std::unique_ptr<actionlib::SimpleActionServer<PlacePlanAction>> server_;
};

}  // namespace place_planner
