// The PlacePlan action server's transport: actionlib::ActionServer's topics (goal, cancel,
// status, result, feedback under the action's name), with one guarantee added in publishResult:
// an answer that is not SUCCEEDED never carries error_code SUCCESS (0).
//
// Why a server of its own: actionlib answers some goals itself, with a default-constructed
// result (error_code 0), before the node sees them: a goal whose cancel arrived first (goal and
// cancel travel on two topics, so a client that cancels at once can be overtaken), and a goal
// stamped before a "cancel everything before t" request. actionlib::ActionServer's
// publishResult is private, so this class is ActionServer (action_server_imp.h, actionlib
// 1.14) re-written over the same ActionServerBase, with the guard.
#pragma once
#include <string>

#include <actionlib/server/action_server_base.h>
#include <ros/ros.h>

#include "place_planner/PlacePlanAction.h"

namespace place_planner {

class PlacePlanServer : public actionlib::ActionServerBase<PlacePlanAction> {
 public:
  using GoalHandle = actionlib::ServerGoalHandle<PlacePlanAction>;
  // Serves under nh/name once start() is called.
  PlacePlanServer(const ros::NodeHandle& nh, const std::string& name,
                  boost::function<void(GoalHandle)> goal_cb, boost::function<void(GoalHandle)> cancel_cb);
  ~PlacePlanServer() override = default;

  // The result as it is published for a goal ending in `status` (a GoalStatus constant): a
  // result with error_code SUCCESS for anything but SUCCEEDED becomes PREEMPTED (RECALLED,
  // PREEMPTED) or INTERNAL_ERROR (ABORTED, REJECTED, others), saying that actionlib answered it.
  static PlacePlanResult guarded(uint8_t status, const PlacePlanResult& result);

 private:
  void initialize() override;
  void publishResult(const actionlib_msgs::GoalStatus& status, const PlacePlanResult& result) override;
  void publishFeedback(const actionlib_msgs::GoalStatus& status, const PlacePlanFeedback& feedback) override;
  void publishStatus() override;

  ros::NodeHandle node_;
  ros::Subscriber goal_sub_, cancel_sub_;
  ros::Publisher status_pub_, result_pub_, feedback_pub_;
  ros::Timer status_timer_;
};

}  // namespace place_planner
