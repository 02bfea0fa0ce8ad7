// PlacePlanServer::guarded (src/node/place_plan_server.cpp), no roscore: a result published for a
// goal that did not succeed never carries SUCCESS. The path through actionlib (a cancel that
// overtakes its goal) is in the rostest (CancelThatOvertakesItsGoal...).
#include <gtest/gtest.h>

#include <actionlib_msgs/GoalStatus.h>

#include "place_planner/ros/place_plan_server.h"

namespace place_planner {
namespace {

using actionlib_msgs::GoalStatus;
using Result = PlacePlanResult;

Result result(uint8_t code, const std::string& message) {
  Result r;
  r.error_code = code;
  r.error_message = message;
  return r;
}

TEST(PlacePlanServerGuard, DefaultResultOfARecalledOrPreemptedGoalBecomesPreempted) {
  for (const uint8_t status : {GoalStatus::RECALLED, GoalStatus::PREEMPTED}) {
    const Result r = PlacePlanServer::guarded(status, Result());  // actionlib's Result()
    EXPECT_EQ(r.error_code, Result::PREEMPTED) << "status " << int(status);
    EXPECT_EQ(r.error_message.rfind("recalled by actionlib", 0), 0u) << r.error_message;
    EXPECT_FALSE(r.partial);
  }
}

TEST(PlacePlanServerGuard, DefaultResultOfAnAbortedOrRejectedGoalBecomesInternalError) {
  for (const uint8_t status : {GoalStatus::ABORTED, GoalStatus::REJECTED, GoalStatus::LOST}) {
    const Result r = PlacePlanServer::guarded(status, Result());
    EXPECT_EQ(r.error_code, Result::INTERNAL_ERROR) << "status " << int(status);
    EXPECT_NE(r.error_message.find("actionlib ended the goal"), std::string::npos) << r.error_message;
  }
}

TEST(PlacePlanServerGuard, TheNodesOwnAnswersPassUnchanged) {
  Result partial = result(Result::SUCCESS, "partial answer: ...");
  partial.partial = true;
  Result r = PlacePlanServer::guarded(GoalStatus::SUCCEEDED, partial);
  EXPECT_EQ(r.error_code, Result::SUCCESS);
  EXPECT_TRUE(r.partial);
  EXPECT_EQ(r.error_message, "partial answer: ...");
  r = PlacePlanServer::guarded(GoalStatus::RECALLED, result(Result::PREEMPTED, "recalled: superseded"));
  EXPECT_EQ(r.error_code, Result::PREEMPTED);
  EXPECT_EQ(r.error_message, "recalled: superseded");
  r = PlacePlanServer::guarded(GoalStatus::ABORTED, result(Result::TF_ERROR, "no transform"));
  EXPECT_EQ(r.error_code, Result::TF_ERROR);
  EXPECT_EQ(r.error_message, "no transform");
}

}  // namespace
}  // namespace place_planner

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
