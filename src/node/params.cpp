#include "place_planner/ros/params.h"

#include <cmath>
#include <stdexcept>

#include <ros/console.h>
#include <ros/package.h>

#include <fstream>
#include <sstream>

#include "place_planner/manipulation/gripper.h"
#include "place_planner/validation/physics_validator.h"

#include <XmlRpcValue.h>

namespace place_planner {
namespace {

// Reads one parameter of the node's private namespace; a missing one keeps `value`.
class ParamReader {
 public:
  explicit ParamReader(const ros::NodeHandle& nh) : nh_(nh) {}

  std::string fullName(const std::string& key) const { return nh_.resolveName(key); }
  bool has(const std::string& key) const { return nh_.hasParam(key); }

  void read(const std::string& key, double* value) const {
    XmlRpc::XmlRpcValue v;
    if (!nh_.getParam(key, v)) return;
    if (!number(v, value)) fail(key, "must be a number");
  }

  void read(const std::string& key, int* value) const {
    XmlRpc::XmlRpcValue v;
    if (!nh_.getParam(key, v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeInt) fail(key, "must be an integer");
    *value = static_cast<int>(v);
  }

  void read(const std::string& key, bool* value) const {
    XmlRpc::XmlRpcValue v;
    if (!nh_.getParam(key, v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) fail(key, "must be true or false");
    *value = static_cast<bool>(v);
  }

  void read(const std::string& key, std::string* value) const {
    XmlRpc::XmlRpcValue v;
    if (!nh_.getParam(key, v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeString) fail(key, "must be a string");
    *value = static_cast<std::string>(v);
  }

  void read(const std::string& key, Eigen::Vector3d* value) const {
    XmlRpc::XmlRpcValue v;
    if (!nh_.getParam(key, v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeArray || v.size() != 3) {
      fail(key, "must be a list of 3 numbers");
    }
    for (int i = 0; i < 3; ++i) {
      if (!number(v[i], &(*value)[i])) fail(key, "must be a list of 3 numbers");
    }
  }

  void read(const std::string& key, std::vector<std::string>* value) const {
    XmlRpc::XmlRpcValue v;
    if (!nh_.getParam(key, v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeArray) fail(key, "must be a list of names");
    value->clear();
    for (int i = 0; i < v.size(); ++i) {
      if (v[i].getType() != XmlRpc::XmlRpcValue::TypeString) fail(key, "must be a list of names");
      value->push_back(static_cast<std::string>(v[i]));
    }
  }

  void read(const std::string& key, std::map<std::string, double>* value) const {
    XmlRpc::XmlRpcValue v;
    if (!nh_.getParam(key, v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeStruct) fail(key, "must be a map from joint name to a number");
    value->clear();
    for (auto& kv : v) {
      double x;
      if (!number(kv.second, &x) || !std::isfinite(x)) {
        fail(key, "must be a map from joint name to a number ('" + kv.first + "' is not)");
      }
      (*value)[kv.first] = x;
    }
  }

  // The value of a parameter named `key` found by searching up from the private namespace.
  bool search(const std::string& key, std::string* value, std::string* where) const {
    if (!nh_.searchParam(key, *where)) return false;
    return nh_.getParam(*where, *value);
  }

  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw std::invalid_argument("parameter " + fullName(key) + " " + why);
  }

 private:
  static bool number(XmlRpc::XmlRpcValue& v, double* out) {
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      *out = static_cast<double>(v);
      return true;
    }
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {  // YAML "1" is an int
      *out = static_cast<int>(v);
      return true;
    }
    return false;
  }

  ros::NodeHandle nh_;
};

BackendKind backendFromString(const std::string& s) {
  if (s == "auto") return BackendKind::kAuto;
  if (s == "cpu") return BackendKind::kCpu;
  if (s == "cuda") return BackendKind::kCuda;
  throw std::invalid_argument("backend = '" + s + "' is unknown (use auto, cpu or cuda)");
}

// package://pkg/rest through ROS's package path, file:// and absolute paths as they are,
// relative ones against base_dir.
std::string resolveMeshUri(const std::string& uri, const std::string& base_dir) {
  if (uri.rfind("package://", 0) == 0) {
    const std::string rest = uri.substr(10);
    const size_t slash = rest.find('/');
    const std::string pkg = rest.substr(0, slash);
    const std::string dir = ros::package::getPath(pkg);
    if (dir.empty()) throw std::invalid_argument("mesh '" + uri + "': package '" + pkg + "' not found");
    return slash == std::string::npos ? dir : dir + rest.substr(slash);
  }
  if (uri.rfind("file://", 0) == 0) return uri.substr(7);
  if (!uri.empty() && uri[0] != '/' && !base_dir.empty()) return base_dir + "/" + uri;
  return uri;
}

// The gripper of NodeConfig's gripper parameters (doc/manipulation.md); null when no links.
std::shared_ptr<const GripperModel> loadGripper(const NodeConfig& c, const ParamReader& r) {
  if (c.gripper_links.empty()) return nullptr;
  std::string xml, source, base_dir = c.gripper_mesh_dir;
  if (!c.urdf_file.empty()) {
    std::ifstream in(c.urdf_file);
    if (!in) r.fail("urdf_file", "= '" + c.urdf_file + "' cannot be read");
    std::ostringstream ss;
    ss << in.rdbuf();
    xml = ss.str();
    source = "parameter " + r.fullName("urdf_file") + " ('" + c.urdf_file + "')";
    const size_t slash = c.urdf_file.rfind('/');
    if (base_dir.empty() && slash != std::string::npos) base_dir = c.urdf_file.substr(0, slash);
  } else {
    std::string where;
    if (!r.search(c.robot_description_param, &xml, &where) || xml.empty()) {
      r.fail("gripper_links", "is set, but there is no URDF: neither " + r.fullName("urdf_file") +
                                  " nor a parameter '" + c.robot_description_param + "' (" +
                                  r.fullName("robot_description_param") + ")");
    }
    source = "parameter " + where;
  }
  try {
    auto g = std::make_shared<GripperModel>(gripperFromUrdf(
        xml, c.gripper_links, c.gripper_joint_positions,
        [&](const std::string& uri) { return resolveMeshUri(uri, base_dir); }));
    if (g->empty()) r.fail("gripper_links", "name links without collision geometry in the URDF of " + source);
    ROS_INFO("place_planner: gripper of %zu links (%zu triangles, frame '%s') from the URDF of %s",
             c.gripper_links.size(), g->triangles.size(), c.gripper_links.front().c_str(), source.c_str());
    return g;
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).rfind("parameter ", 0) == 0) throw;
    r.fail("gripper_links", "cannot be loaded from the URDF of " + source + ": " + e.what());
  }
}

}  // namespace

RankOrder rankOrderFromName(const std::string& name) {
  if (name == "quality") return RankOrder::kQuality;
  if (name == "lowest") return RankOrder::kLowest;
  if (name == "nearest") return RankOrder::kNearest;
  throw std::invalid_argument("rank_order = '" + name + "' is unknown (use quality, lowest or nearest)");
}

const char* rankOrderName(RankOrder order) {
  switch (order) {
    case RankOrder::kQuality: return "quality";
    case RankOrder::kLowest: return "lowest";
    case RankOrder::kNearest: return "nearest";
  }
  return "quality";
}

NodeConfig loadNodeConfig(const ros::NodeHandle& nh) {
  const ParamReader r(nh);
  NodeConfig c;
  r.read("planning_frame", &c.planning_frame);
  r.read("tf_timeout", &c.tf_timeout);
  r.read("feedback_period", &c.feedback_period);
  r.read("marker_candidates", &c.marker_candidates);
  r.read("marker_text_count", &c.marker_text_count);
  r.read("verify_top_k", &c.verify_top_k);
  r.read("verify_engines", &c.verify_engines);
  if (c.planning_frame.empty()) r.fail("planning_frame", "must not be empty");
  if (!(c.tf_timeout >= 0 && c.tf_timeout <= 60)) r.fail("tf_timeout", "is out of range (0 .. 60 s)");
  if (!(c.feedback_period > 0 && c.feedback_period <= 0.1)) {
    r.fail("feedback_period", "is out of range (0 < feedback_period <= 0.1 s)");
  }
  if (c.marker_candidates < 0) r.fail("marker_candidates", "is out of range (>= 0)");
  if (c.marker_text_count < 0) r.fail("marker_text_count", "is out of range (>= 0)");
  if (c.verify_top_k < 0 || c.verify_top_k > 100) {
    r.fail("verify_top_k", "is out of range (0 .. 100, 0 = off)");
  }
  try {
    validation::enginesFromString(c.verify_engines);
  } catch (const std::invalid_argument&) {
    r.fail("verify_engines", "'" + c.verify_engines + "' is none of bullet, mujoco, both");
  }

  // PlannerConfig, field for field (include/place_planner/config.h).
  PlannerConfig& p = c.planner;
  r.read("gravity", &p.gravity);
  r.read("approach", &p.approach);
  r.read("friction", &p.friction);
  r.read("floor_point_spacing", &p.floor_point_spacing);
  r.read("min_floor_points", &p.min_floor_points);
  r.read("lowest_n", &p.lowest_n);
  r.read("max_rotations", &p.max_rotations);
  r.read("sphere_radius", &p.sphere_radius);
  r.read("grid_cell_size", &p.grid_cell_size);
  std::string orientation = toString(p.orientation);
  r.read("orientation", &orientation);
  r.read("max_resting_faces", &p.max_resting_faces);
  r.read("robust_shift", &p.robust_shift);
  r.read("robust_tilt_deg", &p.robust_tilt_deg);
  r.read("robust_com_offset", &p.robust_com_offset);
  r.read("robust_min_share", &p.robust_min_share);
  r.read("robust_min_share_hanging", &p.robust_min_share_hanging);
  r.read("robust_check", &p.robust_check);
  r.read("robust_recheck_caught", &p.robust_recheck_caught);
  r.read("rock_settle", &p.rock_settle);
  // The budget is in seconds like every time of the ROS interface (doc/node.md, "Units"); the
  // core's field is in ms. time_budget_ms (the older name) is still read, with a warning.
  double budget_s = p.time_budget_ms / 1000.0;
  r.read("time_budget_s", &budget_s);
  if (r.has("time_budget_ms")) {
    if (r.has("time_budget_s")) {
      r.fail("time_budget_ms", "and time_budget_s are both set: keep time_budget_s (seconds)");
    }
    double budget_ms = p.time_budget_ms;
    r.read("time_budget_ms", &budget_ms);
    ROS_WARN("parameter %s is deprecated: use time_budget_s (seconds); read as %g s",
             r.fullName("time_budget_ms").c_str(), budget_ms / 1000.0);
    budget_s = budget_ms / 1000.0;
  }
  if (!(std::isfinite(budget_s) && budget_s >= 0)) {
    r.fail("time_budget_s", "= " + std::to_string(budget_s) + " is out of range (>= 0 s, 0 = no budget)");
  }
  p.time_budget_ms = budget_s * 1000.0;
  r.read("max_candidates", &p.max_candidates);
  r.read("threads", &p.threads);
  r.read("max_local_optimisation_steps", &p.max_local_optimisation_steps);
  r.read("min_support_width", &p.min_support_width);
  r.read("min_tipping_angle_deg", &p.min_tipping_angle_deg);
  // start_orientation is not a parameter: each goal's object_pose gives it.
  r.read("min_quality", &p.min_quality);
  r.read("merge_distance", &p.merge_distance);
  r.read("merge_angle_deg", &p.merge_angle_deg);
  std::string backend = "auto";
  r.read("backend", &backend);
  r.read("region_min", &p.region_min);
  r.read("region_max", &p.region_max);
  // Bounded work.
  r.read("max_triangles", &p.max_triangles);
  r.read("max_floor_points", &p.max_floor_points);
  double max_tree_nodes = static_cast<double>(p.max_tree_nodes);  // a long; YAML ints are 32 bit
  r.read("max_tree_nodes", &max_tree_nodes);
  if (!(std::isfinite(max_tree_nodes) && max_tree_nodes >= 100 && max_tree_nodes <= 9e15 &&
        max_tree_nodes == std::floor(max_tree_nodes))) {
    r.fail("max_tree_nodes", "is out of range (a whole number >= 100)");
  }
  p.max_tree_nodes = static_cast<long>(max_tree_nodes);
  r.read("max_model_mb", &p.max_model_mb);
  r.read("max_object_size", &p.max_object_size);
  r.read("max_area_size", &p.max_area_size);
  // Manipulation. has_grasp and grasp come with each goal.
  r.read("max_gripper_tilt_deg", &p.max_gripper_tilt_deg);
  r.read("gripper_min_clearance", &p.gripper_min_clearance);
  r.read("keep_colliding", &p.keep_colliding);
  r.read("approach_distance", &p.approach_distance);
  r.read("approach_min_distance", &p.approach_min_distance);
  r.read("retreat_distance", &p.retreat_distance);
  r.read("retreat_min_distance", &p.retreat_min_distance);
  std::string rank_order = rankOrderName(p.rank_order);
  r.read("rank_order", &rank_order);
  std::string placement = toString(p.placement);
  r.read("placement", &placement);
  r.read("prefer_near", &p.prefer_near);
  r.read("min_edge_clearance", &p.min_edge_clearance);
  r.read("scan_noise", &p.scan_noise);
  r.read("scan_unseen_reach", &p.scan_unseen_reach);
  r.read("closed_scan", &p.closed_scan);
  try {
    p.rank_order = rankOrderFromName(rank_order);
    p.placement = placementKindFromString(placement);
    p.orientation = orientationModeFromString(orientation);
    p.backend = backendFromString(backend);
    validate(p);  // "friction = -0.1 is out of range (...)"
  } catch (const std::invalid_argument& e) {
    // validate() starts with the field name, which is the parameter's name.
    std::string what = e.what();
    if (what.rfind("orientation_mode", 0) == 0) what.replace(0, 16, "orientation");
    throw std::invalid_argument("parameter " + r.fullName("") + "/" + what);
  }
  r.read("robot_description_param", &c.robot_description_param);
  r.read("urdf_file", &c.urdf_file);
  r.read("gripper_links", &c.gripper_links);
  r.read("gripper_joint_positions", &c.gripper_joint_positions);
  r.read("gripper_mesh_dir", &c.gripper_mesh_dir);
  r.read("object_shape_frame", &c.object_shape_frame);
  r.read("placement_area_shape_frame", &c.placement_area_shape_frame);
  if (c.robot_description_param.empty()) r.fail("robot_description_param", "must not be empty");
  p.gripper = loadGripper(c, r);
  return c;
}

}  // namespace place_planner
