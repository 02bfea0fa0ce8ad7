// The place_planner ROS 1 node: a thin adapter over place_planner::Planner.
//   action server  ~place_plan   (place_planner/PlacePlan; goals run on a thread of their own)
//   subscribes     object_mesh, placement_area_mesh   (pcl_msgs/PolygonMesh, remappable)
//                  object_shape, placement_area_shape (shape_msgs/Mesh, frames: parameters)
//   publishes      ~markers (visualization_msgs/MarkerArray, latched), ~candidates (PoseArray, latched)
// Frames (doc/node.md): W = ~planning_frame. The placement area mesh is brought into W by tf2.
// The object's mesh frame O is located by goal.object_pose; the object mesh's vertices are in
// header.frame_id when that is set (tf2 -> W, then object_pose^-1 -> O) and in O when it is empty.
//
// One goal runs at a time; the newest goal wins (SimpleActionServer's policy). The goal queue is
// the node's own, over PlacePlanServer (actionlib's ActionServer with a guard on results), so
// that every goal that does not run to the end is answered with a PREEMPTED result of its own:
// SimpleActionServer answers a goal it drops before it starts (RECALLED) with a default result,
// whose error_code 0 reads as SUCCESS.
#pragma once
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <dynamic_reconfigure/server.h>
#include <pcl_msgs/PolygonMesh.h>
#include <shape_msgs/Mesh.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "place_planner/PlacePlanAction.h"
#include "place_planner/PlacePlannerConfig.h"
#include "place_planner/planner.h"
#include "place_planner/ros/params.h"
#include "place_planner/ros/place_plan_server.h"
#include "place_planner/ros/prepare_goal.h"

namespace place_planner {

class PlacePlannerNode {
 public:
  // Loads and validates the parameters from pnh: throws std::invalid_argument naming the bad one
  // before anything is advertised.
  PlacePlannerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);
  // Stops the running goal (answered PREEMPTED) and the goal thread.
  ~PlacePlannerNode();

 private:
  using Server = PlacePlanServer;
  using GoalHandle = Server::GoalHandle;
  enum class Terminal { kSucceeded, kAborted, kCanceled };
  struct Answer;  // the result of one goal and the state to end it in

  // actionlib's callbacks (ROS callback thread).
  void onGoal(GoalHandle goal);
  void onCancel(GoalHandle goal);
  // The goal thread: takes the newest pending goal, runs it, ends it; until shutdown.
  void goalLoop();
  // Accepts, runs and ends one goal, then publishes its markers; never throws.
  void serve(GoalHandle goal);
  // One goal, start to answer; never throws (an exception is INTERNAL_ERROR).
  Answer execute(const PlacePlanGoal& goal);
  void plan(const PlacePlanGoal& goal, Answer* answer);

  // X_WF: pose of `frame` in the planning frame (tf2, waiting up to ~tf_timeout).
  Eigen::Isometry3d lookup(const std::string& frame) const;
  // Between goals: freed heap back to the OS, so that the resident size is what the node holds.
  static void releaseFreedMemory();
  bool onProgress(const Progress& progress);
  // dynamic_reconfigure (config/PlacePlanner.cfg): the new values go to the parameter server and
  // through loadNodeConfig (the startup reader and validate()); refused ones are logged by name
  // and the previous values kept. The next goal plans with them; a running goal keeps its own.
  void onReconfigure(PlacePlannerConfig& tuning, uint32_t level);
  void onFeedbackTimer();
  // Publishes when feedback_period has passed since the last feedback.
  void publishFeedback(const Progress& progress);

  ros::NodeHandle nh_, pnh_;
  NodeConfig config_;  // as loaded at startup; never changed after (read by every thread)
  // The planner parameters as tuned live; each goal copies them when it starts.
  std::mutex tuning_mutex_;
  PlannerConfig tuned_planner_;
  PlacePlannerConfig last_tuning_;  // the last accepted values (callback thread only)
  bool tuned_once_ = false;
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<PlacePlannerConfig>> reconfigure_;
  Planner planner_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Subscriber object_sub_, area_sub_;
  ros::Publisher marker_pub_, candidates_pub_;
  ros::WallTimer feedback_timer_;

  std::mutex mesh_mutex_;  // the latest meshes from the topics; per mesh the newest of the two kinds
  pcl_msgs::PolygonMeshConstPtr latest_object_, latest_area_;
  shape_msgs::MeshConstPtr latest_object_shape_, latest_area_shape_;
  ros::Subscriber object_shape_sub_, area_shape_sub_;

  // Objects one after another (goal thread only): merged into the area so far, and the last
  // plan's object and candidate poses, which add_to_area takes one from.
  PlacedObjects placed_;

  std::mutex feedback_mutex_;  // progress of the running goal; shared with the feedback timer
  bool planning_ = false;
  Progress progress_;
  ros::WallTime plan_start_, last_feedback_;

  // Goal queue. Never held while calling into actionlib (whose callbacks take it).
  std::mutex goal_mutex_;
  std::condition_variable goal_cv_;
  std::optional<GoalHandle> pending_;  // newest goal, not started yet
  std::optional<GoalHandle> running_;  // the goal the thread works on
  bool stopping_ = false;
  // Cancel or a newer goal: the running goal's planner stops at its next step.
  std::atomic<bool> preempt_requested_{false};
  ros::WallTime preempt_time_;  // when it was requested (goal_mutex_)
  void requestPreempt();        // with goal_mutex_ held

  std::unique_ptr<Server> server_;
  std::thread goal_thread_;
};

}  // namespace place_planner
