// The gripper that holds the object (beyond the paper): the collision geometry of
// the robot's gripper links, from its URDF, as one triangle mesh in the frame F of the first
// link named. Convention: F's z axis is the approach axis, pointing from the palm to the
// fingertips; the grasp X_OF places F in the object frame O (the goal's `grasp`).
// Frames: F (gripper), O (object), G (planning frame with gravity -z, scene.h).
#pragma once
#include <Eigen/Geometry>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "place_planner/model/scene.h"

namespace place_planner {

struct GripperModel {
  std::vector<Eigen::Vector3d> vertices_F;
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> triangle_link;  // index into links
  std::vector<std::string> links;  // as named; links[0] is F
  bool empty() const { return triangles.empty(); }
};

// Turns a mesh URI of the URDF (package://pkg/path, file:///path, a plain path) into a file
// path; the node resolves package:// with ROS, the default handles file:// and plain paths
// (relative ones against `base_dir`).
using MeshResolver = std::function<std::string(const std::string& uri)>;

// Collision geometry of `links` (boxes, cylinders, spheres, meshes in any format mesh_io reads,
// STL included), posed through the joints between them at `joint_positions` (rad or m; joints
// not listed at 0, the URDF's zero state). Throws std::invalid_argument naming the link, the
// joint or the file when the URDF does not parse, a link is unknown or not connected to the
// first, or a mesh cannot be read.
GripperModel gripperFromUrdf(const std::string& urdf_xml, const std::vector<std::string>& links,
                             const std::map<std::string, double>& joint_positions = {},
                             const MeshResolver& resolve = {});
GripperModel gripperFromUrdfFile(const std::string& path, const std::vector<std::string>& links,
                                 const std::map<std::string, double>& joint_positions = {},
                                 const MeshResolver& resolve = {});

// Smallest distance (m) between the gripper posed at X_GF and the area's triangles, exact
// (triangle against triangle, through the area's triangle BVH); 0 when they intersect; `cap`
// when nothing is nearer than cap.
double gripperClearance(const GripperModel& g, const Eigen::Isometry3d& X_GF, const AreaModel& area, double cap);

}  // namespace place_planner
