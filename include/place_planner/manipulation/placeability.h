// Can a robot execute a candidate (beyond the paper)? The straight approach along
// d_vis to the goal, the gripper (gripper.h) riding with the object through the approach, the
// intermediate poses and the goal, and the gripper's retreat along -z of its frame F once it
// lets go. Maps one to one onto moveit_msgs/PlaceLocation (doc/manipulation.md).
// Frames: leaves in G; the Placement's poses in W, the retreat's direction in F.
#pragma once
#include <Eigen/Geometry>

#include "place_planner/infra/backend.h"
#include "place_planner/config.h"
#include "place_planner/manipulation/gripper.h"
#include "place_planner/planner.h"
#include "place_planner/search/hanging_starts.h"
#include "place_planner/search/tree_stepper.h"

namespace place_planner {

struct PlaceabilityContext {
  const ObjectModel& om;
  const AreaModel& am;
  Backend& backend;  // its distance kernel sweeps the object along the approach (V-A)
  V3 d_vis;          // approach direction, G
  const PlannerConfig& config;
};

// Steps along the approach and the retreat at which the gripper is checked (m).
constexpr double kMotionStep = 0.005;

// The leaf's Placement: `blocked` names the first thing that stops it — "goal", "intermediate
// pose", "approach" (the gripper within approach_min_distance), "retreat" (within
// retreat_min_distance), "edge" (min_edge_clearance: the area drops off nearer than that
// around the object's footprint) — or is empty.
// A hanging leaf (its root's `hanging` start) is approached along its peg, threaded, to the
// first pose of its path, then lowered: its pre-place pose is beyond the peg's tip.
Placement checkPlacement(const TreeLeaf& leaf, const PlaceabilityContext& ctx, const HangingStart* hanging = nullptr);

// With a grasp: does F's z axis (the approach axis) at this pose point within
// max_gripper_tilt_deg of straight down (gravity, -z of G)? True without a grasp.
bool gripperTiltOk(const Eigen::Matrix3d& R_GO, const PlannerConfig& config);

}  // namespace place_planner
