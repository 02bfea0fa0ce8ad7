// Sends one PlacePlan goal (meshes from the topics) and prints the ranked result.
// Private parameters: action (default /place_planner/place_plan), frame (world), object_x,
// object_y, object_z (where the object's mesh frame is now, m), orientation_mode (""),
// floor_point_spacing (0 = node default), max_candidates (0 = node default), print (5 rows),
// timeout (s), report_file (optional: the printed report is also written there, and its last
// line is "status N" with the exit status, since roslaunch reports neither).
// Exit status 0 when the answer is SUCCESS with a stable best candidate.
#include <actionlib/client/simple_action_client.h>
#include <ros/ros.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "place_planner/PlacePlanAction.h"
#include "place_planner/infra/output_file.h"
#include "place_planner/ros/conversions.h"

namespace {

const char* codeName(int code) {
  using R = place_planner::PlacePlanResult;
  switch (code) {
    case R::SUCCESS: return "SUCCESS";
    case R::NO_STABLE_POSE: return "NO_STABLE_POSE";
    case R::INVALID_MESH: return "INVALID_MESH";
    case R::NO_MESH: return "NO_MESH";
    case R::TF_ERROR: return "TF_ERROR";
    case R::INVALID_GOAL: return "INVALID_GOAL";
    case R::PREEMPTED: return "PREEMPTED";
    case R::TIMED_OUT: return "TIMED_OUT";
    case R::INTERNAL_ERROR: return "INTERNAL_ERROR";
    default: return "UNKNOWN";
  }
}

// printf into the report (stdout and, later, the report file).
std::string g_report;
template <typename... Args>
void report(const char* format, Args... args) {
  std::string text(std::snprintf(nullptr, 0, format, args...) + 1, '\0');
  std::snprintf(text.data(), text.size(), format, args...);
  text.pop_back();
  std::fputs(text.c_str(), stdout);
  g_report += text;
}

int run(ros::NodeHandle& pnh) {
  std::string action = "/place_planner/place_plan", frame = "world", mode;
  double x = 0, y = 0, z = 0.5, spacing = 0, timeout = 60;
  int max_candidates = 0, rows = 5;
  pnh.param("action", action, action);
  pnh.param("frame", frame, frame);
  pnh.param("object_x", x, x);
  pnh.param("object_y", y, y);
  pnh.param("object_z", z, z);
  pnh.param("orientation_mode", mode, mode);
  pnh.param("floor_point_spacing", spacing, spacing);
  pnh.param("max_candidates", max_candidates, max_candidates);
  pnh.param("print", rows, rows);
  pnh.param("timeout", timeout, timeout);

  actionlib::SimpleActionClient<place_planner::PlacePlanAction> client(action, true);
  if (!client.waitForServer(ros::Duration(timeout))) {
    report("demo_client: no action server %s\n", action.c_str());
    return 1;
  }
  place_planner::PlacePlanGoal goal;
  goal.object_pose.header.frame_id = frame;
  goal.object_pose.pose.position.x = x;
  goal.object_pose.pose.position.y = y;
  goal.object_pose.pose.position.z = z;
  goal.object_pose.pose.orientation.w = 1.0;
  goal.orientation_mode = mode;
  goal.floor_point_spacing = spacing;
  goal.max_candidates = max_candidates;

  // The node may not have the bag's meshes yet: NO_MESH is retried for a few seconds.
  place_planner::PlacePlanResultConstPtr result;
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(10.0);
  for (;;) {
    client.sendGoal(goal);
    if (!client.waitForResult(ros::Duration(timeout))) {
      client.cancelGoal();
      report("demo_client: no result within %.0f s\n", timeout);
      return 1;
    }
    result = client.getResult();
    if (result->error_code != place_planner::PlacePlanResult::NO_MESH || ros::WallTime::now() > give_up) break;
    ros::WallDuration(0.5).sleep();
  }

  report("\nplace_planner: %s in %.3f s, %d floor points evaluated, %zu candidates%s%s\n",
              codeName(result->error_code), result->planning_time, result->floor_points_evaluated,
              result->candidates.size(), result->error_message.empty() ? "" : "\n  ",
              result->error_message.c_str());
  if (!result->candidates.empty()) {
    report("rank  Q      stable  position in %s (m)        roll/pitch/yaw (deg)     contacts\n",
                frame.c_str());
  }
  for (size_t i = 0; i < result->candidates.size() && static_cast<int>(i) < rows; ++i) {
    const auto& c = result->candidates[i];
    const Eigen::Isometry3d X = place_planner::fromMsg(c.pose.pose);
    // Fixed-axis roll, pitch, yaw (as tf2's getRPY), in (-180, 180].
    const Eigen::Matrix3d R = X.rotation();
    const double deg = 180.0 / M_PI;
    const Eigen::Vector3d ypr(std::atan2(R(1, 0), R(0, 0)) * deg,
                              std::asin(std::clamp(-R(2, 0), -1.0, 1.0)) * deg,
                              std::atan2(R(2, 1), R(2, 2)) * deg);
    const Eigen::Vector3d p = X.translation();
    report("#%-3zu  %.3f  %-6s  (%7.3f, %7.3f, %7.3f)   (%6.1f, %6.1f, %6.1f)   %zu\n", i + 1,
                c.quality, c.stable ? "yes" : "no", p.x(), p.y(), p.z(), ypr[2] + 0.0,
                ypr[1] + 0.0, ypr[0] + 0.0,  // + 0.0: no "-0.0"
                c.contact_points.size());
  }
  std::fflush(stdout);
  const bool ok = result->error_code == place_planner::PlacePlanResult::SUCCESS &&
                  !result->candidates.empty() && result->candidates.front().stable;
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "demo_client");
  ros::NodeHandle pnh("~");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const int status = run(pnh);
  std::string report_file;
  if (pnh.getParam("report_file", report_file) && !report_file.empty()) {
    std::ostringstream report;
    report << g_report << "status " << status << "\n";
    place_planner::writeOutputFile(report_file, report.str());
  }
  return status;
}
