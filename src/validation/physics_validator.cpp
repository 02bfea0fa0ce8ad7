// Bullet model of one object/area pair: shapes built once, a fresh world per simulation.
#include "place_planner/validation/physics_validator.h"

#include <LinearMath/btConvexHullComputer.h>
#include <btBulletDynamicsCommon.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <sstream>
#include <unordered_map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "place_planner/infra/parallel_for.h"
#include "place_planner/infra/stable_sort.h"
#include "place_planner/search/loops.h"
#include "place_planner/validation/mujoco_validator.h"

namespace place_planner {
namespace validation {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

btVector3 toBt(const Eigen::Vector3d& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
Eigen::Vector3d fromBt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

btTransform toBt(const Eigen::Isometry3d& X) {
  const Eigen::Matrix3d& R = X.linear();
  btMatrix3x3 B(btScalar(R(0, 0)), btScalar(R(0, 1)), btScalar(R(0, 2)), btScalar(R(1, 0)),
                btScalar(R(1, 1)), btScalar(R(1, 2)), btScalar(R(2, 0)), btScalar(R(2, 1)),
                btScalar(R(2, 2)));
  return btTransform(B, toBt(Eigen::Vector3d(X.translation())));
}

Eigen::Isometry3d fromBt(const btTransform& T) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  const btMatrix3x3& B = T.getBasis();
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = B[r][c];
  // Single-precision Bullet: re-orthonormalise so X stays an isometry.
  const Eigen::Quaterniond q(R);
  X.linear() = q.normalized().toRotationMatrix();
  X.translation() = fromBt(T.getOrigin());
  return X;
}

void require(bool ok, const char* field, double value, const char* range) {
  if (ok) return;
  std::ostringstream os;
  os << "ValidatorConfig." << field << " = " << value << " is out of range (" << range << ")";
  throw std::invalid_argument(os.str());
}

void validateConfig(const ValidatorConfig& c) {
  require(c.friction >= 0, "friction", c.friction, "must be >= 0");
  require(c.density > 0, "density", c.density, "must be > 0");
  require(c.time_step > 0 && c.time_step <= 0.02, "time_step", c.time_step, "(0, 0.02] s");
  require(c.solver_iterations >= 1, "solver_iterations", c.solver_iterations, "must be >= 1");
  require(c.margin > 0, "margin", c.margin, "must be > 0");
  require(c.linear_damping >= 0 && c.linear_damping <= 1, "linear_damping", c.linear_damping, "must be in [0, 1]");
  require(c.angular_damping >= 0 && c.angular_damping <= 1, "angular_damping", c.angular_damping, "must be in [0, 1]");
  require(c.world_scale >= 0.01 && c.world_scale <= 1000, "world_scale", c.world_scale, "[0.01, 1000]");
  require(c.piece_thickness >= 0, "piece_thickness", c.piece_thickness, "must be >= 0");
  require(c.piece_max_triangles >= 1, "piece_max_triangles", c.piece_max_triangles, ">= 1");
  require(c.piece_max_size > 0, "piece_max_size", c.piece_max_size, "must be > 0");
  require(c.gravity.allFinite() && c.gravity.norm() > 1e-6, "gravity.norm()", c.gravity.norm(),
          "must be finite and non-zero");
  require(c.settle_time > 0, "settle_time", c.settle_time, "must be > 0");
  require(c.release_gap >= 0, "release_gap", c.release_gap, "must be >= 0");
  require(c.max_translation > 0, "max_translation", c.max_translation, "must be > 0");
  require(c.max_rotation_deg > 0, "max_rotation_deg", c.max_rotation_deg, "must be > 0");
  require(c.early_accept_steps >= 0, "early_accept_steps", c.early_accept_steps, "must be >= 0");
  require(c.rest_steps >= 1, "rest_steps", c.rest_steps, "must be >= 1");
  require(c.max_drop_time > 0, "max_drop_time", c.max_drop_time, "must be > 0");
}

// Triangles binned by their bounding boxes into cubic cells of size h: a segment no longer than
// h meets only triangles listed in the (at most 2 x 2 x 2) cells its own box touches. It makes
// the thickness rays of makeConvexPieces local: 16 s -> well under 1 s for a 16k-triangle mug.
class TriangleGrid {
 public:
  TriangleGrid(const Mesh& m, double h) : h_(h), stamp_(m.triangles.size(), 0) {
    for (int t = 0; t < static_cast<int>(m.triangles.size()); ++t) {
      Eigen::Vector3d lo = m.vertices[m.triangles[t][0]], hi = lo;
      for (int k = 1; k < 3; ++k) {
        lo = lo.cwiseMin(m.vertices[m.triangles[t][k]]);
        hi = hi.cwiseMax(m.vertices[m.triangles[t][k]]);
      }
      forCells(lo, hi, [&](long long key) { cells_[key].push_back(t); });
    }
  }

  // Triangles whose boxes may meet the segment a-b (|a - b| <= h), each once.
  const std::vector<int>& near(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    ++round_;
    out_.clear();
    forCells(a.cwiseMin(b), a.cwiseMax(b), [&](long long key) {
      const auto it = cells_.find(key);
      if (it == cells_.end()) return;
      for (int t : it->second) {
        if (stamp_[t] == round_) continue;
        stamp_[t] = round_;
        out_.push_back(t);
      }
    });
    return out_;
  }

 private:
  template <typename F>
  void forCells(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, F&& f) const {
    const Eigen::Vector3i a = (lo / h_).array().floor().cast<int>();
    const Eigen::Vector3i b = (hi / h_).array().floor().cast<int>();
    for (int x = a.x(); x <= b.x(); ++x)
      for (int y = a.y(); y <= b.y(); ++y)
        for (int z = a.z(); z <= b.z(); ++z)
          f((static_cast<long long>(x & 0x1fffff) << 42) | (static_cast<long long>(y & 0x1fffff) << 21) |
            static_cast<long long>(z & 0x1fffff));
  }

  double h_;
  std::unordered_map<long long, std::vector<int>> cells_;
  std::vector<unsigned> stamp_;
  unsigned round_ = 0;
  std::vector<int> out_;
};

// Distance along unit d from p to the nearest of the triangles `candidates` not in `skip`
// (Moller-Trumbore); infinity when the ray meets none of them (open meshes, or beyond the
// candidates' reach).
double rayDepth(const Mesh& m, const Eigen::Vector3d& p, const Eigen::Vector3d& d,
                const std::vector<int>& candidates, const std::vector<int>& skip) {
  double best = std::numeric_limits<double>::infinity();
  for (int t : candidates) {
    if (std::find(skip.begin(), skip.end(), t) != skip.end()) continue;
    const Eigen::Vector3d& a = m.vertices[m.triangles[t][0]];
    const Eigen::Vector3d e1 = m.vertices[m.triangles[t][1]] - a;
    const Eigen::Vector3d e2 = m.vertices[m.triangles[t][2]] - a;
    const Eigen::Vector3d h = d.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-15) continue;
    const Eigen::Vector3d s = p - a;
    const double u = s.dot(h) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    const double dist = e2.dot(q) / det;
    if (dist > 1e-7 && dist < best) best = dist;
  }
  return best;
}

// The convex hull of 2-D points (OpenCV's), its area and its least width: across one of its
// edges (the rotating calipers' rule).
std::vector<cv::Point2f> convexHull2d(const std::vector<Eigen::Vector2d>& p) {
  std::vector<cv::Point2f> pts, hull;
  for (const auto& q : p) pts.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
  if (pts.size() >= 3) cv::convexHull(pts, hull);
  return hull;
}

double polygonArea(const std::vector<cv::Point2f>& h) { return h.size() < 3 ? 0.0 : cv::contourArea(h); }

double polygonWidth(const std::vector<cv::Point2f>& h) {
  if (h.size() < 3) return 0.0;
  double w = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < h.size(); ++i) {
    const cv::Point2d a = h[i], e = cv::Point2d(h[(i + 1) % h.size()]) - a;
    const double len = std::hypot(e.x, e.y);
    if (len < 1e-12) continue;
    double far = 0;
    for (const cv::Point2d p : h) far = std::max(far, std::abs(e.x * (p.y - a.y) - e.y * (p.x - a.x)) / len);
    w = std::min(w, far);
  }
  return w;
}

// A group's vertices seen along n (in-plane coordinates).
std::vector<Eigen::Vector2d> projected(const Mesh& m, const std::vector<int>& group, const Eigen::Vector3d& n) {
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Eigen::Vector2d> q;
  for (int t : group)
    for (int k = 0; k < 3; ++k) q.emplace_back(m.vertices[m.triangles[t][k]].dot(u), m.vertices[m.triangles[t][k]].dot(v));
  return q;
}

// btConvexHullComputer shrinks a hull by at most this share of its inner radius.
constexpr double kShrinkClamp = 0.45;
// m^2: a triangle this small (sides of about 0.14 mm) seeds no piece; it may join a
// neighbour's. Its normal is its mesh's noise: a sliver at the full-resolution YCB mug's rim,
// thickened 1 cm along its normal, reached 8 mm out through the rim and MuJoCo threw the mug
// standing on it (test_mujoco_validator, doc/validation.md).
constexpr double kSliverArea = 1e-8;

// Groups neighbouring triangles (sharing an edge) of similar normal into pieces; each piece
// becomes the point set of a convex slab: its vertices plus the same moved inwards (against the
// piece's area-weighted normal) by a thickness (piece_thickness, or less where the opposite
// side of the object is closer). Zero-area triangles are skipped, slivers seed none.
std::vector<std::vector<Eigen::Vector3d>> makeConvexPieces(const Mesh& m, const ValidatorConfig& c) {
  const int nt = static_cast<int>(m.triangles.size());
  std::vector<Eigen::Vector3d> normal(nt), centroid(nt);
  std::vector<double> area(nt);
  for (int t = 0; t < nt; ++t) {
    const auto& tri = m.triangles[t];
    const Eigen::Vector3d& a = m.vertices[tri[0]];
    const Eigen::Vector3d& b = m.vertices[tri[1]];
    const Eigen::Vector3d& d = m.vertices[tri[2]];
    const Eigen::Vector3d n = (b - a).cross(d - a);
    area[t] = 0.5 * n.norm();
    normal[t] = area[t] > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
    centroid[t] = (a + b + d) / 3.0;
  }
  const std::vector<std::vector<int>> nbr = triangleNeighbours(m);
  // The thickness is clamped to piece_thickness below: only triangles within that reach matter.
  const double reach = c.piece_thickness;
  TriangleGrid grid(m, reach);

  const double cos_max = std::cos(c.piece_max_normal_deg * M_PI / 180.0);
  // used: 0 free, 1 in a piece. A group cut again is stamped in `region`, and while it is cut
  // (`active` its stamp, 0 none) only its triangles may grow.
  std::vector<char> used(nt, 0);
  std::vector<int> region(nt, 0);
  int active = 0, stamp = 0;
  auto grow = [&](int seed, double max_size) {
    std::vector<int> group{seed};
    used[seed] = 1;
    std::queue<int> q;
    q.push(seed);
    while (!q.empty() && static_cast<int>(group.size()) < c.piece_max_triangles) {
      const int t = q.front();
      q.pop();
      for (int u : nbr[t]) {
        if (used[u] || (active != 0 && region[u] != active) || area[u] <= 0) continue;
        if (normal[u].dot(normal[seed]) < cos_max) continue;
        if ((centroid[u] - centroid[seed]).norm() > max_size) continue;
        used[u] = 1;
        group.push_back(u);
        q.push(u);
        if (static_cast<int>(group.size()) >= c.piece_max_triangles) break;
      }
    }
    return group;
  };
  auto pieceNormal = [&](const std::vector<int>& group) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (int t : group) n += area[t] * normal[t];
    return n.norm() > 1e-12 ? Eigen::Vector3d(n.normalized()) : normal[group[0]];
  };
  // The share of the group's convex outline (along its normal) that its triangles cover.
  auto fill = [&](const std::vector<int>& group) {
    const Eigen::Vector3d n = pieceNormal(group);
    double covered = 0;
    for (int t : group) covered += area[t] * std::abs(normal[t].dot(n));
    const double outline = polygonArea(convexHull2d(projected(m, group, n)));
    return outline > 1e-12 ? covered / outline : 1.0;
  };
  std::vector<std::vector<int>> groups;
  for (int seed = 0; seed < nt; ++seed) {
    if (used[seed] || area[seed] <= kSliverArea) continue;
    std::vector<std::pair<std::vector<int>, double>> todo;  // a group, the size it was grown to
    todo.emplace_back(grow(seed, c.piece_max_size), c.piece_max_size);
    while (!todo.empty()) {
      auto [g, size] = std::move(todo.back());
      todo.pop_back();
      if (c.piece_min_fill <= 0 || g.size() < 2 || fill(g) >= c.piece_min_fill) {
        groups.push_back(std::move(g));
        continue;
      }
      // Cut again, half as large, within the group's triangles.
      active = ++stamp;
      for (int t : g) region[t] = active, used[t] = 0;
      for (int t : g)
        if (!used[t]) todo.emplace_back(grow(t, 0.5 * size), 0.5 * size);
      active = 0;
    }
  }
  std::vector<std::vector<Eigen::Vector3d>> pieces;
  for (const std::vector<int>& group : groups) {
    const Eigen::Vector3d n = pieceNormal(group);
    // Thickness: piece_thickness, less where the opposite surface is closer (thin walls, the
    // marker's 2 cm body) so that the piece does not poke out on the other side; a piece facing
    // along piece_full_depth_along keeps it all (no depth rays cast).
    const bool full = c.piece_full_depth_along.norm() > 0 &&
                      n.dot(c.piece_full_depth_along.normalized()) > std::cos(M_PI / 4);
    double depth = std::numeric_limits<double>::infinity();
    // A full-depth piece's thickness need be no more than its width (a slab about as thick as
    // it is wide keeps its contact normal true, mujoco_validator.cpp): a floor's 4 cm piece
    // keeps 2 cm, a wire's 7 mm top strip is a slab to the wire's underside, not 2 cm below it
    // where a handle hung on the wire passes.
    double width = std::numeric_limits<double>::infinity();
    if (full) width = polygonWidth(convexHull2d(projected(m, group, n)));
    if (!full || width < c.piece_thickness)
      for (int t : group)
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d& p = m.vertices[m.triangles[t][k]];
          const Eigen::Vector3d start = p - 1e-6 * n;
          depth = std::min(depth, rayDepth(m, start, -n, grid.near(start, start - reach * n), group));
        }
    const double thickness = std::min(full ? std::max(depth, width) : depth, c.piece_thickness);
    // The hull is shrunk by both margins (object's and area's) below, but Bullet shrinks a hull
    // by at most kShrinkClamp of its inner radius (about half a slab's thickness): a thin slab
    // keeps most of the margins, and a mug's 1.5 mm bottom rested 5-7 mm above the table (with
    // thin slabs thickened to 6 margins it poked through). So the slab is inset here by what
    // the shrink leaves, both faces: [inset, thickness - inset], the shrink (kShrinkClamp / 2 of
    // what remains) making up the two margins; a wall thinner than 4 margins is a sheet at its
    // middle (its sides then stand out by 2 margins less half the wall).
    const double m2 = 2.0 * c.margin, sheet = 0.05 * c.margin, share = 0.5 * kShrinkClamp;
    double inset = std::max(0.0, (m2 - share * thickness) / (1.0 - 2.0 * share));
    if (thickness - 2.0 * inset < sheet) inset = 0.5 * (thickness - sheet);
    std::vector<Eigen::Vector3d> pts;
    for (int t : group)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d& p = m.vertices[m.triangles[t][k]];
        pts.push_back(p - inset * n);
        pts.push_back(p - (thickness - inset) * n);
      }
    pieces.push_back(std::move(pts));
  }
  return pieces;
}

// The convex hull of the points (Bullet's btConvexHullComputer): each face as its vertices in
// order; empty when the hull has no volume.
std::vector<std::vector<Eigen::Vector3d>> hullFaces(const std::vector<Eigen::Vector3d>& pts) {
  std::vector<double> xyz;
  for (const auto& p : pts)
    for (int k = 0; k < 3; ++k) xyz.push_back(p[k]);
  btConvexHullComputer ch;
  ch.compute(xyz.data(), 3 * sizeof(double), static_cast<int>(pts.size()), 0, 0);
  std::vector<std::vector<Eigen::Vector3d>> faces;
  if (ch.vertices.size() < 4) return faces;
  auto at = [&](int v) { return Eigen::Vector3d(ch.vertices[v].x(), ch.vertices[v].y(), ch.vertices[v].z()); };
  for (int f = 0; f < ch.faces.size(); ++f) {
    const btConvexHullComputer::Edge* e0 = &ch.edges[ch.faces[f]];
    std::vector<Eigen::Vector3d> face{at(e0->getSourceVertex())};
    for (const btConvexHullComputer::Edge* e = e0->getNextEdgeOfFace(); e != e0; e = e->getNextEdgeOfFace())
      face.push_back(at(e->getSourceVertex()));
    faces.push_back(std::move(face));
  }
  return faces;
}

// Volume of the convex hull of the points (a fan over each hull face, apex at a hull vertex).
double hullVolume(const std::vector<Eigen::Vector3d>& pts) {
  const std::vector<std::vector<Eigen::Vector3d>> faces = hullFaces(pts);
  if (faces.empty()) return 0.0;
  const Eigen::Vector3d apex = faces[0][0];
  double vol = 0.0;
  for (const auto& f : faces)
    for (size_t i = 1; i + 1 < f.size(); ++i) vol += std::abs((f[0] - apex).dot((f[i] - apex).cross(f[i + 1] - apex))) / 6.0;
  return vol;
}

// Mesh volume / convex hull volume for a closed mesh (every edge in exactly two triangles);
// 0 for an open mesh.
double meshConvexity(const Mesh& m) {
  if (!closedMesh(m, true)) return 0.0;
  const double hull = hullVolume(m.vertices);
  return hull > 0 ? std::abs(signedVolume(m)) / hull : 0.0;
}

struct World {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
};

}  // namespace

bool closedMesh(const Mesh& m, bool manifold) {
  std::map<std::pair<int, int>, int> edge_count;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      int i = t[k], j = t[(k + 1) % 3];
      if (i > j) std::swap(i, j);
      ++edge_count[{i, j}];
    }
  for (const auto& [e, n] : edge_count)
    if (n < 2 || (manifold && n != 2)) return false;
  return true;
}

double signedVolume(const Mesh& m) {
  double vol = 0.0;
  for (const auto& t : m.triangles) vol += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  return vol;
}

Mesh turnedOver(const Mesh& m) {
  std::vector<std::vector<int>> reversed;
  for (const auto& t : m.triangles) reversed.push_back({t[0], t[2], t[1]});
  return buildMesh(m.vertices, reversed, "mesh turned over");
}

std::vector<std::vector<Eigen::Vector3d>> convexPieces(const Mesh& mesh, const ValidatorConfig& config) {
  // A closed mesh wound inwards (its signed volume negative: a reconstruction's normals flipped)
  // is turned outwards first: its slabs, thickened against their faces' normals, stood out of
  // it. The YCB mug wound inwards, its three best poses on books_stack: Bullet and MuJoCo kept
  // none of them (all three as wound outwards).
  if (closedMesh(mesh, false) && signedVolume(mesh) < 0) return makeConvexPieces(turnedOver(mesh), config);
  return makeConvexPieces(mesh, config);
}

double convexity(const Mesh& mesh) { return meshConvexity(mesh); }

void clipToHull(std::vector<std::vector<Eigen::Vector3d>>& pieces, const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 4) return;
  Eigen::Vector3d mid = Eigen::Vector3d::Zero();
  for (const auto& p : points) mid += p;
  mid /= static_cast<double>(points.size());
  std::vector<std::pair<Eigen::Vector3d, double>> planes;  // outward unit normal, offset
  for (const auto& f : hullFaces(points)) {
    if (f.size() < 3) continue;
    Eigen::Vector3d n = (f[1] - f[0]).cross(f[2] - f[0]);
    if (n.norm() < 1e-15) continue;
    n.normalize();
    if (n.dot(f[0] - mid) < 0) n = -n;
    planes.emplace_back(n, n.dot(f[0]));
  }
  // Alternating projections onto the faces' half-spaces: a slab corner a little outside comes
  // back onto the hull within a few rounds.
  for (auto& piece : pieces)
    for (auto& p : piece)
      for (int round = 0; round < 4; ++round)
        for (const auto& [n, d] : planes) {
          const double out = n.dot(p) - d;
          if (out > 0) p -= out * n;
        }
}

BoxBody boxBody(const Mesh& object_O, double density) {
  const Eigen::Vector3d ext = object_O.properties.bounds_max - object_O.properties.bounds_min;
  BoxBody b;
  b.mass = density * std::max(ext.x(), 1e-3) * std::max(ext.y(), 1e-3) * std::max(ext.z(), 1e-3);
  b.inertia = b.mass / 12.0 * Eigen::Vector3d(ext.y() * ext.y() + ext.z() * ext.z(), ext.x() * ext.x() + ext.z() * ext.z(),
                                             ext.x() * ext.x() + ext.y() * ext.y());
  return b;
}

double rotationAngleDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  const double c = std::clamp(((R_a.transpose() * R_b).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

struct PhysicsValidator::Impl {
  ValidatorConfig cfg;
  Eigen::Vector3d c_O = Eigen::Vector3d::Zero();  // centre of mass in O (the body origin)
  double mass = 0.0;
  btVector3 inertia{0, 0, 0};
  std::vector<std::unique_ptr<btConvexHullShape>> hulls;
  std::unique_ptr<btCompoundShape> object_shape;
  std::unique_ptr<btTriangleMesh> area_triangles;
  std::unique_ptr<btBvhTriangleMeshShape> area_shape;
  Eigen::Vector3d up_W = Eigen::Vector3d::UnitZ();  // against gravity
  double area_lowest = 0.0;                         // min over area vertices of up . p
  double build_ms = 0.0;
  double convexity = 0.0;

  // A fresh world with the static area and the object at X_WO at rest.
  struct Sim {
    World w;
    std::unique_ptr<btRigidBody> area_body;
    std::unique_ptr<btRigidBody> body;
    ~Sim() {
      if (body) w.world.removeRigidBody(body.get());
      if (area_body) w.world.removeRigidBody(area_body.get());
    }
  };

  std::unique_ptr<Sim> makeSim(const Eigen::Isometry3d& X_WO) const {
    auto s = std::make_unique<Sim>();
    s->w.world.setGravity(toBt(Eigen::Vector3d(cfg.world_scale * cfg.gravity)));
    s->w.world.getSolverInfo().m_numIterations = cfg.solver_iterations;
    // Split impulse for every penetration (Bullet's default only below 4 cm depth, Baumgarte
    // above): position correction then adds no velocity. Measured: with the default, a 19 g
    // marker dropped on the table crawled 0.5 m at up to 0.6 m/s and fell off.
    s->w.world.getSolverInfo().m_splitImpulse = 1;
    s->w.world.getSolverInfo().m_splitImpulsePenetrationThreshold = 0;
    btRigidBody::btRigidBodyConstructionInfo ai(0.0, nullptr, area_shape.get());
    ai.m_friction = 1.0;  // Bullet multiplies: the object's mu alone decides
    ai.m_restitution = 0.0;
    s->area_body = std::make_unique<btRigidBody>(ai);
    s->w.world.addRigidBody(s->area_body.get());

    btRigidBody::btRigidBodyConstructionInfo oi(btScalar(mass), nullptr, object_shape.get(),
                                                inertia);
    oi.m_friction = btScalar(cfg.friction);
    oi.m_restitution = 0.0;
    oi.m_linearDamping = btScalar(cfg.linear_damping);
    oi.m_angularDamping = btScalar(cfg.angular_damping);
    oi.m_startWorldTransform = toBullet(X_WO * Eigen::Translation3d(c_O));
    s->body = std::make_unique<btRigidBody>(oi);
    s->body->setActivationState(DISABLE_DEACTIVATION);
    s->w.world.addRigidBody(s->body.get());
    return s;
  }

  Eigen::Isometry3d objectPose(const btRigidBody& b) const {
    return fromBullet(b.getWorldTransform()) * Eigen::Translation3d(-c_O);
  }

  // Poses and speeds between W (metres) and the scaled Bullet world (world_scale units per metre).
  btTransform toBullet(Eigen::Isometry3d X) const {
    X.translation() *= cfg.world_scale;
    return toBt(X);
  }
  Eigen::Isometry3d fromBullet(const btTransform& T) const {
    Eigen::Isometry3d X = fromBt(T);
    X.translation() /= cfg.world_scale;
    return X;
  }
  double linearSpeed(const btRigidBody& b) const { return b.getLinearVelocity().length() / cfg.world_scale; }
};

bool stillHanging(const PoseCheck& check, const Eigen::Isometry3d& X_WO_goal, const Eigen::Vector3d& com_O,
                  const ValidatorConfig& config) {
  const Eigen::Vector3d up = -config.gravity.normalized();
  const double dropped = (X_WO_goal * com_O - check.X_WO_final * com_O).dot(up);
  return !check.interrupted && check.moved_m < config.max_translation && dropped < 0.005;
}

ValidatorConfig forHanging(ValidatorConfig c) {
  c.linear_damping = c.angular_damping = 0.3;
  c.settle_time = std::max(c.settle_time, 3.0);
  return c;
}

PhysicsValidator::PhysicsValidator(const Mesh& object_O, const Mesh& area_W,
                                   const ValidatorConfig& config)
    : impl_(std::make_unique<Impl>()) {
  validateConfig(config);
  if (object_O.triangles.empty()) throw std::invalid_argument("PhysicsValidator: empty object mesh");
  if (area_W.triangles.empty()) throw std::invalid_argument("PhysicsValidator: empty area mesh");
  const auto t0 = Clock::now();
  Impl& d = *impl_;
  d.cfg = config;
  d.c_O = object_O.properties.center_of_mass;
  const double S = config.world_scale;  // Bullet units per metre

  // Object: compound of convex pieces, body origin at c_O, axes of O.
  d.object_shape = std::make_unique<btCompoundShape>(true, static_cast<int>(object_O.triangles.size()));
  // A (nearly) convex closed object is one hull: exact and much cheaper than pieces. Not one
  // with a loop: its hull fills the opening (a solid mug's handle), and a peg through it is
  // then inside the object.
  std::vector<std::vector<Eigen::Vector3d>> pieces;
  d.convexity = meshConvexity(object_O);
  std::vector<Loop> loops;
  const bool near_convex = d.convexity >= config.convex_volume_ratio;
  if (near_convex || config.loop_sized_pieces) loops = findLoops(object_O);
  if (near_convex && loops.empty()) {
    pieces.push_back(object_O.vertices);
  } else {
    ValidatorConfig pc = config;
    if (config.loop_sized_pieces)
      for (const Loop& l : loops) pc.piece_max_size = std::min(pc.piece_max_size, l.radius);
    pieces = validation::convexPieces(object_O, pc);
  }
  for (const auto& pts : pieces) {
    // Shrink every face of the slab by both margins (object's and area's): Bullet keeps the
    // margin-inflated shapes apart, so the true surfaces then touch where the geometry says
    // (unshrunk, a cube rested 2 mm above the table). The hull keeps its vertices only.
    std::vector<double> xyz;
    for (const auto& p : pts)
      for (int k = 0; k < 3; ++k) xyz.push_back(S * (p[k] - d.c_O[k]));
    btConvexHullComputer ch;
    ch.compute(xyz.data(), 3 * sizeof(double), static_cast<int>(pts.size()),
               btScalar(2.0 * S * config.margin), btScalar(kShrinkClamp));
    if (ch.vertices.size() < 4) continue;
    auto hull = std::make_unique<btConvexHullShape>();
    for (int k = 0; k < ch.vertices.size(); ++k) hull->addPoint(ch.vertices[k], false);
    hull->recalcLocalAabb();
    hull->setMargin(btScalar(S * config.margin));
    btTransform I;
    I.setIdentity();
    d.object_shape->addChildShape(I, hull.get());
    d.hulls.push_back(std::move(hull));
  }
  const BoxBody body = boxBody(object_O, config.density);
  d.mass = body.mass;
  d.inertia = toBt(Eigen::Vector3d(S * S * body.inertia));  // in Bullet's units

  // Area: one static BVH triangle mesh.
  d.area_triangles = std::make_unique<btTriangleMesh>(true, false);
  for (const auto& tri : area_W.triangles)
    d.area_triangles->addTriangle(toBt(Eigen::Vector3d(S * area_W.vertices[tri[0]])),
                                  toBt(Eigen::Vector3d(S * area_W.vertices[tri[1]])),
                                  toBt(Eigen::Vector3d(S * area_W.vertices[tri[2]])), true);
  d.area_shape = std::make_unique<btBvhTriangleMeshShape>(d.area_triangles.get(), true, true);
  // Measured: with the default margin 0 a cube crept 2-5 cm in 2 s on a 15 deg triangle slope at
  // mu 0.4 (tan 15 = 0.27) and stuck at mu 0.1 on the diagonal edge; with 1 mm it sticks and
  // slides exactly where tan(slope) = mu says.
  d.area_shape->setMargin(btScalar(S * config.margin));

  d.up_W = -config.gravity.normalized();
  d.area_lowest = std::numeric_limits<double>::infinity();
  for (const auto& p : area_W.vertices) d.area_lowest = std::min(d.area_lowest, d.up_W.dot(p));
  d.build_ms = msSince(t0);
}

PhysicsValidator::~PhysicsValidator() = default;

const ValidatorConfig& PhysicsValidator::config() const { return impl_->cfg; }
double PhysicsValidator::mass() const { return impl_->mass; }
int PhysicsValidator::convexPieces() const { return static_cast<int>(impl_->hulls.size()); }
double PhysicsValidator::shapeBuildMs() const { return impl_->build_ms; }
double PhysicsValidator::convexity() const { return impl_->convexity; }

PoseCheck PhysicsValidator::check(const Eigen::Isometry3d& X_WO_goal) const {
  return check(X_WO_goal, std::function<bool()>());
}

PoseCheck PhysicsValidator::check(const Eigen::Isometry3d& X_WO_goal,
                                  const std::function<bool()>& keep_going) const {
  const auto t0 = Clock::now();
  const Impl& d = *impl_;
  const ValidatorConfig& c = d.cfg;
  Eigen::Isometry3d X_release = X_WO_goal;
  X_release.translation() += c.release_gap * d.up_W;
  auto sim = d.makeSim(X_release);
  const Eigen::Vector3d p_goal = X_WO_goal * d.c_O;
  const int steps = static_cast<int>(std::ceil(c.settle_time / c.time_step - 1e-9));
  PoseCheck r;
  int calm = 0;
  for (int i = 0; i < steps; ++i) {
    sim->w.world.stepSimulation(btScalar(c.time_step), 0);
    r.sim_time += c.time_step;
    if (c.early_accept_steps > 0) {
      const btRigidBody& b = *sim->body;
      calm = (d.linearSpeed(b) < c.early_accept_linear &&
              b.getAngularVelocity().length() < c.early_accept_angular) ? calm + 1 : 0;
      if (calm >= c.early_accept_steps) {
        const Eigen::Isometry3d X = d.objectPose(b);
        if ((X * d.c_O - p_goal).norm() < 0.5 * c.max_translation &&
            rotationAngleDeg(X.linear(), X_WO_goal.linear()) < 0.5 * c.max_rotation_deg) {
          r.early_accepted = true;
          break;
        }
      }
    }
    if ((i & 15) == 15) {  // early abort, checked every 16 steps
      if (keep_going && !keep_going()) {
        r.interrupted = true;
        break;
      }
      const Eigen::Isometry3d X = d.objectPose(*sim->body);
      if ((X * d.c_O - p_goal).norm() > c.abort_translation ||
          rotationAngleDeg(X.linear(), X_WO_goal.linear()) > c.abort_rotation_deg) {
        r.aborted = true;
        break;
      }
    }
  }
  r.X_WO_final = d.objectPose(*sim->body);
  r.moved_m = (r.X_WO_final * d.c_O - p_goal).norm();
  r.turned_deg = rotationAngleDeg(r.X_WO_final.linear(), X_WO_goal.linear());
  r.confirmed = !r.aborted && !r.interrupted && (r.early_accepted || (r.moved_m < c.max_translation &&
                                                    r.turned_deg < c.max_rotation_deg));
  r.wall_ms = msSince(t0);
  return r;
}

DropResult PhysicsValidator::drop(const Eigen::Isometry3d& X_WO_start) const {
  const auto t0 = Clock::now();
  const Impl& d = *impl_;
  const ValidatorConfig& c = d.cfg;
  auto sim = d.makeSim(X_WO_start);
  const int max_steps = static_cast<int>(std::ceil(c.max_drop_time / c.time_step));
  DropResult r;
  int calm = 0;
  for (int i = 0; i < max_steps; ++i) {
    sim->w.world.stepSimulation(btScalar(c.time_step), 0);
    ++r.steps;
    const btRigidBody& b = *sim->body;
    if (d.linearSpeed(b) < c.rest_linear &&
        b.getAngularVelocity().length() < c.rest_angular) {
      if (++calm >= c.rest_steps) {
        r.at_rest = true;
        break;
      }
    } else {
      calm = 0;
    }
    if (d.up_W.dot(d.fromBullet(b.getWorldTransform()).translation()) < d.area_lowest - c.fall_below) {
      r.fell_off = true;
      break;
    }
  }
  r.sim_time = r.steps * c.time_step;
  r.X_WO_rest = d.objectPose(*sim->body);
  r.wall_ms = msSince(t0);
  return r;
}

double remainingBudgetMs(double plan_budget_ms, double used_ms) {
  if (!(plan_budget_ms > 0)) return 0.0;
  // 1 ns: spent, yet positive (0 would mean no limit).
  return std::max(plan_budget_ms - used_ms, 1e-6);
}

Engines enginesFromString(const std::string& s) {
  if (s == "bullet") return Engines::kBullet;
  if (s == "mujoco") return Engines::kMujoco;
  if (s == "both") return Engines::kBoth;
  throw std::invalid_argument("engines: '" + s + "' is none of bullet, mujoco, both");
}

const char* toString(Engines e) {
  switch (e) {
    case Engines::kBullet: return "bullet";
    case Engines::kMujoco: return "mujoco";
    case Engines::kBoth: return "both";
  }
  return "?";
}

VerifyStats verifyTopK(const Mesh& object_O, const Mesh& area_W, const PlannerConfig& cfg,
                       PlanResult& result, int k, double budget_ms, int threads,
                       const std::function<bool()>& keep_going, Engines engines) {
  const auto t0 = Clock::now();
  VerifyStats s;
  std::vector<Candidate>& cands = result.candidates;
  for (size_t i = 0; i < cands.size(); ++i) {
    cands[i].physics = PhysicsCheck();
    cands[i].physics.planner_rank = static_cast<int>(i);
  }
  // The best k stable candidates, in rank order.
  std::vector<size_t> picked;
  for (size_t i = 0; i < cands.size() && static_cast<int>(picked.size()) < k; ++i)
    if (cands[i].stable) picked.push_back(i);
  s.selected = static_cast<int>(picked.size());
  s.threads = std::max(1, std::min<int>(resolveThreads(threads), s.selected));
  const bool limited = budget_ms > 0;
  const std::function<bool()> may_start = [&] {
    return !(limited && msSince(t0) >= budget_ms) && (!keep_going || keep_going());
  };
  if (picked.empty() || !may_start()) {
    s.total_ms = msSince(t0);
    return s;
  }

  ValidatorConfig vc;
  vc.friction = cfg.friction;
  const Eigen::Vector3d d_g = cfg.gravity.norm() > 0 ? cfg.gravity.normalized() : Eigen::Vector3d(0, 0, -1);
  vc.gravity = 9.81 * d_g;
  // Hanging candidates: checked damped and judged by stillHanging (a pendulum turns to its rest).
  const ValidatorConfig hc = forHanging(vc);
  bool any_hanging = false, any_standing = false;
  for (size_t i : picked) (cands[i].hanging ? any_hanging : any_standing) = true;
  const bool bullet = engines != Engines::kMujoco, mujoco = engines != Engines::kBullet;
  std::unique_ptr<PhysicsValidator> standing_b, hanging_b;
  std::unique_ptr<MujocoValidator> standing_m, hanging_m;
  if (bullet && any_standing) standing_b = std::make_unique<PhysicsValidator>(object_O, area_W, vc);
  if (bullet && any_hanging) hanging_b = std::make_unique<PhysicsValidator>(object_O, area_W, hc);
  if (mujoco && any_standing) standing_m = std::make_unique<MujocoValidator>(object_O, area_W, vc);
  if (mujoco && any_hanging) hanging_m = std::make_unique<MujocoValidator>(object_O, area_W, hc);
  for (const auto* v : {standing_b.get(), hanging_b.get()})
    if (v) s.shape_ms += v->shapeBuildMs();
  for (const auto* v : {standing_m.get(), hanging_m.get()})
    if (v) s.shape_ms += v->buildMs();

  // Indices are handed out in rank order (parallel_for.h), so the best start first; the budget
  // is read before each start (a MuJoCo check, once started, runs to its end).
  std::vector<PoseCheck> checks(picked.size()), mj(picked.size());
  std::vector<char> ran(picked.size(), 0);
  parallelFor(picked.size(), s.threads, [&](size_t j) {
    if (!may_start()) return;
    const Candidate& c = cands[picked[j]];
    if (bullet) {
      checks[j] = (c.hanging ? *hanging_b : *standing_b).check(c.X_WO, may_start);
      if (checks[j].interrupted) return;
    }
    if (mujoco) {
      if (!may_start()) return;
      mj[j] = (c.hanging ? *hanging_m : *standing_m).check(c.X_WO);
    }
    ran[j] = 1;
  });

  double sim_ms = 0.0;
  const Eigen::Vector3d com_O = object_O.properties.center_of_mass;
  for (size_t j = 0; j < picked.size(); ++j) {
    if (!ran[j]) continue;
    PhysicsCheck& p = cands[picked[j]].physics;
    const Candidate& c = cands[picked[j]];
    p.checked = true;
    p.stayed = true;
    if (bullet) {
      const bool kept = c.hanging ? stillHanging(checks[j], c.X_WO, com_O, hc) : checks[j].confirmed;
      p.stayed = kept;
      p.bullet_checked = true;
      p.bullet_stayed = kept;
      p.moved_m = checks[j].moved_m;
      p.turned_deg = checks[j].turned_deg;
      s.bullet_stayed += kept;
      sim_ms += checks[j].wall_ms;
    }
    if (mujoco) {
      const bool kept = c.hanging ? stillHanging(mj[j], c.X_WO, com_O, hc) : mj[j].confirmed;
      p.mujoco_checked = true;
      p.mujoco_stayed = kept;
      p.mujoco_moved_m = mj[j].moved_m;
      p.mujoco_turned_deg = mj[j].turned_deg;
      if (!bullet) {
        p.moved_m = mj[j].moved_m;
        p.turned_deg = mj[j].turned_deg;
      }
      p.stayed = p.stayed && kept;
      s.mujoco_stayed += kept;
      sim_ms += mj[j].wall_ms;
    }
    ++s.checked;
    s.stayed += p.stayed;
  }
  s.per_check_ms = s.checked > 0 ? sim_ms / s.checked : 0.0;

  // Checked and fell: behind the other stable candidates, ahead of the unstable ones; the order
  // within each group is kept (stable partition in three groups).
  const auto group = [](const Candidate& c) {
    if (!c.stable) return 2;
    return c.physics.checked && !c.physics.stayed ? 1 : 0;
  };
  stableSortAligned(cands, [&](const Candidate& a, const Candidate& b) { return group(a) < group(b); });
  s.demoted = s.checked - s.stayed;
  s.total_ms = msSince(t0);
  return s;
}

}  // namespace validation
}  // namespace place_planner
