// rviz markers of one planning answer, built in one place and published as one batch per goal
// (rviz_visual_tools style). The first marker of the batch is a DELETEALL, so the previous
// goal's markers disappear. Namespaces (documented in doc/node.md):
#pragma once
#include <string>

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include "place_planner/manipulation/gripper.h"
#include "place_planner/model/mesh.h"
#include "place_planner/planner.h"

namespace place_planner {
namespace marker_ns {
constexpr const char* kPlacementArea = "placement_area";   // grey triangle list
constexpr const char* kCandidates = "candidates";          // object at each goal pose, red->green by Q
constexpr const char* kContacts = "contacts";              // red spheres at the contact points (best few)
constexpr const char* kContactNormals = "contact_normals"; // arrows along the normals (<= 24 per candidate)
constexpr const char* kFloorPoints = "floor_points";       // orange spheres
constexpr const char* kBestPath = "best_path";             // best candidate's intermediate poses, faded
constexpr const char* kQuality = "quality";                // "#1 Q=0.87" text above the best few
// Manipulation (doc/manipulation.md), for the best few (as the contacts):
constexpr const char* kApproach = "approach";              // arrow pre-place -> end of the approach
constexpr const char* kGripper = "gripper";                // the gripper's triangles at X_WF (with a grasp)
constexpr const char* kRetreat = "retreat";                // the gripper's retreat arrow (with a grasp)
}  // namespace marker_ns

struct MarkerOptions {
  std::string frame_id = "world";  // the planning frame W
  ros::Time stamp;
  int max_candidates = 10;         // object outlines drawn, best first
  int text_count = 3;              // quality labels, contacts, approach/retreat arrows and
                                   // grippers, best first (>= 1 for all but the labels)
  const GripperModel* gripper = nullptr;  // drawn at X_WF of candidates with a gripper pose (optional)
};

// object_O: the object mesh in the frame whose poses the candidates' X_WO give. area_W: the
// placement area in the planning frame. An empty result gives the area and the floor points.
visualization_msgs::MarkerArray buildMarkers(const Mesh& object_O, const Mesh& area_W,
                                             const PlanResult& result, const MarkerOptions& options);

// Red (Q <= 0) -> yellow -> green (Q >= 1).
void qualityColour(double quality, float* r, float* g, float* b);

}  // namespace place_planner
