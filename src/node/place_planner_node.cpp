#include "place_planner/ros/place_planner_node.h"

#include <geometry_msgs/PoseArray.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "place_planner/ros/conversions.h"
#include "place_planner/ros/markers.h"
#include "place_planner/validation/physics_validator.h"

namespace place_planner {
namespace {

using Result = PlacePlanResult;

// A goal that cannot be planned: the error code and the message the caller gets.
struct GoalError : std::runtime_error {
  GoalError(uint8_t c, const std::string& what) : std::runtime_error(what), code(c) {}
  uint8_t code;
};

// Tolerance on |q| - 1 for quaternions in the goal; beyond it the goal is rejected rather than
// silently normalised. A zero quaternion (an unset message field) is read as identity.
constexpr double kUnitQuaternionTolerance = 1e-3;

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

const char* codeName(uint8_t code) {
  switch (code) {
    case Result::SUCCESS: return "SUCCESS";
    case Result::NO_STABLE_POSE: return "NO_STABLE_POSE";
    case Result::INVALID_MESH: return "INVALID_MESH";
    case Result::NO_MESH: return "NO_MESH";
    case Result::TF_ERROR: return "TF_ERROR";
    case Result::INVALID_GOAL: return "INVALID_GOAL";
    case Result::PREEMPTED: return "PREEMPTED";
    case Result::TIMED_OUT: return "TIMED_OUT";
    default: return "UNKNOWN";
  }
}

}  // namespace

struct PlacePlannerNode::Prepared {
  Mesh object_O;  // in the object's mesh frame O
  Mesh area_W;    // in the planning frame
  PlannerConfig config;
  int verify_top_k = 0;  // Bullet check of the best K stable candidates (0 = off)
  bool has_grasp = false;
  Eigen::Isometry3d X_OG = Eigen::Isometry3d::Identity();
};

PlacePlannerNode::PlacePlannerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), pnh_(pnh), config_(loadNodeConfig(pnh)), tf_listener_(tf_buffer_) {
  object_sub_ = nh_.subscribe<pcl_msgs::PolygonMesh>(
      "object_mesh", 1, [this](const pcl_msgs::PolygonMeshConstPtr& m) {
        std::lock_guard<std::mutex> lock(mesh_mutex_);
        latest_object_ = m;
      });
  area_sub_ = nh_.subscribe<pcl_msgs::PolygonMesh>(
      "placement_area_mesh", 1, [this](const pcl_msgs::PolygonMeshConstPtr& m) {
        std::lock_guard<std::mutex> lock(mesh_mutex_);
        latest_area_ = m;
      });
  marker_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  candidates_pub_ = pnh_.advertise<geometry_msgs::PoseArray>("candidates", 1, true);
  feedback_timer_ = nh_.createWallTimer(ros::WallDuration(config_.feedback_period / 2),
                                        [this](const ros::WallTimerEvent&) { onFeedbackTimer(); });
  server_ = std::make_unique<actionlib::SimpleActionServer<PlacePlanAction>>(
      pnh_, "place_plan", [this](const PlacePlanGoalConstPtr& g) { execute(g); }, false);
  server_->start();
  ROS_INFO("place_planner: serving %s/place_plan, planning frame '%s'",
           pnh_.getNamespace().c_str(), config_.planning_frame.c_str());
}

Eigen::Isometry3d PlacePlannerNode::lookup(const std::string& frame, const std::string& what) const {
  if (frame.empty() || frame == config_.planning_frame) return Eigen::Isometry3d::Identity();
  try {
    return tf2::transformToEigen(tf_buffer_.lookupTransform(
        config_.planning_frame, frame, ros::Time(0), ros::Duration(config_.tf_timeout)));
  } catch (const tf2::TransformException& e) {
    throw GoalError(Result::TF_ERROR, what + ": no transform from frame '" + frame +
                                          "' to planning frame '" + config_.planning_frame +
                                          "' (" + e.what() + ")");
  }
}

PlacePlannerNode::Prepared PlacePlannerNode::prepare(const PlacePlanGoal& goal) {
  Prepared out;
  // Meshes: the goal's, or the latest from the topics.
  pcl_msgs::PolygonMeshConstPtr object_msg, area_msg;
  {
    std::lock_guard<std::mutex> lock(mesh_mutex_);
    object_msg = latest_object_;
    area_msg = latest_area_;
  }
  const pcl_msgs::PolygonMesh* object = &goal.object_mesh;
  const pcl_msgs::PolygonMesh* area = &goal.placement_area_mesh;
  if (object->polygons.empty()) {
    if (!object_msg) {
      throw GoalError(Result::NO_MESH, "object mesh: the goal's object_mesh is empty and nothing "
                                       "was received on " + object_sub_.getTopic());
    }
    object = object_msg.get();
  }
  if (area->polygons.empty()) {
    if (!area_msg) {
      throw GoalError(Result::NO_MESH, "placement area mesh: the goal's placement_area_mesh is "
                                       "empty and nothing was received on " + area_sub_.getTopic());
    }
    area = area_msg.get();
  }

  // Frames. X_WO: where the object's mesh frame is now.
  const Eigen::Isometry3d X_WF = lookup(goal.object_pose.header.frame_id, "object_pose");
  const Eigen::Isometry3d X_WO = X_WF * poseFromGoal(goal.object_pose.pose, "object_pose.pose");
  const Eigen::Isometry3d X_WA = lookup(area->header.frame_id, "placement area mesh");
  // Object vertices are in header.frame_id M when set, else in O.
  const Eigen::Isometry3d X_OM = object->header.frame_id.empty()
                                     ? Eigen::Isometry3d::Identity()
                                     : Eigen::Isometry3d(X_WO.inverse() *
                                                         lookup(object->header.frame_id, "object mesh"));

  // Validated in the frame they came in (so an index or coordinate in a message names the element
  // as sent), then mapped.
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> polygons;
  try {
    fromMsg(*object, "object mesh", &vertices, &polygons);
    out.object_O = mappedBy(buildMesh(vertices, polygons, "object mesh"), X_OM);
    fromMsg(*area, "placement area mesh", &vertices, &polygons);
    out.area_W = mappedBy(buildMesh(vertices, polygons, "placement area mesh"), X_WA);
  } catch (const MeshError& e) {
    throw GoalError(Result::INVALID_MESH, e.what());
  }

  // Config: the parameters, overridden by the goal's non-zero fields.
  PlannerConfig& c = out.config;
  c = config_.planner;
  // Orientation "keep" starts from the object's current orientation; the others turn it least.
  c.start_orientation = Eigen::Quaterniond(X_WO.rotation());
  const auto direction = [&](const geometry_msgs::Vector3Stamped& v, const char* field,
                             Eigen::Vector3d* value) {
    const Eigen::Vector3d d = fromMsg(v.vector);
    if (!d.allFinite()) throw GoalError(Result::INVALID_GOAL, std::string(field) + " is not finite");
    if (d.norm() == 0.0) return;
    *value = lookup(v.header.frame_id, field).rotation() * d;
  };
  direction(goal.gravity, "gravity", &c.gravity);
  direction(goal.approach, "approach", &c.approach);
  if (goal.friction != 0) c.friction = goal.friction;
  if (goal.floor_point_spacing != 0) c.floor_point_spacing = goal.floor_point_spacing;
  if (goal.max_rotations != 0) c.max_rotations = goal.max_rotations;
  if (goal.max_candidates != 0) c.max_candidates = goal.max_candidates;
  if (goal.min_quality != 0) c.min_quality = goal.min_quality;
  if (goal.time_budget != 0) c.time_budget_ms = goal.time_budget * 1000.0;
  out.verify_top_k = goal.verify_top_k == 0 ? config_.verify_top_k : std::max(0, goal.verify_top_k);
  if (out.verify_top_k > 100) {
    throw GoalError(Result::INVALID_GOAL, "goal: verify_top_k = " + std::to_string(goal.verify_top_k) +
                                              " is out of range (<= 100; 0 = parameter, < 0 = off)");
  }
  try {
    if (!goal.orientation_mode.empty()) c.orientation = orientationModeFromString(goal.orientation_mode);
    validate(c);  // names the field: "friction = -1 is out of range (...)"
  } catch (const std::invalid_argument& e) {
    throw GoalError(Result::INVALID_GOAL, std::string("goal: ") + e.what());
  }
  if (goal.has_region) {
    // The region box is axis-aligned in its own frame: the planning frame gets the axis-aligned
    // box around its 8 transformed corners.
    const Eigen::Isometry3d X_WR = lookup(goal.region_min.header.frame_id, "region_min");
    if (goal.region_max.header.frame_id != goal.region_min.header.frame_id) {
      throw GoalError(Result::INVALID_GOAL, "region_min is in frame '" + goal.region_min.header.frame_id +
                                                "' but region_max in '" +
                                                goal.region_max.header.frame_id + "'");
    }
    const Eigen::Vector3d lo = fromMsg(goal.region_min.point), hi = fromMsg(goal.region_max.point);
    if (!lo.allFinite() || !hi.allFinite() || (lo.array() > hi.array()).any()) {
      throw GoalError(Result::INVALID_GOAL, "region_min must be finite and <= region_max");
    }
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
  }
  return out;
}

void PlacePlannerNode::execute(const PlacePlanGoalConstPtr& goal) {
  const ros::WallTime start = ros::WallTime::now();
  Result result;
  Prepared prepared;
  try {
    prepared = prepare(*goal);
  } catch (const GoalError& e) {
    result.error_code = e.code;
    result.error_message = e.what();
    result.planning_time = (ros::WallTime::now() - start).toSec();
    ROS_WARN("place_planner: goal rejected, %s: %s", codeName(e.code), e.what());
    server_->setAborted(result, result.error_message);
    return;
  }

  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    planning_ = true;
    progress_ = Progress();
    plan_start_ = last_feedback_ = ros::WallTime::now();
  }
  PlanResult plan;
  std::string failure;
  try {
    plan = planner_.plan(prepared.object_O, prepared.area_W, prepared.config,
                         [this](const Progress& p) { return onProgress(p); });
  } catch (const std::exception& e) {
    failure = e.what();
  }
  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    planning_ = false;
  }
  if (!failure.empty()) {
    // Not expected for a validated goal (e.g. a CUDA error): the goal fails, the node serves on.
    result.error_code = Result::INVALID_GOAL;
    result.error_message = "planner failed: " + failure;
    result.planning_time = (ros::WallTime::now() - start).toSec();
    ROS_ERROR("place_planner: %s", result.error_message.c_str());
    server_->setAborted(result, result.error_message);
    return;
  }
  for (const auto& w : plan.warnings) ROS_WARN("place_planner: %s", w.c_str());

  // Physics check of the best K stable candidates, in what is left of the budget; not for a
  // cancelled goal, and a cancel stops it starting further checks.
  std::string physics_summary;
  if (prepared.verify_top_k > 0 && !plan.cancelled && plan.stableCount() > 0) {
    try {
      const validation::VerifyStats v = validation::verifyTopK(
          prepared.object_O, prepared.area_W, prepared.config, plan, prepared.verify_top_k,
          validation::remainingBudgetMs(prepared.config.time_budget_ms, plan.stats.total_ms),
          prepared.config.threads, [this] { return ros::ok() && !server_->isPreemptRequested(); });
      std::ostringstream os;
      os << "; physics: " << v.stayed << " of " << v.checked << " checked stayed ("
         << v.selected - v.checked << " not checked, " << v.total_ms << " ms)";
      physics_summary = os.str();
    } catch (const std::exception& e) {
      // The plan stands; the candidates stay unchecked.
      ROS_ERROR("place_planner: physics check failed: %s", e.what());
      physics_summary = std::string("; physics check failed: ") + e.what();
    }
  }

  const ros::Time stamp = ros::Time::now();
  result.candidates.resize(plan.candidates.size());
  for (size_t i = 0; i < plan.candidates.size(); ++i) {
    toMsg(plan.candidates[i], config_.planning_frame, stamp,
          prepared.has_grasp ? &prepared.X_OG : nullptr, &result.candidates[i]);
  }
  result.floor_points_evaluated = plan.stats.floor_points_done;
  result.planning_time = (ros::WallTime::now() - start).toSec();
  result.partial = false;
  const int n_stable = plan.stableCount();
  std::ostringstream summary;
  summary << plan.candidates.size() << " candidates (" << n_stable << " stable) from "
          << plan.stats.floor_points_done << " of " << plan.stats.floor_points_total
          << " floor points in " << result.planning_time << " s" << physics_summary;
  const std::string budget =
      "time budget of " + std::to_string(prepared.config.time_budget_ms / 1000.0) + " s used up";
  // PlanResult::outcome() decides; the codes keep their numbers.
  switch (plan.outcome()) {
    case PlanOutcome::kCancelled:
      result.error_code = Result::PREEMPTED;
      result.error_message = "preempted: " + summary.str();
      server_->setPreempted(result, result.error_message);
      break;
    case PlanOutcome::kTimedOutWithStable:
      // A partial answer is still an answer: SUCCESS, flagged.
      result.error_code = Result::SUCCESS;
      result.partial = true;
      result.error_message = "partial answer: " + budget + ", the stable candidates found so far: " +
                             summary.str();
      server_->setSucceeded(result, result.error_message);
      break;
    case PlanOutcome::kTimedOutNone:
      result.error_code = Result::TIMED_OUT;
      result.error_message = budget + " before any stable pose: " + summary.str();
      server_->setAborted(result, result.error_message);
      break;
    case PlanOutcome::kNoStable:
      result.error_code = Result::NO_STABLE_POSE;
      result.error_message = "no stable pose: " + summary.str();
      server_->setAborted(result, result.error_message);
      break;
    case PlanOutcome::kStable:
      result.error_code = Result::SUCCESS;
      result.error_message = "";
      server_->setSucceeded(result, summary.str());
      break;
  }
  ROS_INFO("place_planner: %s%s, %s", codeName(result.error_code), result.partial ? " (partial)" : "",
           summary.str().c_str());

  // Visualisation after the answer, so it does not delay the caller.
  MarkerOptions options;
  options.frame_id = config_.planning_frame;
  options.stamp = stamp;
  options.max_candidates = config_.marker_candidates;
  options.text_count = config_.marker_text_count;
  marker_pub_.publish(buildMarkers(prepared.object_O, prepared.area_W, plan, options));
  geometry_msgs::PoseArray poses;
  poses.header.frame_id = config_.planning_frame;
  poses.header.stamp = stamp;
  for (const auto& c : result.candidates) poses.poses.push_back(c.pose.pose);
  candidates_pub_.publish(poses);
}

bool PlacePlannerNode::onProgress(const Progress& progress) {
  {
    std::lock_guard<std::mutex> lock(feedback_mutex_);
    progress_ = progress;
  }
  publishFeedback(progress);
  return ros::ok() && !server_->isPreemptRequested();
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
  server_->publishFeedback(feedback);
}

}  // namespace place_planner
