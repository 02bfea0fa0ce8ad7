#include "place_planner/infra/scenes.h"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

namespace place_planner {
namespace scenes {
namespace {

struct Builder {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  void add(const Mesh& m, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity(),
           const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
    const int off = static_cast<int>(v.size());
    for (const auto& p : m.vertices) v.push_back(R * p + t);
    for (auto poly : m.patches) {
      for (int& i : poly) i += off;
      f.push_back(poly);
    }
  }
  Mesh build(const std::string& name) const { return buildMesh(v, f, name); }
};

Eigen::Matrix3d rotZ(double deg) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

Mesh box(double sx, double sy, double sz, const Eigen::Vector3d& c) {
  const double x = sx / 2, y = sy / 2, z = sz / 2;
  std::vector<Eigen::Vector3d> v = {{-x, -y, -z}, {x, -y, -z}, {x, y, -z}, {-x, y, -z},
                                    {-x, -y, z},  {x, -y, z},  {x, y, z},  {-x, y, z}};
  for (auto& p : v) p += c;
  // Counter-clockwise seen from outside.
  std::vector<std::vector<int>> f = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                     {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  return buildMesh(v, f, "box");
}

namespace {
// Closed prism along z over an ellipse (semi-axes a along x, b along y), centred at the origin.
Mesh ellipticPrism(double a, double b, double h, int segments, const char* name) {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  for (int i = 0; i < segments; ++i) {
    const double phi = 2 * M_PI * i / segments;
    v.emplace_back(a * std::cos(phi), b * std::sin(phi), -h / 2);
  }
  for (int i = 0; i < segments; ++i) v.emplace_back(v[i].x(), v[i].y(), h / 2);
  std::vector<int> bottom, top;
  for (int i = 0; i < segments; ++i) {
    bottom.push_back(segments - 1 - i);
    top.push_back(segments + i);
    const int j = (i + 1) % segments;
    f.push_back({i, j, segments + j, segments + i});
  }
  f.push_back(bottom);
  f.push_back(top);
  return buildMesh(v, f, name);
}
}  // namespace

Mesh cylinder(double r, double h, int segments) { return ellipticPrism(r, r, h, segments, "cylinder"); }

Mesh ellipticCylinder(double a, double b, double h, int segments) {
  return ellipticPrism(a, b, h, segments, "elliptic cylinder");
}

Mesh plane(double sx, double sy, double tilt_deg) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(tilt_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  std::vector<Eigen::Vector3d> v = {R * Eigen::Vector3d(-sx / 2, -sy / 2, 0),
                                    R * Eigen::Vector3d(sx / 2, -sy / 2, 0),
                                    R * Eigen::Vector3d(sx / 2, sy / 2, 0),
                                    R * Eigen::Vector3d(-sx / 2, sy / 2, 0)};
  return buildMesh(v, {{0, 1, 2, 3}}, "plane");
}

Mesh vTrough(double size, double angle_deg) {
  const double a = angle_deg * M_PI / 180.0;
  const double dy = size / 2 * std::cos(a), dz = size / 2 * std::sin(a);
  std::vector<Eigen::Vector3d> v = {{-size / 2, -dy, dz}, {size / 2, -dy, dz}, {size / 2, 0, 0},
                                    {-size / 2, 0, 0},    {size / 2, dy, dz},  {-size / 2, dy, dz}};
  return buildMesh(v, {{0, 3, 2, 1}, {3, 5, 4, 2}}, "v_trough");
}

Mesh merge(const std::vector<Mesh>& parts, const std::string& name) {
  Builder b;
  for (const auto& m : parts) b.add(m);
  return b.build(name);
}

Mesh table() { return box(1.0, 0.8, 0.03, {0, 0, -0.015}); }

Mesh dishRack() {
  Builder b;
  b.add(box(0.45, 0.45, 0.01, {0, 0, 0.005}));
  // Rows of pegs along x, 6 cm apart in y: a plate stands between two rows.
  for (int iy = -3; iy <= 3; ++iy)
    for (int ix = -4; ix <= 4; ++ix)
      b.add(box(0.01, 0.01, 0.08, {0.05 * ix, 0.06 * iy, 0.05}));
  return b.build("dish_rack");
}

Mesh openBox() {
  Builder b;
  const double sx = 0.3, sy = 0.25, h = 0.12, t = 0.01;
  b.add(box(sx, sy, t, {0, 0, t / 2}));
  b.add(box(t, sy, h, {-sx / 2 + t / 2, 0, h / 2}));
  b.add(box(t, sy, h, {sx / 2 - t / 2, 0, h / 2}));
  b.add(box(sx - 2 * t, t, h, {0, -sy / 2 + t / 2, h / 2}));
  b.add(box(sx - 2 * t, t, h, {0, sy / 2 - t / 2, h / 2}));
  return b.build("open_box");
}

Mesh binderStack() {
  Builder b;
  b.add(box(0.6, 0.5, 0.02, {0, 0, 0.01}));
  const double th = 0.05;
  b.add(box(0.31, 0.26, th), rotZ(0), {-0.05, 0.0, 0.02 + th / 2});
  b.add(box(0.31, 0.26, th), rotZ(12), {0.0, 0.03, 0.02 + 1.5 * th});
  b.add(box(0.31, 0.26, th), rotZ(-8), {0.04, -0.02, 0.02 + 2.5 * th});
  return b.build("binder_stack");
}

namespace {
// A closed box whose faces are split into n x n quads (outward CCW), added to b.
void splitBox(Builder& b, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n) {
  const Eigen::Vector3d d = hi - lo;
  auto face = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    const int base = static_cast<int>(b.v.size());
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) b.v.push_back(o + u * (double(i) / n) + v * (double(j) / n));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const int a = base + i * (n + 1) + j;
        b.f.push_back({a, a + n + 1, a + n + 2, a + 1});  // u x v is the outward normal
      }
  };
  const Eigen::Vector3d X(d.x(), 0, 0), Y(0, d.y(), 0), Z(0, 0, d.z());
  face(lo, Y, X);           // -z
  face(lo + Z, X, Y);       // +z
  face(lo, X, Z);           // -y
  face(lo + Y, Z, X);       // +y
  face(lo, Z, Y);           // -x
  face(lo + X, Y, Z);       // +x
}
}  // namespace

Mesh shelfUnit(int n) {
  Builder b;
  for (int k = 0; k < 6; ++k) {
    const double top = 0.02 + 0.45 * k;
    splitBox(b, {-0.5, -0.2, top - 0.02}, {0.5, 0.2, top}, n);
  }
  splitBox(b, {-0.52, -0.2, 0.0}, {-0.5, 0.2, 2.4}, n);
  splitBox(b, {0.5, -0.2, 0.0}, {0.52, 0.2, 2.4}, n);
  splitBox(b, {-0.52, 0.2, 0.0}, {0.52, 0.22, 2.4}, n);
  return b.build("shelf");
}

Mesh pegWall(double rise_deg) {
  Builder b;
  b.add(box(0.6, 0.02, 0.6, {0, 0.1, 0.3}));
  // Pegs 12 mm thick sticking out 10 cm towards -y, rising towards their tips, 20 cm apart.
  const double kRise = rise_deg * M_PI / 180;
  const Eigen::Matrix3d along_y =
      Eigen::AngleAxisd(-M_PI / 2 - kRise, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (const double z : {0.3, 0.5})
    for (const double x : {-0.2, 0.0, 0.2})
      b.add(cylinder(0.006, 0.1, 12), along_y, {x, 0.092 - 0.05 * std::cos(kRise), z + 0.05 * std::sin(kRise)});
  return b.build("peg_wall");
}

Mesh mugTree() {
  Builder b;
  b.add(cylinder(0.1, 0.02, 32), Eigen::Matrix3d::Identity(), {0, 0, 0.01});
  b.add(cylinder(0.012, 0.36, 16), Eigen::Matrix3d::Identity(), {0, 0, 0.2});
  // Four arms 9 cm long, 10 mm thick, rising 25 degrees, at two heights.
  for (int k = 0; k < 4; ++k) {
    const double yaw = M_PI / 2 * k;
    const Eigen::Vector3d dir(std::cos(yaw) * std::cos(25 * M_PI / 180), std::sin(yaw) * std::cos(25 * M_PI / 180),
                              std::sin(25 * M_PI / 180));
    const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), dir).toRotationMatrix();
    const double z = k % 2 ? 0.22 : 0.30;
    b.add(cylinder(0.005, 0.09, 12), R, Eigen::Vector3d(0, 0, z) + (0.01 + 0.045) * dir);
  }
  return b.build("mug_tree");
}

Mesh mugRack(double rise_deg) {
  Builder b;
  b.add(box(0.5, 0.02, 0.12, {0, 0.01, 0.4}));
  // Four pegs 8 mm thick and 8 cm long, rising towards -y, 12 cm apart, each with a knob on its
  // end (a part of its own, overlapping the peg's end).
  const double rise = rise_deg * M_PI / 180;
  const Eigen::Vector3d d(0, -std::cos(rise), std::sin(rise));
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d).toRotationMatrix();
  for (const double x : {-0.18, -0.06, 0.06, 0.18}) {
    b.add(cylinder(0.004, 0.08, 16), R, Eigen::Vector3d(x, 0, 0.4) + 0.04 * d);
    b.add(cylinder(0.007, 0.008, 16), R, Eigen::Vector3d(x, 0, 0.4) + 0.08 * d);
  }
  return b.build("mug_rack");
}

Mesh cupHooks() {
  Builder b;
  b.add(box(0.6, 0.2, 0.02, {0, 0, 0.41}));
  // Three hooks of 6 mm wire 20 cm apart, each a stem 5 cm down from the board's underside, an
  // arm 3.5 cm out towards -y and a tip turned up 1 cm at its end.
  const Eigen::Matrix3d along_y = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (const double x : {-0.2, 0.0, 0.2}) {
    b.add(cylinder(0.003, 0.05, 12), Eigen::Matrix3d::Identity(), {x, 0, 0.375});
    b.add(cylinder(0.003, 0.041, 12), along_y, {x, -0.0175, 0.35});
    b.add(cylinder(0.003, 0.01, 12), Eigen::Matrix3d::Identity(), {x, -0.035, 0.355});
  }
  return b.build("cup_hooks");
}

Mesh tube(double r_in, double r_out, double h, int segments) {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * M_PI * i / segments, c = std::cos(a), s = std::sin(a);
    for (const double r : {r_out, r_in})
      for (const double z : {0.0, h}) v.emplace_back(r * c, r * s, z);
  }
  // Per segment: outer bottom, outer top, inner bottom, inner top (4 i + 0..3); quads wound
  // outwards (the inner wall's outside faces the hole).
  for (int i = 0; i < segments; ++i) {
    const int a = 4 * i, b = 4 * ((i + 1) % segments);
    f.push_back({a, b, b + 1, a + 1});          // outer wall
    f.push_back({a + 2, a + 3, b + 3, b + 2});  // inner wall
    f.push_back({a + 1, b + 1, b + 3, a + 3});  // top
    f.push_back({a, a + 2, b + 2, b});          // bottom
  }
  return buildMesh(v, f, "tube");
}

Mesh mug() {
  Builder b;
  const Mesh body = cylinder(0.04, 0.1, 24);
  b.add(body, Eigen::Matrix3d::Identity(), {0, 0, 0.05});
  b.add(box(0.02, 0.015, 0.06), Eigen::Matrix3d::Identity(), {0.05, 0, 0.05});
  return b.build("mug");
}

Mesh torus(double R, double r, int segments, int sides) {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> f;
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < sides; ++j) {
      const double u = 2 * M_PI * i / segments, w = 2 * M_PI * j / sides;
      v.emplace_back((R + r * std::cos(w)) * std::cos(u), (R + r * std::cos(w)) * std::sin(u), r * std::sin(w));
    }
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < sides; ++j) {
      const int a = i * sides + j, b = ((i + 1) % segments) * sides + j, c = ((i + 1) % segments) * sides + (j + 1) % sides,
                d = i * sides + (j + 1) % sides;
      f.push_back({a, b, c, d});
    }
  return buildMesh(v, f, "torus");
}

Mesh loopMug() {
  Builder b;
  b.add(cylinder(0.04, 0.1, 24), Eigen::Matrix3d::Identity(), {0, 0, 0.05});
  // A C of three bars: an opening 2.8 cm tall and 2 cm deep, 1.6 cm across.
  b.add(box(0.026, 0.016, 0.01, {0.051, 0, 0.084}));
  b.add(box(0.026, 0.016, 0.01, {0.051, 0, 0.016}));
  b.add(box(0.01, 0.016, 0.078, {0.069, 0, 0.05}));
  return b.build("loop_mug");
}

Mesh plate() {
  Builder b;
  b.add(cylinder(0.12, 0.02, 32), Eigen::Matrix3d::Identity(), {0, 0, 0.01});
  return b.build("plate");
}

Mesh pen() {
  Builder b;
  b.add(cylinder(0.006, 0.14, 12), Eigen::Matrix3d::Identity(), {0, 0, 0.07});
  return b.build("pen");
}

Mesh byName(const std::string& n) {
  if (n == "table") return table();
  if (n == "dish_rack") return dishRack();
  if (n == "open_box") return openBox();
  if (n == "binder_stack") return binderStack();
  if (n == "shelf") return shelfUnit();
  if (n == "mug") return mug();
  if (n == "plate") return plate();
  if (n == "pen") return pen();
  if (n == "peg_wall") return pegWall();
  if (n == "peg_wall_rising") return pegWall(10.0);  // pegs rising 10 degrees towards their tips
  if (n == "mug_tree") return mugTree();
  if (n == "loop_mug") return loopMug();
  if (n == "ring") return torus(0.03, 0.006);
  if (n == "mug_rack") return mugRack();
  if (n == "cup_hooks") return cupHooks();
  if (n == "tape_roll") return tube(0.038, 0.055, 0.048);
  if (n == "cube") return box(0.1, 0.1, 0.1, {0, 0, 0.05});
  throw std::invalid_argument("unknown built-in scene '" + n +
                              "' (table, dish_rack, open_box, binder_stack, shelf, peg_wall, peg_wall_rising, mug_tree, mug_rack, cup_hooks, mug, loop_mug, ring, tape_roll, plate, pen, cube)");
}

std::vector<std::string> areaNames() { return {"table", "dish_rack", "open_box", "binder_stack"}; }
std::vector<std::string> objectNames() { return {"mug", "plate", "pen", "cube"}; }

}  // namespace scenes
}  // namespace place_planner
