#include "place_planner/ros/place_plan_server.h"

#include <actionlib_msgs/GoalStatusArray.h>

namespace place_planner {

using actionlib_msgs::GoalStatus;

PlacePlanServer::PlacePlanServer(const ros::NodeHandle& nh, const std::string& name,
                                 boost::function<void(GoalHandle)> goal_cb,
                                 boost::function<void(GoalHandle)> cancel_cb)
    : actionlib::ActionServerBase<PlacePlanAction>(goal_cb, cancel_cb, false), node_(nh, name) {}

PlacePlanResult PlacePlanServer::guarded(uint8_t status, const PlacePlanResult& result) {
  if (status == GoalStatus::SUCCEEDED || result.error_code != PlacePlanResult::SUCCESS) return result;
  PlacePlanResult r = result;
  if (status == GoalStatus::RECALLED || status == GoalStatus::PREEMPTED) {
    r.error_code = PlacePlanResult::PREEMPTED;
    r.error_message = "recalled by actionlib before the planner saw the goal (its cancel came first)";
  } else {
    r.error_code = PlacePlanResult::INTERNAL_ERROR;
    r.error_message = "internal error: actionlib ended the goal (status " + std::to_string(status) +
                      ") without an answer from the planner";
  }
  r.partial = false;
  return r;
}

// As actionlib::ActionServer::initialize(): the same topics, parameters and defaults.
void PlacePlanServer::initialize() {
  int pub_queue_size = 50, sub_queue_size = 50;
  node_.param("actionlib_server_pub_queue_size", pub_queue_size, 50);
  node_.param("actionlib_server_sub_queue_size", sub_queue_size, 50);
  if (pub_queue_size < 0) pub_queue_size = 50;
  if (sub_queue_size < 0) sub_queue_size = 50;
  result_pub_ = node_.advertise<PlacePlanActionResult>("result", static_cast<uint32_t>(pub_queue_size));
  feedback_pub_ = node_.advertise<PlacePlanActionFeedback>("feedback", static_cast<uint32_t>(pub_queue_size));
  status_pub_ = node_.advertise<actionlib_msgs::GoalStatusArray>("status", static_cast<uint32_t>(pub_queue_size), true);
  double status_frequency = 5.0, status_list_timeout = 5.0;
  std::string frequency_name;
  if (node_.searchParam("actionlib_status_frequency", frequency_name)) {
    node_.param(frequency_name, status_frequency, 5.0);
  }
  node_.param("status_list_timeout", status_list_timeout, 5.0);
  status_list_timeout_ = ros::Duration(status_list_timeout);
  if (status_frequency > 0) {
    status_timer_ = node_.createTimer(ros::Duration(1.0 / status_frequency), [this](const ros::TimerEvent&) {
      boost::recursive_mutex::scoped_lock lock(lock_);
      if (started_) publishStatus();
    });
  }
  goal_sub_ = node_.subscribe<PlacePlanActionGoal>(
      "goal", static_cast<uint32_t>(sub_queue_size),
      [this](const PlacePlanActionGoalConstPtr& goal) { goalCallback(goal); });
  cancel_sub_ = node_.subscribe<actionlib_msgs::GoalID>(
      "cancel", static_cast<uint32_t>(sub_queue_size),
      [this](const actionlib_msgs::GoalIDConstPtr& id) { cancelCallback(id); });
}

void PlacePlanServer::publishResult(const GoalStatus& status, const PlacePlanResult& result) {
  boost::recursive_mutex::scoped_lock lock(lock_);
  auto ar = boost::make_shared<PlacePlanActionResult>();
  ar->header.stamp = ros::Time::now();
  ar->status = status;
  ar->result = guarded(status.status, result);
  if (ar->result.error_code != result.error_code) {
    ROS_WARN("place_planner: goal %s: %s", status.goal_id.id.c_str(), ar->result.error_message.c_str());
  }
  result_pub_.publish(ar);
  publishStatus();
}

void PlacePlanServer::publishFeedback(const GoalStatus& status, const PlacePlanFeedback& feedback) {
  boost::recursive_mutex::scoped_lock lock(lock_);
  auto af = boost::make_shared<PlacePlanActionFeedback>();
  af->header.stamp = ros::Time::now();
  af->status = status;
  af->feedback = feedback;
  feedback_pub_.publish(af);
}

void PlacePlanServer::publishStatus() {
  boost::recursive_mutex::scoped_lock lock(lock_);
  actionlib_msgs::GoalStatusArray status_array;
  status_array.header.stamp = ros::Time::now();
  status_array.status_list.reserve(status_list_.size());
  for (auto it = status_list_.begin(); it != status_list_.end();) {
    status_array.status_list.push_back(it->status_);
    // A goal nobody holds a handle to any more is listed for status_list_timeout, then dropped.
    if (it->handle_destruction_time_ != ros::Time() &&
        it->handle_destruction_time_ + status_list_timeout_ < ros::Time::now()) {
      it = status_list_.erase(it);
    } else {
      ++it;
    }
  }
  status_pub_.publish(status_array);
}

}  // namespace place_planner
