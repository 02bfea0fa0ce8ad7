// The gripper's collision geometry from its URDF (gripper.h), with urdfdom (no ROS needed).
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "place_planner/manipulation/gripper.h"
#include "place_planner/infra/mesh_io.h"

namespace place_planner {
namespace {

Eigen::Isometry3d toIsometry(const urdf::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return T;
}

// Appends a triangle mesh (vertices in the link frame L) posed by X_FL.
void append(GripperModel& g, int link, const std::vector<Eigen::Vector3d>& v,
            const std::vector<std::array<int, 3>>& t, const Eigen::Isometry3d& X_FL) {
  const int base = static_cast<int>(g.vertices_F.size());
  for (const auto& p : v) g.vertices_F.push_back(X_FL * p);
  for (const auto& f : t) {
    g.triangles.push_back({base + f[0], base + f[1], base + f[2]});
    g.triangle_link.push_back(link);
  }
}

void box(GripperModel& g, int link, const Eigen::Vector3d& size, const Eigen::Isometry3d& X) {
  std::vector<Eigen::Vector3d> v;
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(), (i & 4 ? 0.5 : -0.5) * size.z());
  append(g, link, v, {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                      {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}}, X);
}

// Polygonal prisms and spheres circumscribe the true shape (vertices pushed out by the chord's
// sag), so a clearance the mesh reports is one the real link has.
void cylinder(GripperModel& g, int link, double r, double len, const Eigen::Isometry3d& X, int n = 24) {
  const double R = r / std::cos(M_PI / n);
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<int, 3>> t;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    v.emplace_back(R * std::cos(a), R * std::sin(a), -0.5 * len);
    v.emplace_back(R * std::cos(a), R * std::sin(a), 0.5 * len);
  }
  v.emplace_back(0, 0, -0.5 * len);
  v.emplace_back(0, 0, 0.5 * len);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    t.push_back({2 * i, 2 * j, 2 * i + 1});
    t.push_back({2 * j, 2 * j + 1, 2 * i + 1});
    t.push_back({2 * n, 2 * j, 2 * i});
    t.push_back({2 * n + 1, 2 * i + 1, 2 * j + 1});
  }
  append(g, link, v, t, X);
}

void sphere(GripperModel& g, int link, double r, const Eigen::Isometry3d& X, int n = 12) {
  const double R = r / (std::cos(M_PI / n) * std::cos(M_PI / n));
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<int, 3>> t;
  const int rings = n / 2;
  for (int k = 0; k <= rings; ++k)
    for (int i = 0; i < n; ++i) {
      const double th = M_PI * k / rings, ph = 2 * M_PI * i / n;
      v.emplace_back(R * std::sin(th) * std::cos(ph), R * std::sin(th) * std::sin(ph), R * std::cos(th));
    }
  for (int k = 0; k < rings; ++k)
    for (int i = 0; i < n; ++i) {
      const int a = k * n + i, b = k * n + (i + 1) % n, c = a + n, d = b + n;
      t.push_back({a, c, b});
      t.push_back({b, c, d});
    }
  append(g, link, v, t, X);
}

std::string defaultResolve(const std::string& uri, const std::string& base_dir) {
  if (uri.rfind("file://", 0) == 0) return uri.substr(7);
  if (uri.rfind("package://", 0) == 0)
    throw std::invalid_argument("mesh '" + uri + "': package:// needs a resolver (the node passes ROS's)");
  if (!uri.empty() && uri[0] != '/' && !base_dir.empty()) return base_dir + "/" + uri;
  return uri;
}

// Motion of a joint at position q (rad or m) in its own frame.
Eigen::Isometry3d jointMotion(const urdf::Joint& j, double q) {
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d axis(j.axis.x, j.axis.y, j.axis.z);
  if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS)
    M.linear() = Eigen::AngleAxisd(q, axis.normalized()).toRotationMatrix();
  else if (j.type == urdf::Joint::PRISMATIC)
    M.translation() = q * axis.normalized();
  return M;
}

GripperModel build(const urdf::ModelInterfaceSharedPtr& model, const std::vector<std::string>& links,
                   const std::map<std::string, double>& q, const MeshResolver& resolve, const std::string& base_dir) {
  if (!model) throw std::invalid_argument("URDF: does not parse (urdfdom reported the error above)");
  if (links.empty()) throw std::invalid_argument("gripper_links: empty (name at least the link whose frame is the grasp's)");
  for (const auto& kv : q)
    if (!model->getJoint(kv.first))
      throw std::invalid_argument("gripper_joint_positions: no joint '" + kv.first + "' in the URDF");
  auto position = [&](const urdf::Joint& j) -> double {
    if (j.mimic) {
      auto it = q.find(j.mimic->joint_name);
      const double base = it == q.end() ? 0.0 : it->second;
      return j.mimic->multiplier * base + j.mimic->offset;
    }
    auto it = q.find(j.name);
    return it == q.end() ? 0.0 : it->second;
  };
  // Pose of a link in the model's root frame, through its chain of parent joints.
  auto rootPose = [&](const std::string& name) {
    urdf::LinkConstSharedPtr link = model->getLink(name);
    if (!link) throw std::invalid_argument("gripper_links: no link '" + name + "' in the URDF");
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    for (int depth = 0; link->parent_joint; ++depth) {
      if (depth > 1000) throw std::invalid_argument("URDF: the chain above link '" + name + "' does not end");
      const urdf::Joint& j = *link->parent_joint;
      X = toIsometry(j.parent_to_joint_origin_transform) * jointMotion(j, position(j)) * X;
      link = model->getLink(j.parent_link_name);
      if (!link) throw std::invalid_argument("URDF: joint '" + j.name + "' has no parent link");
    }
    return X;
  };
  GripperModel g;
  g.links = links;
  const Eigen::Isometry3d X_root_F = rootPose(links[0]);
  for (size_t li = 0; li < links.size(); ++li) {
    const Eigen::Isometry3d X_FL = X_root_F.inverse() * rootPose(links[li]);
    for (const auto& col : model->getLink(links[li])->collision_array) {
      if (!col || !col->geometry) continue;
      const Eigen::Isometry3d X = X_FL * toIsometry(col->origin);
      const int link = static_cast<int>(li);
      const urdf::Geometry& geo = *col->geometry;
      switch (geo.type) {
        case urdf::Geometry::BOX: {
          const auto& b = static_cast<const urdf::Box&>(geo);
          box(g, link, Eigen::Vector3d(b.dim.x, b.dim.y, b.dim.z), X);
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& c = static_cast<const urdf::Cylinder&>(geo);
          cylinder(g, link, c.radius, c.length, X);
          break;
        }
        case urdf::Geometry::SPHERE:
          sphere(g, link, static_cast<const urdf::Sphere&>(geo).radius, X);
          break;
        case urdf::Geometry::MESH: {
          const auto& m = static_cast<const urdf::Mesh&>(geo);
          const std::string path = resolve ? resolve(m.filename) : defaultResolve(m.filename, base_dir);
          Mesh mesh;
          try {
            mesh = loadMesh(path);
          } catch (const std::exception& e) {
            throw std::invalid_argument("gripper link '" + links[li] + "': mesh '" + m.filename + "': " + e.what());
          }
          std::vector<Eigen::Vector3d> v;
          for (const auto& p : mesh.vertices) v.push_back(Eigen::Vector3d(m.scale.x * p.x(), m.scale.y * p.y(), m.scale.z * p.z()));
          append(g, link, v, mesh.triangles, X);
          break;
        }
      }
    }
  }
  if (g.empty()) throw std::invalid_argument("gripper_links: none of the links named has collision geometry");
  return g;
}

}  // namespace

GripperModel gripperFromUrdf(const std::string& urdf_xml, const std::vector<std::string>& links,
                             const std::map<std::string, double>& joint_positions, const MeshResolver& resolve) {
  return build(urdf::parseURDF(urdf_xml), links, joint_positions, resolve, "");
}

GripperModel gripperFromUrdfFile(const std::string& path, const std::vector<std::string>& links,
                                 const std::map<std::string, double>& joint_positions, const MeshResolver& resolve) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("URDF file '" + path + "' cannot be opened");
  std::stringstream ss;
  ss << in.rdbuf();
  const size_t slash = path.find_last_of('/');
  return build(urdf::parseURDF(ss.str()), links, joint_positions, resolve,
               slash == std::string::npos ? "." : path.substr(0, slash));
}

}  // namespace place_planner
