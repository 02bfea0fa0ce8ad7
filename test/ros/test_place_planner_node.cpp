// rostest of the place_planner node (test/ros/place_planner_node.test): every test sends real
// goals through actionlib and checks the answer's geometry, not only that something came back.
// Frames: W = world (the node's planning frame), S = sensor (a static transform this test
// broadcasts), O = the object's mesh frame.
#include <actionlib/client/action_client.h>
#include <actionlib/client/simple_action_client.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <shape_msgs/Mesh.h>
#include <visualization_msgs/MarkerArray.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <set>

#include "place_planner/PlacePlanAction.h"
#include "place_planner/ros/conversions.h"
#include "place_planner/ros/markers.h"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/ros/params.h"
#include "place_planner/infra/scenes.h"

namespace place_planner {
namespace {

using Client = actionlib::SimpleActionClient<PlacePlanAction>;
using Result = PlacePlanResult;

constexpr char kAction[] = "/place_planner/place_plan";
// Test 2 and the issue: the same scene given in another frame gives the same answer to 1 mm.
constexpr double kSameAnswer = 1e-3;
// Q of the same pose from the same scene in another frame: float32 vertices and the sphere
// model's sampling move it by up to 0.011 (measured).
constexpr double kSameQuality = 0.03;
// Poses copied or composed in double precision: only rounding separates them.
constexpr double kExact = 1e-6;
// A vertex resting on the area (the planner's contact tolerance is well below this).
constexpr double kOnSurface = 2e-3;
// Cancel (or a newer goal) must end the running goal within 0.5 s, measured at the
// client on this 2-core machine while others build on it; measured: about 10 ms.
constexpr double kCancelLatency = 0.5;
// Feedback is promised every 100 ms, between the planner's batched steps; allow scheduling
// jitter on a loaded 2-core CI machine. Measured: largest gaps 75-83 ms alone, 100-214 ms with
// another test running beside it (run_tests -j2).
constexpr double kFeedbackGap = 0.3;
// sizeof(PlannerConfig) when the YAML was last brought in line with it (x86-64, g++ 12).
constexpr size_t kPlannerConfigSize = 624;

// The scene of the quick goals: a box on a 0.4 x 0.3 m plane at z = 0.
Mesh testArea() { return scenes::plane(0.4, 0.3); }
Mesh testObject() { return scenes::box(0.08, 0.06, 0.04); }
// The scene of the long goals: the table with a 1 cm floor point grid.
Mesh longArea() { return scenes::table(); }

// Where the object's mesh frame is now (in W): above the area, turned about z.
Eigen::Isometry3d X_WO_start() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translate(Eigen::Vector3d(0.05, 0.02, 0.4));
  X.rotate(Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()));
  return X;
}

// The sensor frame: pose of S in W, broadcast as a static transform by main().
Eigen::Isometry3d X_WS() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translate(Eigen::Vector3d(0.3, -0.2, 0.7));
  X.rotate(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, -0.5).normalized()));
  return X;
}

Mesh mapped(const Mesh& m, const Eigen::Isometry3d& X) { return transformed(m, X.rotation(), X.translation()); }

pcl_msgs::PolygonMesh meshMsg(const Mesh& mesh, const std::string& frame) {
  pcl_msgs::PolygonMesh msg;
  toMsg(mesh, frame, &msg);
  return msg;
}

PlacePlanGoal quickGoal() {
  PlacePlanGoal goal;
  goal.object_pose.header.frame_id = "world";
  toMsg(X_WO_start(), &goal.object_pose.pose);
  goal.max_candidates = 1000;  // all of them: test 2 compares the whole answer
  return goal;
}

PlacePlanGoal longGoal() {
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(longArea(), "world");
  goal.floor_point_spacing = 0.01;
  goal.max_candidates = 10;
  return goal;
}

// A quick goal with inline meshes (for a node that has no topic meshes).
PlacePlanGoal boxOnPlaneGoalForCuda() {
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(testArea(), "world");
  return goal;
}

struct Answer {
  actionlib::SimpleClientGoalState state{actionlib::SimpleClientGoalState::LOST};
  Result result;
};

Client& client() {
  static Client c(kAction, true);
  return c;
}

Answer send(const PlacePlanGoal& goal, double timeout = 60.0) {
  Client& c = client();
  EXPECT_TRUE(c.waitForServer(ros::Duration(30.0)));
  c.sendGoal(goal);
  Answer a;
  if (!c.waitForResult(ros::Duration(timeout))) {
    ADD_FAILURE() << "no result within " << timeout << " s";
    c.cancelGoal();
    return a;
  }
  a.state = c.getState();
  a.result = *c.getResult();
  return a;
}

double distance(const geometry_msgs::Pose& a, const geometry_msgs::Pose& b) {
  return (fromMsg(a).translation() - fromMsg(b).translation()).norm();
}
double angle(const geometry_msgs::Pose& a, const geometry_msgs::Pose& b) {
  return Eigen::AngleAxisd(fromMsg(a).rotation().transpose() * fromMsg(b).rotation()).angle();
}

// The same set of candidates in two answers (ties in Q may order them differently): each has a
// twin within 1 mm and 0.01 rad with the same verdict, for at least 70 % of either answer (test
// 2 says why not all).
void expectSameCandidateSets(const std::vector<PlacementCandidate>& ref,
                             const std::vector<PlacementCandidate>& got) {
  for (const auto* pair : {&ref, &got}) {
    const auto& from = *pair;
    const auto& to = pair == &ref ? got : ref;
    size_t matched = 0;
    for (const auto& c : from) {
      const PlacementCandidate* twin = nullptr;
      double best = std::numeric_limits<double>::infinity();
      for (const auto& d : to) {
        const double dist = distance(c.pose.pose, d.pose.pose);
        if (angle(c.pose.pose, d.pose.pose) < 0.01 && dist < best) best = dist, twin = &d;
      }
      if (twin && best < kSameAnswer && twin->stable == c.stable) {
        EXPECT_NEAR(twin->quality, c.quality, kSameQuality);
        ++matched;
      }
    }
    EXPECT_GE(matched, static_cast<size_t>(0.7 * from.size())) << matched << " of " << from.size();
    std::printf("[same set] %zu of %zu have a twin\n", matched, from.size());
  }
}

// The answer of test 1 (meshes from the topics); computed once, shared with test 2.
const Answer& topicAnswer() {
  static Answer answer;
  static bool done = false;
  if (done) return answer;
  ros::NodeHandle nh;
  static ros::Publisher object_pub = nh.advertise<pcl_msgs::PolygonMesh>("object_mesh", 1, true);
  static ros::Publisher area_pub = nh.advertise<pcl_msgs::PolygonMesh>("placement_area_mesh", 1, true);
  object_pub.publish(meshMsg(testObject(), ""));  // vertices in O
  area_pub.publish(meshMsg(testArea(), "world"));
  // The node may not have the latched meshes yet: NO_MESH is retried for a while.
  for (int i = 0; i < 50; ++i) {
    answer = send(quickGoal());
    if (answer.result.error_code != Result::NO_MESH) break;
    ros::WallDuration(0.1).sleep();
  }
  done = true;
  return answer;
}

// ---------------------------------------------------------------- 1
TEST(PlacePlannerNode, MeshesFromTopicsGiveStablePoseInPlanningFrame) {
  const Answer& a = topicAnswer();
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  EXPECT_EQ(a.state, actionlib::SimpleClientGoalState::SUCCEEDED);
  ASSERT_FALSE(a.result.candidates.empty());
  EXPECT_GT(a.result.floor_points_evaluated, 0);
  EXPECT_GT(a.result.planning_time, 0.0);
  std::printf("[test 1] %zu candidates, %d floor points, planning_time %.3f s\n",
              a.result.candidates.size(), a.result.floor_points_evaluated, a.result.planning_time);

  const PlacementCandidate& best = a.result.candidates.front();
  EXPECT_TRUE(best.stable);
  EXPECT_GE(best.quality, 0.3);  // the message's own threshold for stable
  EXPECT_EQ(best.pose.header.frame_id, "world");
  for (size_t i = 1; i < a.result.candidates.size(); ++i) {  // ranked
    const auto& prev = a.result.candidates[i - 1];
    const auto& c = a.result.candidates[i];
    EXPECT_TRUE(prev.stable >= c.stable);
    // Ranked by Q less at most 0.05 for re-orientation and, for a box standing on a plane, whose
    // stable poses hold every release, 0.05 for robustness among the others (ranking.h).
    if (prev.stable == c.stable) EXPECT_GE(prev.quality, c.quality - 0.1 - 1e-9);
  }

  // A box resting on the plane z = 0: a whole face down, nothing below the plane.
  const Eigen::Isometry3d X_WO = fromMsg(best.pose.pose);
  const Mesh object = testObject();
  double min_z = std::numeric_limits<double>::infinity();
  for (const auto& v : object.vertices) min_z = std::min(min_z, (X_WO * v).z());
  int down = 0;
  for (const auto& v : object.vertices) down += (X_WO * v).z() < min_z + kOnSurface;
  EXPECT_NEAR(min_z, 0.0, kOnSurface);
  EXPECT_EQ(down, 4) << "a box at rest has one face (4 vertices) on the plane";
  // Its contacts are on the plane, normals up, and inside the area.
  ASSERT_GE(best.contact_points.size(), 3u);
  for (size_t i = 0; i < best.contact_points.size(); ++i) {
    EXPECT_NEAR(best.contact_points[i].z, 0.0, kOnSurface);
    EXPECT_LE(std::abs(best.contact_points[i].x), 0.2 + kOnSurface);
    EXPECT_LE(std::abs(best.contact_points[i].y), 0.15 + kOnSurface);
    // Unit, pointing at the object (up); the sphere model tilts normals at the box's edges.
    EXPECT_NEAR(fromMsg(best.contact_normals[i]).norm(), 1.0, 1e-6);
    EXPECT_GT(best.contact_normals[i].z, 0.5);
  }
  // The path ends at the goal pose and starts above it.
  const auto& path = best.intermediate_poses;
  EXPECT_EQ(path.header.frame_id, "world");
  ASSERT_GE(path.poses.size(), 2u);
  EXPECT_LT(distance(path.poses.back(), best.pose.pose), kExact);
  EXPECT_LT(angle(path.poses.back(), best.pose.pose), kExact);
  EXPECT_GT(path.poses.front().position.z, best.pose.pose.position.z);
  // Without a grasp there is no gripper pose: flagged absent and empty, not the identity.
  for (const auto& c : a.result.candidates) {
    EXPECT_FALSE(c.has_gripper_pose);
    EXPECT_EQ(c.gripper_pose.header.frame_id, "");
    EXPECT_EQ(c.gripper_pose.pose.orientation.w, 0.0);
    EXPECT_EQ(fromMsg(c.gripper_pose.pose.position).norm(), 0.0);
  }
}

// ---------------------------------------------------------------- 2
TEST(PlacePlannerNode, InlineMeshesInTransformedFrameGiveSameAnswer) {
  const Answer& reference = topicAnswer();
  ASSERT_EQ(reference.result.error_code, Result::SUCCESS) << reference.result.error_message;

  // Everything in the sensor frame S: the area, the object's vertices and the object's pose.
  const Eigen::Isometry3d X_SW = X_WS().inverse();
  PlacePlanGoal goal = quickGoal();
  goal.placement_area_mesh = meshMsg(mapped(testArea(), X_SW), "sensor");
  goal.object_mesh = meshMsg(mapped(testObject(), X_SW * X_WO_start()), "sensor");
  goal.object_pose.header.frame_id = "sensor";
  toMsg(Eigen::Isometry3d(X_SW * X_WO_start()), &goal.object_pose.pose);
  const Answer a = send(goal);
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;

  const auto& ref = reference.result.candidates;
  const auto& got = a.result.candidates;
  ASSERT_GT(ref.size(), 5u);
  EXPECT_NEAR(static_cast<double>(got.size()), static_cast<double>(ref.size()), 0.1 * ref.size() + 1);
  EXPECT_EQ(got.front().pose.header.frame_id, "world");
  EXPECT_NEAR(got.front().quality, ref.front().quality, kSameQuality);
  // Same set of candidates (ties in Q may order them differently): each has a twin within 1 mm
  // with the same verdict. The mesh messages carry float32 points, so the frame change moves
  // vertices by ~1e-7 m, which moves Q by up to ~0.005 (the contact band of the sphere model)
  // and may turn a perturbed release that balances on the edge of holding the other way: near
  // ties in Q then merge or rank differently, and a tree that slides or swings (slip, hanging)
  // may end a few millimetres elsewhere, so up to 30 % may lack a twin (measured: 93 of 120
  // match, 100 before the slip; a wrong transform matches none).
  expectSameCandidateSets(ref, got);
  // The best candidate is an equally good placement: a stable twin in the reference.
  bool best_has_twin = false;
  for (const auto& d : ref)
    best_has_twin |= d.stable && distance(got.front().pose.pose, d.pose.pose) < kSameAnswer &&
                     angle(got.front().pose.pose, d.pose.pose) < 0.01;
  EXPECT_TRUE(got.front().stable);
  EXPECT_TRUE(best_has_twin);
}

// ---------------------------------------------------------------- 3
TEST(PlacePlannerNode, NanVertexIsInvalidMeshAndNodeKeepsServing) {
  PlacePlanGoal goal = quickGoal();
  pcl_msgs::PolygonMesh object = meshMsg(testObject(), "");
  // Vertex 5's y: cloud fields x, y, z are float32 at offsets 0, 4, 8.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&object.cloud.data[5 * object.cloud.point_step + 4], &nan, sizeof nan);
  goal.object_mesh = object;
  goal.placement_area_mesh = meshMsg(testArea(), "world");
  const Answer bad = send(goal);
  EXPECT_EQ(bad.result.error_code, Result::INVALID_MESH);
  EXPECT_EQ(bad.state, actionlib::SimpleClientGoalState::ABORTED);
  EXPECT_NE(bad.result.error_message.find("object mesh"), std::string::npos) << bad.result.error_message;
  EXPECT_NE(bad.result.error_message.find("vertex 5"), std::string::npos) << bad.result.error_message;
  EXPECT_NE(bad.result.error_message.find("y = nan"), std::string::npos) << bad.result.error_message;
  EXPECT_TRUE(bad.result.candidates.empty());

  goal.object_mesh = meshMsg(testObject(), "");
  const Answer good = send(goal);
  EXPECT_EQ(good.result.error_code, Result::SUCCESS) << good.result.error_message;
  ASSERT_FALSE(good.result.candidates.empty());
  EXPECT_TRUE(good.result.candidates.front().stable);
}

// ---------------------------------------------------------------- 4
TEST(PlacePlannerNode, MeshInUnknownFrameIsTfError) {
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(testArea(), "nowhere");
  const Answer a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::TF_ERROR);
  EXPECT_NE(a.result.error_message.find("'nowhere'"), std::string::npos) << a.result.error_message;
  EXPECT_NE(a.result.error_message.find("placement area mesh"), std::string::npos)
      << a.result.error_message;
}

// Feedback of the goal that is running, as the client sees it.
struct FeedbackLog {
  std::mutex mutex;
  std::vector<std::pair<ros::WallTime, PlacePlanFeedback>> items;
  void add(const PlacePlanFeedbackConstPtr& f) {
    std::lock_guard<std::mutex> lock(mutex);
    items.emplace_back(ros::WallTime::now(), *f);
  }
  std::vector<std::pair<ros::WallTime, PlacePlanFeedback>> copy() {
    std::lock_guard<std::mutex> lock(mutex);
    return items;
  }
};

void sendWithFeedback(const PlacePlanGoal& goal, FeedbackLog* log) {
  ASSERT_TRUE(client().waitForServer(ros::Duration(30.0)));
  client().sendGoal(goal, Client::SimpleDoneCallback(), Client::SimpleActiveCallback(),
                    [log](const PlacePlanFeedbackConstPtr& f) { log->add(f); });
}

// ---------------------------------------------------------------- 5
TEST(PlacePlannerNode, CancelEndsGoalQuicklyWithCandidatesSoFar) {
  FeedbackLog log;
  sendWithFeedback(longGoal(), &log);
  // Cancel once some candidates exist (or after 3 s at the latest).
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(3.0);
  int candidates_at_cancel = 0;
  while (ros::WallTime::now() < give_up) {
    const auto items = log.copy();
    if (!items.empty() && items.back().second.candidates_so_far > 0) {
      candidates_at_cancel = items.back().second.candidates_so_far;
      break;
    }
    ros::WallDuration(0.005).sleep();
  }
  ASSERT_EQ(client().getState(), actionlib::SimpleClientGoalState::ACTIVE)
      << "the long goal ended before it could be cancelled: make it longer";
  const ros::WallTime t0 = ros::WallTime::now();
  client().cancelGoal();
  ASSERT_TRUE(client().waitForResult(ros::Duration(5.0)));
  const double latency = (ros::WallTime::now() - t0).toSec();
  std::printf("[test 5] cancel latency %.1f ms, candidates at cancel %d\n", latency * 1e3,
              candidates_at_cancel);
  EXPECT_LT(latency, kCancelLatency);
  EXPECT_EQ(client().getState(), actionlib::SimpleClientGoalState::PREEMPTED);
  const Result r = *client().getResult();
  EXPECT_EQ(r.error_code, Result::PREEMPTED) << r.error_message;
  std::printf("[test 5] %s\n", r.error_message.c_str());
  const auto items = log.copy();
  ASSERT_FALSE(items.empty());
  EXPECT_LT(r.floor_points_evaluated, items.back().second.floor_points_total) << "it was not cut short";
  ASSERT_GT(candidates_at_cancel, 0) << "no candidate within 3 s";
  ASSERT_FALSE(r.candidates.empty());
  for (const auto& c : r.candidates) {
    EXPECT_EQ(c.pose.header.frame_id, "world");
    EXPECT_LE(c.quality, 1.0);
  }
}

// ---------------------------------------------------------------- 5b
TEST(PlacePlannerNode, NewGoalPreemptsRunningOne) {
  FeedbackLog log;
  sendWithFeedback(longGoal(), &log);
  for (int i = 0; i < 200 && log.copy().empty(); ++i) ros::WallDuration(0.01).sleep();
  ASSERT_EQ(client().getState(), actionlib::SimpleClientGoalState::ACTIVE);
  // A second caller with a quick goal.
  Client other(kAction, true);
  ASSERT_TRUE(other.waitForServer(ros::Duration(10.0)));
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(testArea(), "world");
  const ros::WallTime t0 = ros::WallTime::now();
  other.sendGoal(goal);
  ASSERT_TRUE(client().waitForResult(ros::Duration(5.0)));
  const double latency = (ros::WallTime::now() - t0).toSec();
  std::printf("[test 5b] preemption by a new goal: the running goal answered %.1f ms after it was sent\n",
              latency * 1e3);
  EXPECT_LT(latency, kCancelLatency);
  EXPECT_EQ(client().getState(), actionlib::SimpleClientGoalState::PREEMPTED);
  EXPECT_EQ(client().getResult()->error_code, Result::PREEMPTED);
  ASSERT_TRUE(other.waitForResult(ros::Duration(30.0)));
  EXPECT_EQ(other.getResult()->error_code, Result::SUCCESS) << other.getResult()->error_message;
}

// ---------------------------------------------------------------- 5c
// Goals that never run to the end never read as SUCCESS: a goal superseded while it waits
// (RECALLED) and a waiting goal that is cancelled answer PREEMPTED with a message saying so.
// (SimpleActionServer answered both with a default result: error_code 0.)
using MultiClient = actionlib::ActionClient<PlacePlanAction>;

bool waitDone(const MultiClient::GoalHandle& g, double timeout) {
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(timeout);
  while (g.getCommState() != actionlib::CommState::DONE) {
    if (ros::WallTime::now() > give_up) return false;
    ros::WallDuration(0.002).sleep();
  }
  return true;
}

TEST(PlacePlannerNode, SupersededOrCancelledWaitingGoalIsPreemptedNeverSuccess) {
  MultiClient ac(kAction);
  ASSERT_TRUE(ac.waitForActionServerToStart(ros::Duration(10.0)));
  PlacePlanGoal quick = quickGoal();
  quick.object_mesh = meshMsg(testObject(), "");
  quick.placement_area_mesh = meshMsg(testArea(), "world");
  int recalled = 0, preempted_running = 0;
  for (int round = 0; round < 5; ++round) {
    // A runs; B and C come back to back on one connection: B waits and C supersedes it (or, should
    // B have started in between, C preempts it while it runs).
    MultiClient::GoalHandle a = ac.sendGoal(longGoal());
    const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(5.0);
    while (a.getCommState() != actionlib::CommState::ACTIVE && ros::WallTime::now() < give_up) {
      ros::WallDuration(0.002).sleep();
    }
    ASSERT_EQ(a.getCommState(), actionlib::CommState::ACTIVE);
    MultiClient::GoalHandle b = ac.sendGoal(longGoal());
    MultiClient::GoalHandle c = ac.sendGoal(quick);
    ASSERT_TRUE(waitDone(a, 5.0));
    ASSERT_TRUE(waitDone(b, 5.0));
    ASSERT_TRUE(waitDone(c, 30.0));
    EXPECT_EQ(a.getTerminalState().state_, actionlib::TerminalState::PREEMPTED);
    ASSERT_TRUE(a.getResult());
    EXPECT_EQ(a.getResult()->error_code, Result::PREEMPTED);
    const auto b_state = b.getTerminalState().state_;
    ASSERT_TRUE(b.getResult());
    EXPECT_EQ(b.getResult()->error_code, Result::PREEMPTED) << b.getResult()->error_message;
    if (b_state == actionlib::TerminalState::RECALLED) {
      ++recalled;
      EXPECT_EQ(b.getResult()->error_message.rfind("recalled: superseded", 0), 0u) << b.getResult()->error_message;
    } else {
      ++preempted_running;
      EXPECT_EQ(b_state, actionlib::TerminalState::PREEMPTED);
    }
    EXPECT_EQ(c.getTerminalState().state_, actionlib::TerminalState::SUCCEEDED);
    ASSERT_TRUE(c.getResult());
    EXPECT_EQ(c.getResult()->error_code, Result::SUCCESS) << c.getResult()->error_message;
  }
  std::printf("[test 5c] superseded while waiting: %d recalled, %d preempted after they started\n",
              recalled, preempted_running);
  EXPECT_GT(recalled, 0) << "the waiting goal always started first: the test no longer tests recall";

  // A waiting goal cancelled before it starts: RECALLED, PREEMPTED, the running one goes on.
  MultiClient::GoalHandle a = ac.sendGoal(longGoal());
  while (a.getCommState() != actionlib::CommState::ACTIVE) ros::WallDuration(0.002).sleep();
  // B preempts A; cancelling B at once catches it waiting (or just started: then PREEMPTED).
  MultiClient::GoalHandle b = ac.sendGoal(longGoal());
  // actionlib's rule: cancel what the server has acknowledged (a cancel sent before that can
  // meet a status list without the goal, which the client takes as LOST).
  const ros::WallTime ack_by = ros::WallTime::now() + ros::WallDuration(5.0);
  while (b.getCommState() == actionlib::CommState::WAITING_FOR_GOAL_ACK && ros::WallTime::now() < ack_by)
    ros::WallDuration(0.001).sleep();
  b.cancel();
  ASSERT_TRUE(waitDone(a, 5.0));
  ASSERT_TRUE(waitDone(b, 5.0));
  ASSERT_TRUE(b.getResult());
  EXPECT_EQ(b.getResult()->error_code, Result::PREEMPTED) << b.getResult()->error_message;
  EXPECT_TRUE(b.getTerminalState().state_ == actionlib::TerminalState::RECALLED ||
              b.getTerminalState().state_ == actionlib::TerminalState::PREEMPTED)
      << b.getTerminalState().toString();
  EXPECT_EQ(a.getResult()->error_code, Result::PREEMPTED);
}

// ---------------------------------------------------------------- 5c'
// A cancel that overtakes its goal (two topics): actionlib answers the goal itself, RECALLED,
// with a default result, which PlacePlanServer's guard turns into PREEMPTED. Sent as raw
// messages so that the cancel comes first every time.
TEST(PlacePlannerNode, CancelThatOvertakesItsGoalIsPreemptedNotSuccess) {
  ros::NodeHandle nh;
  ros::Publisher cancel_pub = nh.advertise<actionlib_msgs::GoalID>(std::string(kAction) + "/cancel", 1);
  ros::Publisher goal_pub = nh.advertise<PlacePlanActionGoal>(std::string(kAction) + "/goal", 1);
  std::mutex mutex;
  std::vector<PlacePlanActionResult> results;
  ros::Subscriber sub = nh.subscribe<PlacePlanActionResult>(
      std::string(kAction) + "/result", 10, [&](const PlacePlanActionResultConstPtr& r) {
        std::lock_guard<std::mutex> lock(mutex);
        results.push_back(*r);
      });
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(10.0);
  while ((cancel_pub.getNumSubscribers() == 0 || goal_pub.getNumSubscribers() == 0 ||
          sub.getNumPublishers() == 0) && ros::WallTime::now() < give_up) {
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_GT(goal_pub.getNumSubscribers(), 0u);
  const std::string id = "cancel-first-" + std::to_string(ros::WallTime::now().toNSec());
  actionlib_msgs::GoalID cancel;
  cancel.id = id;
  cancel_pub.publish(cancel);
  ros::WallDuration(0.3).sleep();  // the cancel is in before the goal
  PlacePlanActionGoal goal;
  goal.goal_id.id = id;
  goal.goal_id.stamp = ros::Time::now();
  goal.goal = boxOnPlaneGoalForCuda();
  goal_pub.publish(goal);
  const PlacePlanActionResult* mine = nullptr;
  for (int i = 0; i < 200 && !mine; ++i) {
    ros::WallDuration(0.01).sleep();
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& r : results) {
      if (r.status.goal_id.id == id) mine = &r;
    }
  }
  ASSERT_NE(mine, nullptr) << "no result for the overtaken goal";
  EXPECT_EQ(mine->status.status, actionlib_msgs::GoalStatus::RECALLED);
  EXPECT_EQ(mine->result.error_code, Result::PREEMPTED) << mine->result.error_message;
  EXPECT_EQ(mine->result.error_message.rfind("recalled by actionlib", 0), 0u) << mine->result.error_message;
}

// ---------------------------------------------------------------- 5d
// A planner exception is INTERNAL_ERROR with its message, and the node serves on. The second
// node of place_planner_node.test has backend: cuda; where no GPU answers, the core's plan()
// throws "backend = cuda requested but unavailable" (planner.cpp).
TEST(PlacePlannerNode, PlannerExceptionIsInternalErrorAndNodeServesOn) {
  std::string why;
  if (cuda::available(&why)) {
    GTEST_SKIP() << "a GPU answers here, so backend cuda plans instead of throwing; this test "
                    "needs a machine without one";
  }
  Client cuda_client("/place_planner_cuda/place_plan", true);
  ASSERT_TRUE(cuda_client.waitForServer(ros::Duration(30.0)));
  PlacePlanGoal goal = boxOnPlaneGoalForCuda();
  for (int i = 0; i < 2; ++i) {  // twice: the node is still there after the first
    cuda_client.sendGoal(goal);
    ASSERT_TRUE(cuda_client.waitForResult(ros::Duration(30.0)));
    const Result r = *cuda_client.getResult();
    EXPECT_EQ(cuda_client.getState(), actionlib::SimpleClientGoalState::ABORTED);
    EXPECT_EQ(r.error_code, Result::INTERNAL_ERROR) << r.error_message;
    EXPECT_NE(r.error_message.find("backend = cuda requested but unavailable"), std::string::npos)
        << r.error_message;
    EXPECT_EQ(r.error_message.rfind("internal error: planner failed: ", 0), 0u) << r.error_message;
    EXPECT_TRUE(r.candidates.empty());
  }
  // A bad goal there is still the goal's fault: INVALID_GOAL, not INTERNAL_ERROR.
  goal.friction = -1;
  cuda_client.sendGoal(goal);
  ASSERT_TRUE(cuda_client.waitForResult(ros::Duration(30.0)));
  EXPECT_EQ(cuda_client.getResult()->error_code, Result::INVALID_GOAL);
}

// ---------------------------------------------------------------- 6
// The marker batch the node publishes after answering `goal` (the answer in *answer); an
// empty batch when none came within 2.5 s.
visualization_msgs::MarkerArray markersOf(const PlacePlanGoal& goal, Answer* answer) {
  std::mutex mutex;
  std::vector<visualization_msgs::MarkerArray> batches;
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<visualization_msgs::MarkerArray>(
      "/place_planner/markers", 10, [&](const visualization_msgs::MarkerArrayConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        batches.push_back(*m);
      });
  // Latched: the previous goal's batch arrives first.
  ros::WallDuration(0.5).sleep();
  size_t before;
  {
    std::lock_guard<std::mutex> lock(mutex);
    before = batches.size();
  }
  *answer = send(goal);
  for (int i = 0; i < 50; ++i) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (batches.size() > before) return batches.back();
    }
    ros::WallDuration(0.05).sleep();
  }
  ADD_FAILURE() << "no markers after the goal";
  return {};
}

TEST(PlacePlannerNode, FeedbackDuringLongPlanAndDocumentedMarkers) {
  FeedbackLog log;
  sendWithFeedback(longGoal(), &log);
  ros::WallDuration(1.0).sleep();
  const bool still_running = client().getState() == actionlib::SimpleClientGoalState::ACTIVE;
  client().cancelGoal();
  ASSERT_TRUE(client().waitForResult(ros::Duration(5.0)));
  EXPECT_TRUE(still_running) << "the long goal took less than 1 s: make it longer";
  const auto items = log.copy();
  ASSERT_GE(items.size(), 7u) << "feedback every 100 ms over 1 s";
  double max_gap = 0;
  for (size_t i = 1; i < items.size(); ++i) {
    max_gap = std::max(max_gap, (items[i].first - items[i - 1].first).toSec());
    EXPECT_GE(items[i].second.elapsed_time, items[i - 1].second.elapsed_time);
    EXPECT_GE(items[i].second.floor_points_done, items[i - 1].second.floor_points_done);
  }
  std::printf("[test 6] %zu feedback messages, largest gap %.1f ms\n", items.size(), max_gap * 1e3);
  EXPECT_LT(max_gap, kFeedbackGap);
  EXPECT_GT(items.back().second.floor_points_total, 1000);
  EXPECT_GT(items.back().second.floor_points_done, 0);

  // Markers of a completed goal: one batch, DELETEALL first, every documented namespace.
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(testArea(), "world");
  Answer a;
  const visualization_msgs::MarkerArray batch = markersOf(goal, &a);
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  ASSERT_FALSE(batch.markers.empty());
  EXPECT_EQ(batch.markers.front().action, visualization_msgs::Marker::DELETEALL);
  std::set<std::string> ns;
  for (size_t i = 1; i < batch.markers.size(); ++i) {
    EXPECT_EQ(batch.markers[i].header.frame_id, "world");
    ns.insert(batch.markers[i].ns);
  }
  for (const char* expected :
       {marker_ns::kPlacementArea, marker_ns::kCandidates, marker_ns::kContacts,
        marker_ns::kContactNormals, marker_ns::kFloorPoints, marker_ns::kBestPath,
        marker_ns::kQuality, marker_ns::kApproach}) {
    EXPECT_EQ(ns.count(expected), 1u) << "namespace " << expected << " missing";
  }
  EXPECT_EQ(ns.size(), 8u) << "without a grasp: no gripper, no retreat";
  // One object per candidate (up to marker_candidates = 10), coloured by the push it resists.
  int objects = 0;
  for (const auto& m : batch.markers) objects += m.ns == marker_ns::kCandidates;
  EXPECT_EQ(objects, std::min<int>(10, a.result.candidates.size()));
}

// ---------------------------------------------------------------- 7
TEST(PlacePlannerNode, GripperPoseIsPoseComposedWithGrasp) {
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(testArea(), "world");
  Eigen::Isometry3d X_OG = Eigen::Isometry3d::Identity();
  X_OG.translate(Eigen::Vector3d(0.01, -0.02, 0.12));
  X_OG.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
              Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  goal.has_grasp = true;
  toMsg(X_OG, &goal.grasp);
  const Answer a = send(goal);
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  ASSERT_FALSE(a.result.candidates.empty());
  for (const auto& c : a.result.candidates) {
    EXPECT_TRUE(c.has_gripper_pose);
    EXPECT_EQ(c.gripper_pose.header.frame_id, c.pose.header.frame_id);
    geometry_msgs::Pose expected;
    toMsg(Eigen::Isometry3d(fromMsg(c.pose.pose) * X_OG), &expected);
    EXPECT_LT(distance(c.gripper_pose.pose, expected), kExact);
    EXPECT_LT(angle(c.gripper_pose.pose, expected), kExact);
    // The gripper is 12 cm from the object's origin, wherever the object goes.
    EXPECT_NEAR((fromMsg(c.gripper_pose.pose).translation() - fromMsg(c.pose.pose).translation()).norm(),
                X_OG.translation().norm(), kExact);
  }
}

// ---------------------------------------------------------------- goal fields
TEST(PlacePlannerNode, BadGoalFieldIsInvalidGoalNamingIt) {
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(testArea(), "world");
  goal.friction = -1.0;
  Answer a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::INVALID_GOAL);
  EXPECT_NE(a.result.error_message.find("friction"), std::string::npos) << a.result.error_message;
  goal.friction = 0.0;
  goal.orientation_mode = "upside_down";
  a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::INVALID_GOAL);
  EXPECT_NE(a.result.error_message.find("upside_down"), std::string::npos) << a.result.error_message;
}

// An answer cut by the time budget: TIMED_OUT (ABORTED) when nothing stable was found yet,
// SUCCESS (SUCCEEDED) with partial = true and a message saying so when something was; never
// any other code.
void expectBudgetAnswer(const Answer& a) {
  int stable = 0;
  for (const auto& c : a.result.candidates) stable += c.stable;
  if (a.result.error_code == Result::SUCCESS) {
    EXPECT_TRUE(a.result.partial);
    EXPECT_EQ(a.state, actionlib::SimpleClientGoalState::SUCCEEDED);
    EXPECT_GT(stable, 0);
    EXPECT_NE(a.result.error_message.find("partial answer: time budget"), std::string::npos)
        << a.result.error_message;
  } else {
    EXPECT_EQ(a.result.error_code, Result::TIMED_OUT) << a.result.error_message;
    EXPECT_FALSE(a.result.partial);
    EXPECT_EQ(a.state, actionlib::SimpleClientGoalState::ABORTED);
    EXPECT_EQ(stable, 0);
  }
}

TEST(PlacePlannerNode, TimeBudgetEndsLongPlanWithPartialAnswerOrTimedOut) {
  PlacePlanGoal goal = longGoal();
  goal.time_budget_s = 0.3;  // the long plan needs several seconds
  const ros::WallTime t0 = ros::WallTime::now();
  const Answer a = send(goal);
  const double wall = (ros::WallTime::now() - t0).toSec();
  expectBudgetAnswer(a);
  // The search stops at 80 % of the budget, the robustness check of what it found uses the rest.
  EXPECT_GE(a.result.planning_time, 0.8 * 0.3);
  EXPECT_LT(a.result.planning_time, 0.3 + kCancelLatency);
  EXPECT_LT(wall, 1.0);
  std::printf("[budget] %s after %.3f s with %zu candidates\n",
              a.result.partial ? "partial SUCCESS" : "TIMED_OUT", a.result.planning_time,
              a.result.candidates.size());
  for (const auto& c : a.result.candidates) EXPECT_EQ(c.pose.header.frame_id, "world");
}

// The principal-axis start: the box rests on a face from it whatever the auto mode tries first.
PlacePlanGoal boxOnPlaneGoal() {
  PlacePlanGoal goal = quickGoal();
  goal.object_mesh = meshMsg(testObject(), "");
  goal.placement_area_mesh = meshMsg(testArea(), "world");
  goal.orientation_mode = "principal_axis";
  return goal;
}

TEST(PlacePlannerNode, TinyBudgetIsTimedOutOrPartialNeverElse) {
  PlacePlanGoal goal = longGoal();
  goal.orientation_mode = "principal_axis";
  goal.time_budget_s = 0.001;
  expectBudgetAnswer(send(goal));
  goal.verify_top_k = 3;  // the budget is spent: nothing is simulated
  const Answer a = send(goal);
  expectBudgetAnswer(a);
  for (const auto& c : a.result.candidates) EXPECT_FALSE(c.physics_checked);
}

// A 40 degree slope with mu = 0.05 (tan 40 = 0.84): nothing can rest on it; the search completes.
TEST(PlacePlannerNode, SteepSlopeWithLowFrictionIsNoStablePose) {
  PlacePlanGoal goal = boxOnPlaneGoal();
  goal.placement_area_mesh = meshMsg(scenes::plane(0.6, 0.6, 40.0), "world");
  goal.friction = 0.05;
  goal.verify_top_k = 2;  // nothing stable: nothing to simulate
  const Answer a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::NO_STABLE_POSE) << a.result.error_message;
  EXPECT_EQ(a.state, actionlib::SimpleClientGoalState::ABORTED);
  EXPECT_FALSE(a.result.partial);
  EXPECT_EQ(a.result.error_message.rfind("no stable pose: ", 0), 0u) << a.result.error_message;
  for (const auto& c : a.result.candidates) {
    EXPECT_FALSE(c.stable);
    EXPECT_FALSE(c.physics_checked);
  }
}

// A flagged 0 reaches the planner as 0: on a 5 degree slope (tan 5 deg = 0.087) the box rests
// with the parameter's mu = 0.2 and slides with use_friction and friction 0.
TEST(PlacePlannerNode, FlaggedZeroFrictionIsPlannedAsZero) {
  PlacePlanGoal goal = boxOnPlaneGoal();
  goal.placement_area_mesh = meshMsg(scenes::plane(0.6, 0.6, 5.0), "world");
  goal.friction = 0.0;  // not flagged: the parameter
  Answer a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  ASSERT_FALSE(a.result.candidates.empty());
  EXPECT_TRUE(a.result.candidates.front().stable);
  goal.use_friction = true;
  a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::NO_STABLE_POSE) << a.result.error_message;
  for (const auto& c : a.result.candidates) EXPECT_FALSE(c.stable);
}

// verify_top_k = 2: Bullet checks the best two stable candidates (a box on a face of the plane
// stays put), none of the others; 0 takes the parameter (0 = off), < 0 is off.
TEST(PlacePlannerNode, VerifyTopKChecksTheBestTwoStableCandidates) {
  PlacePlanGoal goal = boxOnPlaneGoal();
  goal.verify_top_k = 2;
  const Answer a = send(goal);
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  EXPECT_FALSE(a.result.partial);
  const auto& cs = a.result.candidates;
  ASSERT_GE(cs.size(), 3u);
  ASSERT_TRUE(cs[0].stable && cs[1].stable);
  for (size_t i = 0; i < cs.size(); ++i) {
    EXPECT_EQ(cs[i].physics_checked, i < 2) << "candidate " << i + 1;
    if (i < 2) {
      EXPECT_TRUE(cs[i].physics_stayed) << "candidate " << i + 1 << " moved " << cs[i].physics_moved
                                        << " m, turned " << cs[i].physics_turned << " deg";
      EXPECT_LT(cs[i].physics_moved, 0.01);
      EXPECT_LT(cs[i].physics_turned, 5.0);
    } else {
      EXPECT_FALSE(cs[i].physics_stayed);
    }
    EXPECT_FALSE(cs[i].start.empty());
    EXPECT_GE(cs[i].robust_share, 0.0);
    EXPECT_LE(cs[i].robust_share, 1.0);
    EXPECT_GE(cs[i].robust_trials, 0);
  }
  std::printf("[verify] best two: moved %.4f / %.4f m, turned %.2f / %.2f deg\n", cs[0].physics_moved,
              cs[1].physics_moved, cs[0].physics_turned, cs[1].physics_turned);
  for (const int k : {0, -1}) {
    goal.verify_top_k = k;
    const Answer b = send(goal);
    ASSERT_EQ(b.result.error_code, Result::SUCCESS) << b.result.error_message;
    for (const auto& c : b.result.candidates) EXPECT_FALSE(c.physics_checked) << "verify_top_k " << k;
  }
}

// ---------------------------------------------------------------- manipulation
// The node runs with the test gripper (test/gripper/test_gripper.urdf through robot_description,
// place_planner_node.test): palm, fingers 2.2 cm off the middle, a camera.

// The box of these tests: 4 x 4 x 8 cm, its frame O at the centre of its base.
constexpr double kTallBoxHeight = 0.08;
Mesh tallBox() { return scenes::box(0.04, 0.04, kTallBoxHeight, Eigen::Vector3d(0, 0, kTallBoxHeight / 2)); }
// Two such boxes that do not overlap have centres at least one box width (4 cm) apart; the
// planner's contact tolerance allows them to touch.
constexpr double kBoxesApart = 0.04 - 2e-3;

// Held from above: F (the palm) at height z in O, F's z (palm -> fingertips) pointing down.
Eigen::Isometry3d graspFromAbove(double z) {
  Eigen::Isometry3d X_OF = Eigen::Isometry3d::Identity();
  X_OF.translation() = Eigen::Vector3d(0, 0, z);
  X_OF.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return X_OF;
}

// Square pegs 1 cm wide, 10 cm tall, 7 cm apart on a floor (test_gripper.cpp): the box fits
// between them, the fingers around it (6 cm across) only in the middle of a cell.
Mesh pegField() {
  std::vector<Mesh> parts = {scenes::box(0.42, 0.42, 0.01, Eigen::Vector3d(0, 0, -0.005))};
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j) parts.push_back(scenes::box(0.01, 0.01, 0.1, Eigen::Vector3d(0.07 * i, 0.07 * j, 0.05)));
  return scenes::merge(parts, "pegs");
}

PlacePlanGoal tallBoxGoal(const Mesh& area) {
  PlacePlanGoal goal;
  goal.object_pose.header.frame_id = "world";
  goal.object_pose.pose.position.z = 0.5;
  goal.object_pose.pose.orientation.w = 1.0;
  goal.object_mesh = meshMsg(tallBox(), "");
  goal.placement_area_mesh = meshMsg(area, "world");
  goal.use_max_candidates = true;
  goal.max_candidates = 30;
  return goal;
}

PlacePlanGoal heldGoal(const Mesh& area, double grasp_z) {
  PlacePlanGoal goal = tallBoxGoal(area);
  goal.has_grasp = true;
  toMsg(graspFromAbove(grasp_z), &goal.grasp);
  return goal;
}

Eigen::Vector3d vec(const geometry_msgs::Vector3& v) { return fromMsg(v); }
Eigen::Vector3d pointOf(const geometry_msgs::Point& p) { return fromMsg(p); }

TEST(PlacePlannerManipulation, AmongPegsTheGripperFitsAndEveryPlaceLocationFieldIsFilled) {
  const Eigen::Isometry3d X_OF = graspFromAbove(0.09);  // palm 1 cm over the top
  Answer a;
  const visualization_msgs::MarkerArray batch = markersOf(heldGoal(pegField(), 0.09), &a);
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  ASSERT_FALSE(a.result.candidates.empty());
  // The gripper reached the planner: it blocked some candidates (fingers in a peg) ...
  EXPECT_GT(a.result.gripper_rejected, 0);
  std::printf("[gripper] %zu candidates, %d blocked by the gripper, %d tilted, %.3f s\n",
              a.result.candidates.size(), a.result.gripper_rejected, a.result.gripper_tilt_rejected,
              a.result.planning_time);
  int straight = 0;
  for (const auto& c : a.result.candidates) {
    // ... and none of those answered is blocked (keep_colliding is off).
    EXPECT_TRUE(c.blocked.empty()) << c.blocked;
    EXPECT_GE(c.gripper_clearance, 0.001 - 1e-9) << "closer than gripper_min_clearance";
    ASSERT_TRUE(c.has_gripper_pose);
    geometry_msgs::Pose expected;
    toMsg(Eigen::Isometry3d(fromMsg(c.pose.pose) * X_OF), &expected);
    EXPECT_LT(distance(c.gripper_pose.pose, expected), kExact);
    EXPECT_LT(angle(c.gripper_pose.pose, expected), kExact);
    // Approach: in W, along gravity (the default approach), the parameters' distances.
    EXPECT_EQ(c.approach_direction.header.frame_id, "world");
    EXPECT_LT((vec(c.approach_direction.vector) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-9);
    EXPECT_DOUBLE_EQ(c.approach_min_distance, 0.03);
    EXPECT_DOUBLE_EQ(c.approach_desired_distance, 0.10);
    EXPECT_GE(c.approach_free_distance, c.approach_min_distance);
    EXPECT_LE(c.approach_free_distance, c.approach_desired_distance + 1e-9);
    // Retreat: in F (frame_id the first gripper link), back along -z of F.
    EXPECT_EQ(c.retreat_direction.header.frame_id, "palm");
    EXPECT_LT((vec(c.retreat_direction.vector) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-9);
    EXPECT_DOUBLE_EQ(c.retreat_min_distance, 0.03);
    EXPECT_DOUBLE_EQ(c.retreat_desired_distance, 0.10);
    EXPECT_GE(c.retreat_free_distance, c.retreat_min_distance);
    EXPECT_LE(c.retreat_free_distance, c.retreat_desired_distance + 1e-9);
    EXPECT_EQ(c.pre_place_pose.header.frame_id, "world");
    if (!c.straight_approach) continue;
    ++straight;
    // Straight: the pre-place pose is the goal pose, desired_distance back along the approach.
    const Eigen::Vector3d expected_pre = pointOf(c.pose.pose.position) -
                                         c.approach_desired_distance * vec(c.approach_direction.vector);
    EXPECT_LT((pointOf(c.pre_place_pose.pose.position) - expected_pre).norm(), 1e-6);
    EXPECT_LT(angle(c.pre_place_pose.pose, c.pose.pose), 1e-6);
  }
  EXPECT_GT(straight, 0) << "from above between pegs, some approach is straight";

  // Markers: the gripper's triangles at the best few gripper poses, approach and retreat arrows.
  int grippers = 0, approaches = 0, retreats = 0;
  for (const auto& m : batch.markers) {
    if (m.ns == marker_ns::kGripper) {
      ++grippers;
      ASSERT_LT(m.id, static_cast<int>(a.result.candidates.size()));
      EXPECT_EQ(m.type, visualization_msgs::Marker::TRIANGLE_LIST);
      EXPECT_GE(m.points.size(), 3u * 12 * 3) << "palm and fingers are boxes of 12 triangles";
      EXPECT_EQ(m.points.size() % 3, 0u);
      EXPECT_LT(distance(m.pose, a.result.candidates[m.id].gripper_pose.pose), 1e-6);
    } else if (m.ns == marker_ns::kApproach) {
      ++approaches;
      ASSERT_EQ(m.points.size(), 2u);
      EXPECT_NEAR((pointOf(m.points[1]) - pointOf(m.points[0])).norm(), 0.10, 1e-6);
    } else if (m.ns == marker_ns::kRetreat) {
      ++retreats;
      ASSERT_EQ(m.points.size(), 2u);
      const auto& g = a.result.candidates[m.id].gripper_pose.pose.position;
      EXPECT_LT((pointOf(m.points[0]) - pointOf(g)).norm(), 1e-6);
      // F's -z is up here: the gripper backs off upwards.
      EXPECT_NEAR(m.points[1].z - m.points[0].z, 0.10, 1e-3);
    }
  }
  const int best_few = std::min<int>(3, a.result.candidates.size());  // marker_text_count
  EXPECT_EQ(grippers, best_few);
  EXPECT_EQ(approaches, best_few);
  EXPECT_EQ(retreats, best_few);
}

TEST(PlacePlannerManipulation, FingersBelowTheBaseAreNoStablePoseNamingTheGripper) {
  // F 3 cm over the base, fingers 5 cm long: their tips 2 cm below the table top.
  PlacePlanGoal goal = heldGoal(testArea(), 0.03);
  Answer a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::NO_STABLE_POSE) << a.result.error_message;
  EXPECT_EQ(a.state, actionlib::SimpleClientGoalState::ABORTED);
  EXPECT_EQ(a.result.error_message.rfind("no stable pose: ", 0), 0u) << a.result.error_message;
  EXPECT_NE(a.result.error_message.find("gripper blocks every stable pose"), std::string::npos)
      << a.result.error_message;
  EXPECT_GT(a.result.gripper_rejected, 0);
  for (const auto& c : a.result.candidates) EXPECT_FALSE(c.stable);
  // Held 1 cm over the top instead, the same box stands on the table: the gripper was the reason.
  toMsg(graspFromAbove(0.09), &goal.grasp);
  a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  // keep_colliding (a goal override): the blocked candidates come back, marked, not stable.
  goal = heldGoal(testArea(), 0.03);
  goal.keep_colliding = true;
  a = send(goal);
  EXPECT_EQ(a.result.error_code, Result::NO_STABLE_POSE) << a.result.error_message;
  ASSERT_FALSE(a.result.candidates.empty());
  for (const auto& c : a.result.candidates) {
    EXPECT_FALSE(c.stable);
    EXPECT_FALSE(c.blocked.empty());
  }
}

TEST(PlacePlannerManipulation, ShapeMsgsGoalGivesTheSameCandidatesAsPolygonMeshes) {
  // The area 0.7 m off in y, so that a node falling back on the topic meshes (test 1's scene)
  // answers elsewhere.
  Eigen::Isometry3d X_WA = Eigen::Isometry3d::Identity();
  X_WA.translation().y() = 0.7;
  const Mesh area_W = mapped(testArea(), X_WA);
  PlacePlanGoal goal = boxOnPlaneGoal();
  goal.placement_area_mesh = meshMsg(area_W, "world");
  goal.max_candidates = 1000;
  const Answer a = send(goal);
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  ASSERT_GT(a.result.candidates.front().pose.pose.position.y, 0.5);
  // The same scene as shapes, the area's vertices in the sensor frame.
  goal.object_mesh = pcl_msgs::PolygonMesh();
  goal.placement_area_mesh = pcl_msgs::PolygonMesh();
  toMsg(testObject(), &goal.object_shape);
  toMsg(mapped(area_W, X_WS().inverse()), &goal.placement_area_shape);
  goal.placement_area_shape_frame = "sensor";
  const Answer b = send(goal);
  ASSERT_EQ(b.result.error_code, Result::SUCCESS) << b.result.error_message;
  // The PolygonMesh carries float32 vertices, the shape float64, and the area came through a
  // frame: near ties in Q may rank differently (test 2), so the sets are compared.
  ASSERT_GT(a.result.candidates.size(), 5u);
  EXPECT_NEAR(static_cast<double>(b.result.candidates.size()), static_cast<double>(a.result.candidates.size()),
              0.1 * a.result.candidates.size() + 1);
  expectSameCandidateSets(a.result.candidates, b.result.candidates);
  EXPECT_TRUE(b.result.candidates.front().stable);
  EXPECT_NEAR(b.result.candidates.front().quality, a.result.candidates.front().quality, kSameQuality);
}

TEST(PlacePlannerManipulation, ShapeTopicsAreUsedForGoalsWithoutMeshes) {
  // The area as a shape on placement_area_shape (frame: the parameter, "" = W), 1 m off in x: the
  // answer must lie on it, so a node still using the PolygonMesh topic (test 1's) fails.
  ros::NodeHandle nh;
  static ros::Publisher object_pub = nh.advertise<shape_msgs::Mesh>("object_shape", 1, true);
  static ros::Publisher area_pub = nh.advertise<shape_msgs::Mesh>("placement_area_shape", 1, true);
  shape_msgs::Mesh object, area;
  toMsg(testObject(), &object);
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation().x() = 1.0;
  toMsg(mapped(testArea(), shift), &area);
  // Latched, but the node must be connected before a goal can expect them.
  for (int i = 0; i < 100 && (object_pub.getNumSubscribers() == 0 || area_pub.getNumSubscribers() == 0); ++i) {
    ros::WallDuration(0.05).sleep();
  }
  object_pub.publish(object);
  area_pub.publish(area);
  Answer a;
  for (int i = 0; i < 50; ++i) {  // until the node has them
    a = send(quickGoal());
    if (!a.result.candidates.empty() && a.result.candidates.front().pose.pose.position.x > 0.75) break;
    ros::WallDuration(0.1).sleep();
  }
  ASSERT_EQ(a.result.error_code, Result::SUCCESS) << a.result.error_message;
  for (const auto& c : a.result.candidates) {
    for (const auto& p : c.contact_points) {
      EXPECT_GE(p.x, 0.8 - kOnSurface);
      EXPECT_LE(p.x, 1.2 + kOnSurface);
      EXPECT_NEAR(p.z, 0.0, kOnSurface);
    }
  }
}

// Centre of the tall box at a candidate's pose.
Eigen::Vector3d tallBoxCentre(const PlacementCandidate& c) {
  return fromMsg(c.pose.pose) * Eigen::Vector3d(0, 0, kTallBoxHeight / 2);
}

TEST(PlacePlannerManipulation, AddToAreaPlacesTheNextBoxBesideTheFirstAndResetFreesItsSpot) {
  PlacePlanGoal goal = tallBoxGoal(testArea());
  goal.use_max_candidates = true;
  goal.max_candidates = 10;
  goal.reset_area = true;  // whatever earlier tests left
  const Answer first = send(goal);
  ASSERT_EQ(first.result.error_code, Result::SUCCESS) << first.result.error_message;
  EXPECT_EQ(first.result.objects_in_area, 0);
  ASSERT_FALSE(first.result.candidates.empty());
  const PlacementCandidate& c0 = first.result.candidates.front();
  const Eigen::Vector3d centre0 = tallBoxCentre(c0);

  // The first box placed at candidate 0: nothing new overlaps it.
  goal.reset_area = false;
  goal.add_to_area = true;
  goal.add_candidate = 0;
  const Answer second = send(goal);
  ASSERT_EQ(second.result.error_code, Result::SUCCESS) << second.result.error_message;
  EXPECT_EQ(second.result.objects_in_area, 1);
  ASSERT_FALSE(second.result.candidates.empty());
  for (const auto& c : second.result.candidates) {
    EXPECT_GE((tallBoxCentre(c) - centre0).norm(), kBoxesApart)
        << "a candidate at " << tallBoxCentre(c).transpose() << " overlaps the box at " << centre0.transpose();
  }
  // Stacked on it or beside it; the first plan's best spot is taken.
  EXPECT_GT(distance(second.result.candidates.front().pose.pose, c0.pose.pose), 0.01);

  // A bad index: INVALID_GOAL naming the field, and nothing changes.
  goal.add_candidate = 1000;
  Answer bad = send(goal);
  EXPECT_EQ(bad.result.error_code, Result::INVALID_GOAL);
  EXPECT_NE(bad.result.error_message.find("add_candidate = 1000"), std::string::npos) << bad.result.error_message;
  goal.add_to_area = false;
  const Answer again = send(goal);
  ASSERT_EQ(again.result.error_code, Result::SUCCESS) << again.result.error_message;
  EXPECT_EQ(again.result.objects_in_area, 1);
  for (const auto& c : again.result.candidates) EXPECT_GE((tallBoxCentre(c) - centre0).norm(), kBoxesApart);

  // reset_area: the area is the table again, and the first plan's answer comes back.
  goal.reset_area = true;
  const Answer reset = send(goal);
  ASSERT_EQ(reset.result.error_code, Result::SUCCESS) << reset.result.error_message;
  EXPECT_EQ(reset.result.objects_in_area, 0);
  ASSERT_FALSE(reset.result.candidates.empty());
  EXPECT_LT(distance(reset.result.candidates.front().pose.pose, c0.pose.pose), kSameAnswer);
  std::printf("[add_to_area] first at (%.3f, %.3f), next best at %.3f m from it\n", centre0.x(), centre0.y(),
              (tallBoxCentre(second.result.candidates.front()) - centre0).norm());
}

// ---------------------------------------------------------------- parameters
TEST(PlacePlannerParams, OutOfRangeAndWrongTypeAreNamed) {
  ros::NodeHandle nh("/params_test");
  nh.setParam("friction", -0.5);
  try {
    loadNodeConfig(nh);
    ADD_FAILURE() << "friction -0.5 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/params_test/friction"), std::string::npos) << e.what();
  }
  nh.setParam("friction", 0.4);
  nh.setParam("gravity", std::string("down"));
  try {
    loadNodeConfig(nh);
    ADD_FAILURE() << "gravity 'down' accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/params_test/gravity"), std::string::npos) << e.what();
  }
  nh.setParam("gravity", std::vector<double>{0.0, -1.0, 0.0});
  nh.setParam("verify_top_k", -1);
  try {
    loadNodeConfig(nh);
    ADD_FAILURE() << "verify_top_k -1 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/params_test/verify_top_k"), std::string::npos) << e.what();
  }
  nh.setParam("verify_top_k", 3);
  nh.setParam("verify_engines", std::string("havok"));
  try {
    loadNodeConfig(nh);
    ADD_FAILURE() << "verify_engines havok accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/params_test/verify_engines"), std::string::npos) << e.what();
  }
  nh.setParam("verify_engines", std::string("both"));
  EXPECT_EQ(loadNodeConfig(nh).verify_engines, "both");
  nh.setParam("robust_check", 1.5);
  try {
    loadNodeConfig(nh);
    ADD_FAILURE() << "robust_check 1.5 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/params_test/robust_check"), std::string::npos) << e.what();
  }
  nh.setParam("robust_check", false);
  // The budget is in seconds; the deprecated time_budget_ms is still read, but not both.
  nh.setParam("time_budget_s", -1.0);
  try {
    loadNodeConfig(nh);
    ADD_FAILURE() << "time_budget_s -1 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/params_test/time_budget_s"), std::string::npos) << e.what();
  }
  nh.setParam("time_budget_s", 0.25);
  EXPECT_DOUBLE_EQ(loadNodeConfig(nh).planner.time_budget_ms, 250.0);
  nh.setParam("time_budget_ms", 300.0);
  try {
    loadNodeConfig(nh);
    ADD_FAILURE() << "time_budget_s and time_budget_ms both accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/params_test/time_budget_ms"), std::string::npos) << e.what();
  }
  nh.deleteParam("time_budget_s");
  EXPECT_DOUBLE_EQ(loadNodeConfig(nh).planner.time_budget_ms, 300.0);
  nh.deleteParam("time_budget_ms");
  nh.setParam("robust_shift", 0.004);
  nh.setParam("orientation", std::string("keep"));
  const NodeConfig c = loadNodeConfig(nh);
  EXPECT_DOUBLE_EQ(c.planner.friction, 0.4);
  EXPECT_EQ(c.planner.gravity, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(c.planner.orientation, OrientationMode::kKeep);
  EXPECT_EQ(c.verify_top_k, 3);
  EXPECT_FALSE(c.planner.robust_check);
  EXPECT_DOUBLE_EQ(c.planner.robust_shift, 0.004);
  EXPECT_EQ(c.planner.max_candidates, PlannerConfig().max_candidates);  // default kept
  nh.deleteParam("");
}

// config/place_planner.yaml (loaded into /place_planner by the .test file) lists every
// PlannerConfig field with the struct's default: a field added or a default changed in
// config.h without the YAML fails here.
TEST(PlacePlannerParams, YamlMirrorsPlannerConfigDefaults) {
  ros::NodeHandle nh("/place_planner");
  for (const char* name :
       {"gravity", "approach", "friction", "floor_point_spacing", "min_floor_points", "lowest_n",
        "max_rotations", "sphere_radius", "grid_cell_size", "orientation", "max_resting_faces",
        "robust_shift", "robust_tilt_deg", "robust_com_offset", "robust_min_share", "robust_min_share_hanging", "robust_check",
        "time_budget_s", "verify_top_k",
        "max_candidates", "threads", "max_local_optimisation_steps", "min_support_width", "min_tipping_angle_deg",
        "min_quality", "merge_distance", "merge_angle_deg", "backend", "region_min", "region_max",
        "planning_frame", "tf_timeout", "feedback_period", "marker_candidates",
        "marker_text_count", "max_triangles", "max_floor_points", "max_tree_nodes", "max_model_mb",
        "max_object_size", "max_area_size", "max_gripper_tilt_deg", "gripper_min_clearance",
        "keep_colliding", "approach_distance", "approach_min_distance", "retreat_distance",
        "retreat_min_distance", "rank_order", "prefer_near", "min_edge_clearance", "scan_noise",
        "scan_unseen_reach", "closed_scan", "robot_description_param", "urdf_file", "gripper_links", "gripper_joint_positions",
        "gripper_mesh_dir", "object_shape_frame", "placement_area_shape_frame"}) {
    EXPECT_TRUE(nh.hasParam(name)) << name << " missing from config/place_planner.yaml";
  }
  const PlannerConfig d;
  EXPECT_EQ(loadNodeConfig(nh).verify_top_k, NodeConfig().verify_top_k);
  const PlannerConfig y = loadNodeConfig(nh).planner;
  EXPECT_EQ(y.gravity, d.gravity);
  EXPECT_EQ(y.approach, d.approach);
  EXPECT_EQ(y.friction, d.friction);
  EXPECT_EQ(y.floor_point_spacing, d.floor_point_spacing);
  EXPECT_EQ(y.min_floor_points, d.min_floor_points);
  EXPECT_EQ(y.lowest_n, d.lowest_n);
  EXPECT_EQ(y.max_rotations, d.max_rotations);
  EXPECT_EQ(y.sphere_radius, d.sphere_radius);
  EXPECT_EQ(y.grid_cell_size, d.grid_cell_size);
  EXPECT_EQ(y.orientation, d.orientation);
  EXPECT_EQ(y.max_resting_faces, d.max_resting_faces);
  EXPECT_EQ(y.robust_shift, d.robust_shift);
  EXPECT_EQ(y.robust_tilt_deg, d.robust_tilt_deg);
  EXPECT_EQ(y.robust_com_offset, d.robust_com_offset);
  EXPECT_EQ(y.robust_min_share, d.robust_min_share);
  EXPECT_EQ(y.robust_min_share_hanging, d.robust_min_share_hanging);
  EXPECT_EQ(y.robust_check, d.robust_check);
  EXPECT_EQ(y.time_budget_ms, d.time_budget_ms);
  EXPECT_EQ(y.max_candidates, d.max_candidates);
  EXPECT_EQ(y.threads, d.threads);
  EXPECT_EQ(y.max_local_optimisation_steps, d.max_local_optimisation_steps);
  EXPECT_EQ(y.min_support_width, d.min_support_width);
  EXPECT_EQ(y.min_tipping_angle_deg, d.min_tipping_angle_deg);
  EXPECT_EQ(y.min_quality, d.min_quality);
  EXPECT_EQ(y.merge_distance, d.merge_distance);
  EXPECT_EQ(y.merge_angle_deg, d.merge_angle_deg);
  EXPECT_EQ(y.backend, d.backend);
  EXPECT_EQ(y.region_min, d.region_min);
  EXPECT_EQ(y.region_max, d.region_max);
  EXPECT_EQ(y.max_triangles, d.max_triangles);
  EXPECT_EQ(y.max_floor_points, d.max_floor_points);
  EXPECT_EQ(y.max_tree_nodes, d.max_tree_nodes);
  EXPECT_EQ(y.max_model_mb, d.max_model_mb);
  EXPECT_EQ(y.max_object_size, d.max_object_size);
  EXPECT_EQ(y.max_area_size, d.max_area_size);
  EXPECT_EQ(y.max_gripper_tilt_deg, d.max_gripper_tilt_deg);
  EXPECT_EQ(y.gripper_min_clearance, d.gripper_min_clearance);
  EXPECT_EQ(y.keep_colliding, d.keep_colliding);
  EXPECT_EQ(y.approach_distance, d.approach_distance);
  EXPECT_EQ(y.approach_min_distance, d.approach_min_distance);
  EXPECT_EQ(y.retreat_distance, d.retreat_distance);
  EXPECT_EQ(y.retreat_min_distance, d.retreat_min_distance);
  EXPECT_EQ(y.rank_order, d.rank_order);
  EXPECT_EQ(y.prefer_near, d.prefer_near);
  EXPECT_EQ(y.min_edge_clearance, d.min_edge_clearance);
  EXPECT_EQ(y.scan_noise, d.scan_noise);
  EXPECT_EQ(y.scan_unseen_reach, d.scan_unseen_reach);
  EXPECT_EQ(y.closed_scan, d.closed_scan);
  // has_grasp, grasp: per goal; gripper: loaded from gripper_links (the .test file sets them).
  EXPECT_EQ(y.has_grasp, d.has_grasp);
  // The struct's size: a new field changes it; then list it above and in the YAML.
  EXPECT_EQ(sizeof(PlannerConfig), kPlannerConfigSize)
      << "PlannerConfig changed: mirror the new field in config/place_planner.yaml and params.cpp";
}

// The gripper parameters: the URDF from a file or from robot_description, links named in errors.
TEST(PlacePlannerParams, GripperIsLoadedAtStartupAndBadLinksAreNamed) {
  const std::string urdf = ros::package::getPath("place_planner") + "/test/gripper/test_gripper.urdf";
  ros::NodeHandle nh("/gripper_params_test");
  nh.setParam("gripper_links", std::vector<std::string>{"palm", "left_finger", "right_finger"});
  nh.setParam("urdf_file", urdf);
  std::map<std::string, double> joints{{"left_finger_joint", 0.03}};
  nh.setParam("gripper_joint_positions", joints);
  NodeConfig c = loadNodeConfig(nh);
  ASSERT_TRUE(c.planner.gripper);
  EXPECT_EQ(c.planner.gripper->links, (std::vector<std::string>{"palm", "left_finger", "right_finger"}));
  EXPECT_EQ(c.planner.gripper->triangles.size(), 36u) << "three boxes";
  // Below the palm (z > 0) only the fingers: the left one's outer face at the opening 0.03
  // plus its 8 mm width.
  double max_y = -1;
  for (const auto& v : c.planner.gripper->vertices_F)
    if (v.z() > 1e-6) max_y = std::max(max_y, v.y());
  EXPECT_NEAR(max_y, 0.038, 1e-9);
  const auto fails = [&](const std::string& what) {
    try {
      loadNodeConfig(nh);
      ADD_FAILURE() << "accepted; expected an error naming " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("/gripper_params_test/"), std::string::npos) << e.what();
    }
  };
  nh.setParam("gripper_links", std::vector<std::string>{"palm", "thumb"});
  fails("thumb");
  nh.setParam("gripper_links", std::vector<std::string>{"palm"});
  nh.setParam("urdf_file", std::string("/no/such/gripper.urdf"));
  fails("/no/such/gripper.urdf");
  // From the parameter robot_description_param names (searched up from the namespace).
  nh.setParam("urdf_file", std::string(""));
  nh.setParam("robot_description_param", std::string("no_such_description"));
  fails("no_such_description");
  nh.setParam("robot_description_param", std::string("robot_description"));  // /robot_description
  c = loadNodeConfig(nh);
  ASSERT_TRUE(c.planner.gripper);
  EXPECT_EQ(c.planner.gripper->triangles.size(), 12u) << "the palm";
  nh.setParam("gripper_joint_positions", std::string("open"));
  fails("gripper_joint_positions");
  nh.deleteParam("");
}

TEST(PlacePlannerParams, NodeRefusesToStartWithBadParameter) {
  // `timeout`: should the node start after all, the test fails instead of hanging.
  const std::string command = "timeout 20 " + std::string(PP_NODE_BINARY) +
                              " __name:=bad_place_planner _max_rotations:=99 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buf[512];
  while (fgets(buf, sizeof buf, pipe)) output += buf;
  const int status = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << output;
  EXPECT_NE(output.find("/bad_place_planner/max_rotations"), std::string::npos) << output;
  // An unknown gripper link (the URDF from /robot_description): named, exit 1.
  ros::NodeHandle nh("/bad_gripper_planner");
  nh.setParam("gripper_links", std::vector<std::string>{"palm", "thumb"});
  FILE* pipe2 = popen(("timeout 20 " + std::string(PP_NODE_BINARY) + " __name:=bad_gripper_planner 2>&1").c_str(), "r");
  ASSERT_NE(pipe2, nullptr);
  output.clear();
  while (fgets(buf, sizeof buf, pipe2)) output += buf;
  const int status2 = pclose(pipe2);
  nh.deleteParam("");
  EXPECT_TRUE(WIFEXITED(status2) && WEXITSTATUS(status2) == 1) << output;
  EXPECT_NE(output.find("/bad_gripper_planner/gripper_links"), std::string::npos) << output;
  EXPECT_NE(output.find("thumb"), std::string::npos) << output;
}

// Live tuning (config/PlacePlanner.cfg): a parameter set through dynamic_reconfigure is used by
// the next goal; a combination validate() refuses is named in the log and the old value kept.
dynamic_reconfigure::Config reconfigure(const dynamic_reconfigure::Config& change) {
  dynamic_reconfigure::Reconfigure srv;
  srv.request.config = change;
  EXPECT_TRUE(ros::service::waitForService("/place_planner/set_parameters", ros::Duration(10.0)));
  EXPECT_TRUE(ros::service::call("/place_planner/set_parameters", srv));
  return srv.response.config;
}

dynamic_reconfigure::Config intChange(const std::string& name, int value) {
  dynamic_reconfigure::Config c;
  dynamic_reconfigure::IntParameter p;
  p.name = name;
  p.value = value;
  c.ints.push_back(p);
  return c;
}

TEST(PlacePlannerParams, DynamicReconfigureIsUsedByTheNextGoal) {
  PlacePlanGoal goal = boxOnPlaneGoalForCuda();
  goal.max_candidates = 0;  // no override: the node's parameter decides
  reconfigure(intChange("max_candidates", 2));
  int value = 0;
  EXPECT_TRUE(ros::param::get("/place_planner/max_candidates", value));
  EXPECT_EQ(value, 2);
  const Answer two = send(goal);
  EXPECT_EQ(two.result.error_code, Result::SUCCESS) << two.result.error_message;
  EXPECT_EQ(two.result.candidates.size(), 2u);

  // approach_min_distance above approach_distance (0.10 m): refused, the old value stays.
  dynamic_reconfigure::Config bad;
  dynamic_reconfigure::DoubleParameter d;
  d.name = "approach_min_distance";
  d.value = 0.5;
  bad.doubles.push_back(d);
  const dynamic_reconfigure::Config after = reconfigure(bad);
  bool seen = false;
  for (const auto& p : after.doubles)
    if (p.name == "approach_min_distance") {
      seen = true;
      EXPECT_NEAR(p.value, 0.03, 1e-9) << "a refused value was kept";
    }
  EXPECT_TRUE(seen);
  const Answer still_two = send(goal);
  EXPECT_EQ(still_two.result.error_code, Result::SUCCESS) << still_two.result.error_message;
  EXPECT_EQ(still_two.result.candidates.size(), 2u);

  reconfigure(intChange("max_candidates", 10));
  const Answer more = send(goal);
  EXPECT_EQ(more.result.error_code, Result::SUCCESS) << more.result.error_message;
  EXPECT_GT(more.result.candidates.size(), 2u);
}

}  // namespace
}  // namespace place_planner

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "place_planner_node_test");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  tf2_ros::StaticTransformBroadcaster broadcaster;
  geometry_msgs::TransformStamped T = tf2::eigenToTransform(place_planner::X_WS());
  T.header.frame_id = "world";
  T.child_frame_id = "sensor";
  T.header.stamp = ros::Time::now();
  broadcaster.sendTransform(T);
  const int rc = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return rc;
}
