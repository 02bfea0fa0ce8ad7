#include "place_planner/ros/place_planner_node.h"

#include <geometry_msgs/PoseArray.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include <sstream>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <stdexcept>

#include "place_planner/ros/conversions.h"
#include "place_planner/ros/markers.h"
#include "place_planner/infra/work_limits.h"
#include "place_planner/validation/physics_validator.h"

namespace place_planner {
namespace {

using Result = PlacePlanResult;

Result preemptedResult(const std::string& why) {
  Result r;
  r.error_code = Result::PREEMPTED;
  r.error_message = why;
  return r;
}

}  // namespace

struct PlacePlannerNode::Answer {
  Result result;
  Terminal terminal = Terminal::kAborted;
  // For the markers, when the planner ran.
  bool planned = false;
  PreparedGoal prepared;
  PlanResult plan;
  ros::Time stamp;
};

PlacePlannerNode::PlacePlannerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), pnh_(pnh), config_(loadNodeConfig(pnh)), tf_listener_(tf_buffer_) {
  // The callbacks only keep the message: a mesh republished at a high rate costs its
  // deserialisation (on roscpp's receive thread) and a pointer swap, also while a goal plans.
  object_sub_ = nh_.subscribe<pcl_msgs::PolygonMesh>(
      "object_mesh", 1, [this](const pcl_msgs::PolygonMeshConstPtr& m) {
        std::lock_guard<std::mutex> lock(mesh_mutex_);
        latest_object_ = m;
        latest_object_shape_.reset();
      });
  area_sub_ = nh_.subscribe<pcl_msgs::PolygonMesh>(
      "placement_area_mesh", 1, [this](const pcl_msgs::PolygonMeshConstPtr& m) {
        std::lock_guard<std::mutex> lock(mesh_mutex_);
        latest_area_ = m;
        latest_area_shape_.reset();
      });
  // shape_msgs/Mesh (MoveIt's collision objects) beside the PolygonMesh: the newest of the two wins.
  object_shape_sub_ = nh_.subscribe<shape_msgs::Mesh>(
      "object_shape", 1, [this](const shape_msgs::MeshConstPtr& m) {
        std::lock_guard<std::mutex> lock(mesh_mutex_);
        latest_object_shape_ = m;
        latest_object_.reset();
      });
  area_shape_sub_ = nh_.subscribe<shape_msgs::Mesh>(
      "placement_area_shape", 1, [this](const shape_msgs::MeshConstPtr& m) {
        std::lock_guard<std::mutex> lock(mesh_mutex_);
        latest_area_shape_ = m;
        latest_area_.reset();
      });
  marker_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  candidates_pub_ = pnh_.advertise<geometry_msgs::PoseArray>("candidates", 1, true);
  feedback_timer_ = nh_.createWallTimer(ros::WallDuration(config_.feedback_period / 2),
                                        [this](const ros::WallTimerEvent&) { onFeedbackTimer(); });
  tuned_planner_ = config_.planner;
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<PlacePlannerConfig>>(reconfigure_mutex_, pnh_);
  reconfigure_->setCallback([this](PlacePlannerConfig& c, uint32_t level) { onReconfigure(c, level); });
  goal_thread_ = std::thread([this] { goalLoop(); });
  server_ = std::make_unique<Server>(
      pnh_, "place_plan", [this](GoalHandle g) { onGoal(g); }, [this](GoalHandle g) { onCancel(g); });
  server_->start();
  ROS_INFO("place_planner: serving %s/place_plan, planning frame '%s'",
           pnh_.getNamespace().c_str(), config_.planning_frame.c_str());
}

PlacePlannerNode::~PlacePlannerNode() {
  {
    std::lock_guard<std::mutex> lock(goal_mutex_);
    stopping_ = true;
  }
  preempt_requested_ = true;
  goal_cv_.notify_all();
  goal_thread_.join();
  std::optional<GoalHandle> pending;
  {
    std::lock_guard<std::mutex> lock(goal_mutex_);
    pending.swap(pending_);
  }
  if (pending) pending->setCanceled(preemptedResult("recalled: the node shut down before it started"));
}

void PlacePlannerNode::onGoal(GoalHandle goal) {
  std::optional<GoalHandle> superseded;
  {
    std::lock_guard<std::mutex> lock(goal_mutex_);
    superseded.swap(pending_);
    pending_ = goal;
    if (running_) requestPreempt();  // the newest goal wins
  }
  goal_cv_.notify_all();
  if (superseded) {
    superseded->setCanceled(preemptedResult("recalled: superseded by a newer goal before it started"));
  }
}

void PlacePlannerNode::onCancel(GoalHandle goal) {
  std::optional<GoalHandle> recalled;
  {
    std::lock_guard<std::mutex> lock(goal_mutex_);
    if (pending_ && *pending_ == goal) {
      recalled.swap(pending_);
    } else if (running_ && *running_ == goal) {
      requestPreempt();
    }
  }
  if (recalled) recalled->setCanceled(preemptedResult("recalled: cancelled before it started"));
}

void PlacePlannerNode::releaseFreedMemory() {
#ifdef __GLIBC__
  // A plan allocates tens of MB for a moment (meshes, models, leaves) on several threads;
  // glibc keeps what was freed in its arenas, so the node's resident size would follow the
  // largest plan so far, not what it holds. Between goals, hand it back (about 1 ms here).
  malloc_trim(0);
#endif
}

void PlacePlannerNode::requestPreempt() {
  if (!preempt_requested_) preempt_time_ = ros::WallTime::now();
  preempt_requested_ = true;
}

void PlacePlannerNode::goalLoop() {
  for (;;) {
    GoalHandle goal;
    {
      std::unique_lock<std::mutex> lock(goal_mutex_);
      goal_cv_.wait(lock, [this] { return stopping_ || pending_; });
      if (stopping_) return;
      goal = *pending_;
      pending_.reset();
      running_ = goal;
      preempt_requested_ = false;
      preempt_time_ = ros::WallTime();
    }
    serve(goal);
    // After serve(): the goal's meshes, models and answer are gone by now.
    releaseFreedMemory();
  }
}

void PlacePlannerNode::serve(GoalHandle goal) {
  // A cancel that came since it was taken is already a preempt request (onCancel sees running_).
  goal.setAccepted("accepted by place_planner");
  const ros::WallTime start = ros::WallTime::now();
  Answer answer = execute(*goal.getGoal());
  answer.result.planning_time = (ros::WallTime::now() - start).toSec();
  {
    std::lock_guard<std::mutex> lock(goal_mutex_);
    running_.reset();
  }
  const Result& r = answer.result;
  switch (answer.terminal) {
    case Terminal::kSucceeded: goal.setSucceeded(r, r.error_message); break;
    case Terminal::kCanceled: goal.setCanceled(r, r.error_message); break;
    case Terminal::kAborted: goal.setAborted(r, r.error_message); break;
  }
  if (!answer.planned) return;
  // Visualisation after the answer, so it does not delay the caller.
  try {
    MarkerOptions options;
    options.frame_id = config_.planning_frame;
    options.stamp = answer.stamp;
    options.max_candidates = config_.marker_candidates;
    options.text_count = config_.marker_text_count;
    options.gripper = config_.planner.gripper.get();
    marker_pub_.publish(buildMarkers(answer.prepared.object_O, answer.prepared.area_W, answer.plan, options));
    geometry_msgs::PoseArray poses;
    poses.header.frame_id = config_.planning_frame;
    poses.header.stamp = answer.stamp;
    for (const auto& c : r.candidates) poses.poses.push_back(c.pose.pose);
    candidates_pub_.publish(poses);
  } catch (const std::exception& e) {
    ROS_ERROR("place_planner: markers of the last goal failed: %s", e.what());
  }
}

Eigen::Isometry3d PlacePlannerNode::lookup(const std::string& frame) const {
  return tf2::transformToEigen(tf_buffer_.lookupTransform(
      config_.planning_frame, frame, ros::Time(0), ros::Duration(config_.tf_timeout)));
}

PlacePlannerNode::Answer PlacePlannerNode::execute(const PlacePlanGoal& goal) {
  Answer answer;
  Result& result = answer.result;
  try {
    plan(goal, &answer);
  } catch (const GoalError& e) {
    result = Result();
    result.error_code = e.code;
    result.error_message = e.what();
    answer.terminal = Terminal::kAborted;
    answer.planned = false;
    ROS_WARN("place_planner: goal rejected, %s: %s", errorCodeName(e.code), e.what());
  } catch (const std::exception& e) {
    // Not expected for a validated goal (a CUDA error, std::bad_alloc): this goal fails, the
    // node serves on.
    result = Result();
    result.error_code = Result::INTERNAL_ERROR;
    result.error_message = std::string("internal error: ") + e.what();
    answer.terminal = Terminal::kAborted;
    answer.planned = false;
    ROS_ERROR("place_planner: %s", result.error_message.c_str());
  } catch (...) {
    result = Result();
    result.error_code = Result::INTERNAL_ERROR;
    result.error_message = "internal error: an exception that is not a std::exception";
    answer.terminal = Terminal::kAborted;
    answer.planned = false;
    ROS_ERROR("place_planner: %s", result.error_message.c_str());
  }
  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    planning_ = false;
  }
  return answer;
}

void PlacePlannerNode::plan(const PlacePlanGoal& goal, Answer* answer) {
  TopicMeshes topics;
  {
    std::lock_guard<std::mutex> lock(mesh_mutex_);
    topics.object = latest_object_;
    topics.area = latest_area_;
    topics.object_shape = latest_object_shape_;
    topics.area_shape = latest_area_shape_;
  }
  topics.object_topic = object_sub_.getTopic();
  topics.area_topic = area_sub_.getTopic();
  topics.object_shape_topic = object_shape_sub_.getTopic();
  topics.area_shape_topic = area_shape_sub_.getTopic();
  int objects = 0;
  Mesh added = areaAdditions(goal, placed_, &objects);
  // The planner parameters as tuned when this goal starts (dynamic_reconfigure).
  NodeConfig goal_config = config_;
  {
    std::lock_guard<std::mutex> lock(tuning_mutex_);
    goal_config.planner = tuned_planner_;
  }
  answer->prepared =
      prepareGoal(goal, topics, goal_config, [this](const std::string& f) { return lookup(f); }, &added);
  // The goal is valid: its reset/add stands, whatever the plan comes to.
  placed_.added_W = std::move(added);
  placed_.count = objects;
  const PreparedGoal& prepared = answer->prepared;

  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    planning_ = true;
    progress_ = Progress();
    plan_start_ = last_feedback_ = ros::WallTime::now();
  }
  PlanResult& plan = answer->plan;
  try {
    plan = planner_.plan(prepared.object_O, prepared.area_W, prepared.config,
                         [this](const Progress& p) { return onProgress(p); });
  } catch (const LimitError& e) {
    // A mesh beyond the bounded-work limits (max_object_size, max_model_mb, ...): the input's.
    throw GoalError(Result::INVALID_MESH, e.what());
  } catch (const std::exception& e) {
    // Whatever the planner throws for a goal prepareGoal accepted is the planner's failure.
    throw std::runtime_error(std::string("planner failed: ") + e.what());
  }
  answer->planned = true;
  // Which backend `auto` chose, and why: said once in the log, not as a warning.
  if (!plan.stats.backend_note.empty()) ROS_INFO_ONCE("place_planner: %s", plan.stats.backend_note.c_str());
  placed_.has_last_plan = true;
  placed_.last_object_O = prepared.object_O;
  placed_.last_X_WO.clear();
  for (const Candidate& c : plan.candidates) placed_.last_X_WO.push_back(c.X_WO);
  // Warnings about the gripper explain a NO_STABLE_POSE: they go into its message.
  std::string gripper_warnings;
  for (const auto& w : plan.warnings) {
    ROS_WARN("place_planner: %s", w.c_str());
    if (w.find("gripper") != std::string::npos) gripper_warnings += w + "; ";
  }

  // Physics check of the best K stable candidates, in what is left of the budget; not for a
  // cancelled goal, and a cancel stops it starting further checks.
  std::string physics_summary;
  if (prepared.verify_top_k > 0 && !plan.cancelled && plan.stableCount() > 0) {
    try {
      const validation::VerifyStats v = validation::verifyTopK(
          prepared.object_O, prepared.area_W, prepared.config, plan, prepared.verify_top_k,
          validation::remainingBudgetMs(prepared.config.time_budget_ms, plan.stats.total_ms),
          prepared.config.threads, [this] { return ros::ok() && !preempt_requested_; },
          validation::enginesFromString(config_.verify_engines));
      std::ostringstream os;
      os << "; physics (" << config_.verify_engines << "): " << v.stayed << " of " << v.checked << " checked stayed ("
         << v.selected - v.checked << " not checked, " << v.total_ms << " ms)";
      physics_summary = os.str();
    } catch (const std::exception& e) {
      // The plan stands; the candidates stay unchecked.
      ROS_ERROR("place_planner: physics check failed: %s", e.what());
      physics_summary = std::string("; physics check failed: ") + e.what();
    }
  }

  Result& result = answer->result;
  answer->stamp = ros::Time::now();
  result.candidates.resize(plan.candidates.size());
  const std::string gripper_frame = config_.planner.gripper ? config_.planner.gripper->links.front() : "";
  for (size_t i = 0; i < plan.candidates.size(); ++i) {
    toMsg(plan.candidates[i], config_.planning_frame, gripper_frame, answer->stamp, &result.candidates[i]);
  }
  result.floor_points_evaluated = plan.stats.floor_points_done;
  result.hanging_starts_evaluated = plan.stats.hanging_starts_done;
  result.trees_without_rest = plan.stats.trees_without_rest;
  result.gripper_rejected = plan.stats.gripper_rejected;
  result.gripper_tilt_rejected = plan.stats.gripper_tilt_rejected;
  result.unseen_withheld = plan.stats.unseen_withheld;
  result.objects_in_area = placed_.count;
  result.partial = false;
  const int n_stable = plan.stableCount();
  std::ostringstream summary;
  summary << plan.candidates.size() << " candidates (" << n_stable << " stable) from " << searchedRoots(plan.stats);
  summary << " in " << (ros::WallTime::now() - plan_start_).toSec() << " s"
          << physics_summary;
  if (plan.stats.unseen_withheld > 0)
    summary << "; " << plan.stats.unseen_withheld << " poses on unseen surface withheld (a pose on seen surface holds)";
  if (prepared.config.has_grasp) {
    summary << "; gripper: " << plan.stats.gripper_rejected << " candidates blocked, "
            << plan.stats.gripper_tilt_rejected << " poses tilted over max_gripper_tilt_deg";
  }
  std::ostringstream budget;
  budget << "time budget of " << prepared.config.time_budget_ms / 1000.0 << " s used up";
  // PlanResult::outcome() decides; the codes keep their numbers.
  switch (plan.outcome()) {
    case PlanOutcome::kCancelled: {
      // How long the planner took to stop: what a caller waits for after its cancel.
      ros::WallTime asked;
      {
        std::lock_guard<std::mutex> lock(goal_mutex_);
        asked = preempt_time_;
      }
      if (!asked.isZero()) {
        summary << "; stopped " << static_cast<int>(1e3 * (ros::WallTime::now() - asked).toSec() + 0.5)
                << " ms after the cancel or newer goal";
      }
      result.error_code = Result::PREEMPTED;
      result.error_message = "preempted: " + summary.str();
      answer->terminal = Terminal::kCanceled;
      break;
    }
    case PlanOutcome::kTimedOutWithStable:
      // A partial answer is still an answer: SUCCESS, flagged.
      result.error_code = Result::SUCCESS;
      result.partial = true;
      result.error_message = "partial answer: " + budget.str() +
                             ", the stable candidates found so far: " + summary.str();
      answer->terminal = Terminal::kSucceeded;
      break;
    case PlanOutcome::kTimedOutNone:
      result.error_code = Result::TIMED_OUT;
      result.error_message = budget.str() + " before any stable pose: " + summary.str();
      answer->terminal = Terminal::kAborted;
      break;
    case PlanOutcome::kNoStable:
      result.error_code = Result::NO_STABLE_POSE;
      result.error_message = "no stable pose: " + gripper_warnings + summary.str();
      answer->terminal = Terminal::kAborted;
      break;
    case PlanOutcome::kStable:
      result.error_code = Result::SUCCESS;
      result.error_message = "";
      answer->terminal = Terminal::kSucceeded;
      break;
  }
  ROS_INFO("place_planner: %s%s, %s", errorCodeName(result.error_code), result.partial ? " (partial)" : "",
           summary.str().c_str());
}

void PlacePlannerNode::onReconfigure(PlacePlannerConfig& tuning, uint32_t /*level*/) {
  tuning.__toServer__(pnh_);
  try {
    NodeConfig fresh = loadNodeConfig(pnh_);
    fresh.planner.gripper = config_.planner.gripper;  // startup-only (not in the .cfg)
    {
      std::lock_guard<std::mutex> lock(tuning_mutex_);
      tuned_planner_ = fresh.planner;
    }
    if (tuned_once_) ROS_INFO("place_planner: planner parameters updated (dynamic_reconfigure): the next goal uses them");
    last_tuning_ = tuning;
    tuned_once_ = true;
  } catch (const std::exception& e) {
    ROS_ERROR("place_planner: dynamic_reconfigure refused: %s; the previous values are kept", e.what());
    if (tuned_once_) {
      last_tuning_.__toServer__(pnh_);
      tuning = last_tuning_;
    }
  }
}

bool PlacePlannerNode::onProgress(const Progress& progress) {
  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    progress_ = progress;
  }
  publishFeedback(progress);
  return ros::ok() && !preempt_requested_;
}

void PlacePlannerNode::onFeedbackTimer() {
  Progress progress;
  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    if (!planning_) return;
    progress = progress_;
  }
  publishFeedback(progress);
}

void PlacePlannerNode::publishFeedback(const Progress& progress) {
  PlacePlanFeedback feedback;
  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    const ros::WallTime now = ros::WallTime::now();
    if (!planning_ || (now - last_feedback_).toSec() < config_.feedback_period) return;
    last_feedback_ = now;
    toMsg(progress, &feedback);
    // Between two core callbacks the clock still moves on.
    feedback.elapsed_time = (now - plan_start_).toSec();
  }
  std::optional<GoalHandle> running;
  {
    std::lock_guard<std::mutex> lock(goal_mutex_);
    running = running_;
  }
  if (running) running->publishFeedback(feedback);
}

}  // namespace place_planner
