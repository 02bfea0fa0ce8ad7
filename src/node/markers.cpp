#include "place_planner/ros/markers.h"

#include <algorithm>
#include <cstdio>

#include "place_planner/ros/conversions.h"

namespace place_planner {
namespace {

using visualization_msgs::Marker;

constexpr double kContactSphere = 0.008;   // m, diameter of a contact point sphere
constexpr double kFloorSphere = 0.01;      // m, diameter of a floor point sphere
constexpr double kNormalLength = 0.04;     // m, contact normal arrows
constexpr float kCandidateAlpha = 0.55f;   // translucent objects at the goal poses
constexpr float kPathAlpha = 0.12f;        // faded intermediate poses
constexpr size_t kMaxNormals = 24;         // arrows per candidate, evenly spread over its contacts

Marker makeMarker(const MarkerOptions& o, const char* ns, int id, int type) {
  Marker m;
  m.header.frame_id = o.frame_id;
  m.header.stamp = o.stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  return m;
}

void setColour(Marker* m, float r, float g, float b, float a) {
  m->color.r = r;
  m->color.g = g;
  m->color.b = b;
  m->color.a = a;
}

constexpr float kGripperAlpha = 0.7f;      // the gripper over the translucent object

Marker arrowMarker(const MarkerOptions& o, const char* ns, int id, const Eigen::Vector3d& from,
                   const Eigen::Vector3d& to, float r, float g, float b) {
  Marker arrow = makeMarker(o, ns, id, Marker::ARROW);
  arrow.scale.x = 0.004;  // shaft diameter
  arrow.scale.y = 0.009;  // head diameter
  arrow.scale.z = 0.015;  // head length
  setColour(&arrow, r, g, b, 1.0f);
  arrow.points.resize(2);
  toMsg(from, &arrow.points[0]);
  toMsg(to, &arrow.points[1]);
  return arrow;
}

// The mesh's triangles in its own frame; the marker pose places it.
void addTriangles(const Mesh& mesh, Marker* m) {
  m->points.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    for (int i : t) {
      geometry_msgs::Point p;
      toMsg(mesh.vertices[i], &p);
      m->points.push_back(p);
    }
  }
}

}  // namespace

void qualityColour(double quality, float* r, float* g, float* b) {
  const float q = static_cast<float>(std::clamp(quality, 0.0, 1.0));
  *r = q < 0.5f ? 1.0f : 2.0f * (1.0f - q);
  *g = q < 0.5f ? 2.0f * q : 1.0f;
  *b = 0.0f;
}

visualization_msgs::MarkerArray buildMarkers(const Mesh& object_O, const Mesh& area_W,
                                             const PlanResult& result, const MarkerOptions& o) {
  visualization_msgs::MarkerArray array;
  {
    Marker clear;
    clear.header.frame_id = o.frame_id;
    clear.header.stamp = o.stamp;
    clear.action = Marker::DELETEALL;
    array.markers.push_back(clear);
  }

  Marker area = makeMarker(o, marker_ns::kPlacementArea, 0, Marker::TRIANGLE_LIST);
  setColour(&area, 0.6f, 0.6f, 0.6f, 1.0f);
  addTriangles(area_W, &area);
  if (!area.points.empty()) array.markers.push_back(area);

  if (!result.floor_points_W.empty()) {
    Marker floor = makeMarker(o, marker_ns::kFloorPoints, 0, Marker::SPHERE_LIST);
    floor.scale.x = floor.scale.y = floor.scale.z = kFloorSphere;
    setColour(&floor, 1.0f, 0.55f, 0.0f, 1.0f);
    for (const auto& p_W : result.floor_points_W) {
      geometry_msgs::Point p;
      toMsg(p_W, &p);
      floor.points.push_back(p);
    }
    array.markers.push_back(floor);
  }

  const int n = std::min<int>(o.max_candidates, static_cast<int>(result.candidates.size()));
  Marker contacts = makeMarker(o, marker_ns::kContacts, 0, Marker::SPHERE_LIST);
  contacts.scale.x = contacts.scale.y = contacts.scale.z = kContactSphere;
  setColour(&contacts, 1.0f, 0.0f, 0.0f, 1.0f);
  int normal_id = 0;
  for (int i = 0; i < n; ++i) {
    const Candidate& c = result.candidates[i];
    Marker object = makeMarker(o, marker_ns::kCandidates, i, Marker::TRIANGLE_LIST);
    toMsg(c.X_WO, &object.pose);
    float r, g, b;
    // Colour: the push it resists (mean over directions; green at half its weight or more).
    qualityColour(c.stable ? std::min(1.0, c.push_resistance_mean / 0.5) : 0.0, &r, &g, &b);
    setColour(&object, r, g, b, kCandidateAlpha);
    addTriangles(object_O, &object);
    array.markers.push_back(object);

    if (i < o.text_count) {
      Marker text = makeMarker(o, marker_ns::kQuality, i, Marker::TEXT_VIEW_FACING);
      const Eigen::Vector3d above =
          c.X_WO * object_O.properties.center_of_mass +
          Eigen::Vector3d(0, 0, object_O.properties.bounding_radius + 0.03);
      toMsg(above, &text.pose.position);
      text.scale.z = 0.03;  // text height
      setColour(&text, 1.0f, 1.0f, 1.0f, 1.0f);
      char buf[96];
      std::snprintf(buf, sizeof buf, "#%d%s Q=%.2f push=%.2f%s%s", i + 1, c.hanging ? " hanging" : "", c.quality,
                    c.push_resistance_mean, c.stable ? "" : " (unstable)",
                    c.support == SupportKind::kSeen ? "" : c.support == SupportKind::kCompleted ? " (on unseen: completed)"
                                                                                                 : " (on unseen: area border)");
      text.text = buf;
      array.markers.push_back(text);
    }

    // Contacts, motions and the gripper of the best few only: the sphere model gives hundreds
    // of contacts per pose, and many grippers hide the scene.
    if (i >= std::max(1, o.text_count)) continue;
    const Placement& pl = c.placement;
    if (pl.checked && pl.approach.desired_distance > 0) {
      // The object's centre of mass from the pre-place pose along the approach (to the goal
      // when straight; to the first contact pose otherwise).
      const Eigen::Vector3d from = pl.pre_place_W * object_O.properties.center_of_mass;
      array.markers.push_back(arrowMarker(o, marker_ns::kApproach, i, from,
                                          from + pl.approach.desired_distance * pl.approach.direction,
                                          0.2f, 0.8f, 1.0f));
    }
    if (c.has_gripper_pose && o.gripper && !o.gripper->empty()) {
      Marker gripper = makeMarker(o, marker_ns::kGripper, i, Marker::TRIANGLE_LIST);
      toMsg(c.X_WF, &gripper.pose);
      const bool blocked = !pl.blocked.empty();
      setColour(&gripper, blocked ? 1.0f : 0.75f, blocked ? 0.2f : 0.75f, blocked ? 0.2f : 0.8f, kGripperAlpha);
      gripper.points.reserve(o.gripper->triangles.size() * 3);
      for (const auto& t : o.gripper->triangles) {
        for (int k : t) {
          geometry_msgs::Point p;
          toMsg(o.gripper->vertices_F[k], &p);
          gripper.points.push_back(p);
        }
      }
      array.markers.push_back(gripper);
    }
    if (c.has_gripper_pose && pl.retreat.desired_distance > 0) {
      const Eigen::Vector3d from = c.X_WF.translation();
      const Eigen::Vector3d to = c.X_WF * (pl.retreat.desired_distance * pl.retreat.direction);
      array.markers.push_back(arrowMarker(o, marker_ns::kRetreat, i, from, to, 1.0f, 0.4f, 1.0f));
    }
    const size_t stride = std::max<size_t>(1, (c.contacts.size() + kMaxNormals - 1) / kMaxNormals);
    for (size_t k = 0; k < c.contacts.size(); ++k) {
      const ContactPoint& contact = c.contacts[k];
      geometry_msgs::Point p;
      toMsg(contact.p_W, &p);
      contacts.points.push_back(p);
      // Contacts of a pose on surface no scan saw (completion.h): magenta, the others red.
      std_msgs::ColorRGBA colour;
      colour.r = 1.0f;
      colour.b = c.support == SupportKind::kSeen ? 0.0f : 1.0f;
      colour.a = 1.0f;
      contacts.colors.push_back(colour);
      if (k % stride != 0) continue;
      Marker arrow = makeMarker(o, marker_ns::kContactNormals, normal_id++, Marker::ARROW);
      arrow.scale.x = 0.003;  // shaft diameter
      arrow.scale.y = 0.006;  // head diameter
      arrow.scale.z = 0.01;   // head length
      setColour(&arrow, 0.1f, 0.3f, 1.0f, 1.0f);
      geometry_msgs::Point tip;
      toMsg(Eigen::Vector3d(contact.p_W + kNormalLength * contact.n_W), &tip);
      arrow.points = {p, tip};
      array.markers.push_back(arrow);
    }
  }
  if (!contacts.points.empty()) array.markers.push_back(contacts);

  if (n > 0) {
    const Candidate& best = result.candidates.front();
    // The goal pose itself is drawn in "candidates"; the path is everything before it.
    for (size_t k = 0; k + 1 < best.intermediate_poses.size(); ++k) {
      Marker step = makeMarker(o, marker_ns::kBestPath, static_cast<int>(k), Marker::TRIANGLE_LIST);
      toMsg(best.intermediate_poses[k], &step.pose);
      setColour(&step, 0.3f, 0.6f, 1.0f, kPathAlpha);
      addTriangles(object_O, &step);
      array.markers.push_back(step);
    }
  }
  return array;
}

}  // namespace place_planner
