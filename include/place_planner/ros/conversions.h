// Message conversions between the ROS interface and the ROS-free core (grid_map's
// GridMapRosConverter style): fromMsg / toMsg only, no ROS graph, no tf.
// Frames: W is the planning frame, O the object's mesh frame, G the gripper frame.
#pragma once
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Vector3.h>
#include <pcl_msgs/PolygonMesh.h>
#include <shape_msgs/Mesh.h>
#include <ros/time.h>

#include "place_planner/PlacePlanFeedback.h"
#include "place_planner/PlacementCandidate.h"
#include "place_planner/model/mesh.h"
#include "place_planner/planner.h"

namespace place_planner {

// PolygonMesh -> vertex positions and polygons, ready for buildMesh() (which checks NaN/Inf and
// indices). The cloud needs x, y, z fields of type FLOAT32 or FLOAT64, little endian; every
// point of the height x width cloud is one vertex. Throws MeshError prefixed with `name`
// ("object mesh: cloud has no field 'z'") for a cloud that cannot be read. An index above
// INT_MAX is clamped so that buildMesh reports it as out of range.
void fromMsg(const pcl_msgs::PolygonMesh& msg, const std::string& name,
             std::vector<Eigen::Vector3d>* vertices, std::vector<std::vector<int>>* polygons);

// shape_msgs/Mesh (what MoveIt's collision objects hold: float64 vertices, triangles) ->
// vertex positions and triangles, ready for buildMesh(), which checks NaN/Inf. A triangle index
// past the vertices throws MeshError naming the mesh, the triangle and the index ("object
// shape: triangle 3 has vertex index 12, but the mesh has 8 vertices").
void fromMsg(const shape_msgs::Mesh& msg, const std::string& name,
             std::vector<Eigen::Vector3d>* vertices, std::vector<std::vector<int>>* polygons);

// Mesh patches -> shape_msgs/Mesh: each patch fanned into triangles from its first vertex
// (patches are convex, mesh.h).
void toMsg(const Mesh& mesh, shape_msgs::Mesh* msg);

// Mesh patches -> PolygonMesh (float32 x, y, z cloud, one Vertices per patch), in frame_id.
void toMsg(const Mesh& mesh, const std::string& frame_id, pcl_msgs::PolygonMesh* msg);

// Pose <-> isometry. fromMsg normalises the quaternion; the caller checks it is a unit one.
Eigen::Isometry3d fromMsg(const geometry_msgs::Pose& msg);
void toMsg(const Eigen::Isometry3d& X, geometry_msgs::Pose* msg);

Eigen::Vector3d fromMsg(const geometry_msgs::Point& msg);
Eigen::Vector3d fromMsg(const geometry_msgs::Vector3& msg);
void toMsg(const Eigen::Vector3d& v, geometry_msgs::Point* msg);
void toMsg(const Eigen::Vector3d& v, geometry_msgs::Vector3* msg);

// One candidate, all in frame_id (the planning frame W) but the retreat direction, which is in
// the gripper frame F named gripper_frame (the first gripper link; "" without a gripper).
// With c.has_gripper_pose (the plan had a grasp) gripper_pose = X_WF; otherwise
// has_gripper_pose = false and gripper_pose is all zero (frame_id empty). The placement
// fields map one to one onto moveit_msgs/PlaceLocation (doc/manipulation.md).
void toMsg(const Candidate& candidate, const std::string& frame_id, const std::string& gripper_frame,
           const ros::Time& stamp, PlacementCandidate* msg);

// Planner progress -> action feedback (elapsed time in seconds).
void toMsg(const Progress& progress, PlacePlanFeedback* msg);

}  // namespace place_planner
