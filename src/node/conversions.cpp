#include "place_planner/ros/conversions.h"

#include <sensor_msgs/PointField.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <climits>
#include <cstring>

namespace place_planner {
namespace {

// Offset and datatype of the field called `axis`; throws naming the mesh and the field.
const sensor_msgs::PointField& findField(const sensor_msgs::PointCloud2& cloud,
                                         const std::string& axis, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name != axis) continue;
    if (f.datatype != sensor_msgs::PointField::FLOAT32 &&
        f.datatype != sensor_msgs::PointField::FLOAT64) {
      throw MeshError(name + ": cloud field '" + axis + "' has datatype " +
                      std::to_string(f.datatype) + " (must be FLOAT32 or FLOAT64)");
    }
    const size_t size = f.datatype == sensor_msgs::PointField::FLOAT32 ? 4 : 8;
    if (f.offset + size > cloud.point_step) {
      throw MeshError(name + ": cloud field '" + axis + "' at offset " + std::to_string(f.offset) +
                      " does not fit in point_step " + std::to_string(cloud.point_step));
    }
    return f;
  }
  throw MeshError(name + ": cloud has no field '" + axis + "'");
}

double readField(const uint8_t* point, const sensor_msgs::PointField& f) {
  if (f.datatype == sensor_msgs::PointField::FLOAT32) {
    float v;
    std::memcpy(&v, point + f.offset, sizeof v);
    return v;
  }
  double v;
  std::memcpy(&v, point + f.offset, sizeof v);
  return v;
}

}  // namespace

void fromMsg(const pcl_msgs::PolygonMesh& msg, const std::string& name,
             std::vector<Eigen::Vector3d>* vertices, std::vector<std::vector<int>>* polygons) {
  const sensor_msgs::PointCloud2& cloud = msg.cloud;
  vertices->clear();
  polygons->clear();
  const size_t n = static_cast<size_t>(cloud.width) * cloud.height;
  if (n > 0) {
    if (cloud.is_bigendian) throw MeshError(name + ": cloud is big endian (not supported)");
    const auto& fx = findField(cloud, "x", name);
    const auto& fy = findField(cloud, "y", name);
    const auto& fz = findField(cloud, "z", name);
    const size_t needed = static_cast<size_t>(cloud.height - 1) * cloud.row_step +
                          static_cast<size_t>(cloud.width) * cloud.point_step;
    if (cloud.row_step < static_cast<size_t>(cloud.width) * cloud.point_step ||
        cloud.data.size() < needed) {
      throw MeshError(name + ": cloud data has " + std::to_string(cloud.data.size()) +
                      " bytes, too few for " + std::to_string(cloud.height) + " x " +
                      std::to_string(cloud.width) + " points (point_step " +
                      std::to_string(cloud.point_step) + ", row_step " +
                      std::to_string(cloud.row_step) + ")");
    }
    vertices->reserve(n);
    for (uint32_t row = 0; row < cloud.height; ++row) {
      const uint8_t* p = cloud.data.data() + static_cast<size_t>(row) * cloud.row_step;
      for (uint32_t col = 0; col < cloud.width; ++col, p += cloud.point_step) {
        vertices->emplace_back(readField(p, fx), readField(p, fy), readField(p, fz));
      }
    }
  }
  polygons->reserve(msg.polygons.size());
  for (const auto& poly : msg.polygons) {
    std::vector<int> indices;
    indices.reserve(poly.vertices.size());
    for (uint32_t i : poly.vertices) {
      indices.push_back(static_cast<int>(std::min<uint32_t>(i, static_cast<uint32_t>(INT_MAX))));
    }
    polygons->push_back(std::move(indices));
  }
}

void fromMsg(const shape_msgs::Mesh& msg, const std::string& name,
             std::vector<Eigen::Vector3d>* vertices, std::vector<std::vector<int>>* polygons) {
  vertices->clear();
  polygons->clear();
  vertices->reserve(msg.vertices.size());
  for (const auto& v : msg.vertices) vertices->push_back(fromMsg(v));
  polygons->reserve(msg.triangles.size());
  for (size_t t = 0; t < msg.triangles.size(); ++t) {
    const auto& idx = msg.triangles[t].vertex_indices;
    for (const uint32_t i : idx) {
      if (i >= msg.vertices.size()) {
        throw MeshError(name + ": triangle " + std::to_string(t) + " has vertex index " + std::to_string(i) +
                        ", but the mesh has " + std::to_string(msg.vertices.size()) + " vertices");
      }
    }
    polygons->push_back({static_cast<int>(idx[0]), static_cast<int>(idx[1]), static_cast<int>(idx[2])});
  }
}

void toMsg(const Mesh& mesh, shape_msgs::Mesh* msg) {
  msg->vertices.resize(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) toMsg(mesh.vertices[i], &msg->vertices[i]);
  msg->triangles.clear();
  for (const auto& patch : mesh.patches) {
    for (size_t k = 1; k + 1 < patch.size(); ++k) {
      shape_msgs::MeshTriangle t;
      t.vertex_indices = {static_cast<uint32_t>(patch[0]), static_cast<uint32_t>(patch[k]),
                          static_cast<uint32_t>(patch[k + 1])};
      msg->triangles.push_back(t);
    }
  }
}

void toMsg(const Mesh& mesh, const std::string& frame_id, pcl_msgs::PolygonMesh* msg) {
  msg->header.frame_id = frame_id;
  msg->cloud.header.frame_id = frame_id;
  sensor_msgs::PointCloud2Modifier modifier(msg->cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(mesh.vertices.size());
  msg->cloud.height = 1;
  msg->cloud.width = static_cast<uint32_t>(mesh.vertices.size());
  msg->cloud.is_dense = true;
  sensor_msgs::PointCloud2Iterator<float> x(msg->cloud, "x"), y(msg->cloud, "y"),
      z(msg->cloud, "z");
  for (const auto& v : mesh.vertices) {
    *x = static_cast<float>(v.x());
    *y = static_cast<float>(v.y());
    *z = static_cast<float>(v.z());
    ++x, ++y, ++z;
  }
  msg->polygons.clear();
  msg->polygons.reserve(mesh.patches.size());
  for (const auto& patch : mesh.patches) {
    pcl_msgs::Vertices poly;
    poly.vertices.assign(patch.begin(), patch.end());
    msg->polygons.push_back(std::move(poly));
  }
}

Eigen::Isometry3d fromMsg(const geometry_msgs::Pose& msg) {
  Eigen::Quaterniond q(msg.orientation.w, msg.orientation.x, msg.orientation.y, msg.orientation.z);
  if (q.norm() > 0) q.normalize();
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q.toRotationMatrix();
  X.translation() = fromMsg(msg.position);
  return X;
}

void toMsg(const Eigen::Isometry3d& X, geometry_msgs::Pose* msg) {
  toMsg(Eigen::Vector3d(X.translation()), &msg->position);
  const Eigen::Quaterniond q(X.rotation());
  msg->orientation.x = q.x();
  msg->orientation.y = q.y();
  msg->orientation.z = q.z();
  msg->orientation.w = q.w();
}

Eigen::Vector3d fromMsg(const geometry_msgs::Point& msg) { return {msg.x, msg.y, msg.z}; }
Eigen::Vector3d fromMsg(const geometry_msgs::Vector3& msg) { return {msg.x, msg.y, msg.z}; }

void toMsg(const Eigen::Vector3d& v, geometry_msgs::Point* msg) {
  msg->x = v.x();
  msg->y = v.y();
  msg->z = v.z();
}

void toMsg(const Eigen::Vector3d& v, geometry_msgs::Vector3* msg) {
  msg->x = v.x();
  msg->y = v.y();
  msg->z = v.z();
}

void toMsg(const Candidate& c, const std::string& frame_id, const std::string& gripper_frame,
           const ros::Time& stamp, PlacementCandidate* msg) {
  msg->pose.header.frame_id = frame_id;
  msg->pose.header.stamp = stamp;
  toMsg(c.X_WO, &msg->pose.pose);
  // Without a grasp there is no gripper pose: left empty (all zero) rather than an identity
  // that a caller could mistake for one.
  msg->has_gripper_pose = c.has_gripper_pose;
  msg->gripper_pose = geometry_msgs::PoseStamped();
  if (c.has_gripper_pose) {
    msg->gripper_pose.header = msg->pose.header;
    toMsg(c.X_WF, &msg->gripper_pose.pose);
  }
  // moveit_msgs/PlaceLocation's pre_place_approach and post_place_retreat.
  const Placement& pl = c.placement;
  msg->pre_place_pose.header = msg->pose.header;
  toMsg(pl.pre_place_W, &msg->pre_place_pose.pose);
  msg->straight_approach = pl.straight;
  msg->approach_direction.header = msg->pose.header;
  toMsg(pl.approach.direction, &msg->approach_direction.vector);
  msg->approach_min_distance = pl.approach.min_distance;
  msg->approach_desired_distance = pl.approach.desired_distance;
  msg->approach_free_distance = pl.approach.free_distance;
  msg->retreat_direction.header.frame_id = gripper_frame;
  msg->retreat_direction.header.stamp = stamp;
  toMsg(pl.retreat.direction, &msg->retreat_direction.vector);
  msg->retreat_min_distance = pl.retreat.min_distance;
  msg->retreat_desired_distance = pl.retreat.desired_distance;
  msg->retreat_free_distance = pl.retreat.free_distance;
  msg->gripper_clearance = pl.gripper_clearance;
  msg->blocked = pl.blocked;
  msg->quality = c.quality;
  msg->stable = c.stable;
  msg->support = toString(c.support);
  msg->curved_support = c.curved_support;
  msg->push_resistance = c.push_resistance;
  msg->push_resistance_mean = c.push_resistance_mean;
  msg->drop_margin = c.drop_margin;
  msg->push_weakest_direction.header = msg->pose.header;
  toMsg(c.push_weakest_W, &msg->push_weakest_direction.vector);
  msg->robust_share = c.robustness.share();
  msg->robust_trials = c.robustness.trials;
  msg->min_tipping_angle = c.robustness.min_tipping_angle;
  msg->start = toString(c.start);
  msg->kind = c.hanging ? "hanging" : "standing";
  msg->physics_checked = c.physics.checked;
  msg->physics_stayed = c.physics.stayed;
  msg->physics_moved = c.physics.moved_m;
  msg->physics_turned = c.physics.turned_deg;
  msg->contact_points.resize(c.contacts.size());
  msg->contact_normals.resize(c.contacts.size());
  for (size_t i = 0; i < c.contacts.size(); ++i) {
    toMsg(c.contacts[i].p_W, &msg->contact_points[i]);
    toMsg(c.contacts[i].n_W, &msg->contact_normals[i]);
  }
  toMsg(c.floor_point_W, &msg->floor_point);
  msg->intermediate_poses.header = msg->pose.header;
  msg->intermediate_poses.poses.resize(c.intermediate_poses.size());
  for (size_t i = 0; i < c.intermediate_poses.size(); ++i) {
    toMsg(c.intermediate_poses[i], &msg->intermediate_poses.poses[i]);
  }
}

void toMsg(const Progress& p, PlacePlanFeedback* msg) {
  msg->floor_points_done = p.floor_points_done;
  msg->floor_points_total = p.floor_points_total;
  msg->hanging_starts_done = p.hanging_starts_done;
  msg->hanging_starts_total = p.hanging_starts_total;
  msg->candidates_so_far = p.candidates;
  msg->best_quality = p.best_quality;
  msg->elapsed_time = p.elapsed_ms / 1000.0;
}

}  // namespace place_planner
