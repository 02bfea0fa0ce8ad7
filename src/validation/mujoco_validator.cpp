// MuJoCo check of placement poses (mujoco_validator.h).
#include "place_planner/validation/mujoco_validator.h"

#include <mujoco/mujoco.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <map>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "place_planner/search/loops.h"

namespace place_planner {
namespace validation {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kTimeStep = 0.001;     // s: a 4 ms contact time constant needs <= 2 ms
constexpr double kMinThickness = 2e-4;  // m: a slab thinner than this is thickened (qhull needs a volume)
constexpr size_t kMaxTriangles = 200000;  // subdivided() stops splitting there (bounded work)
// Contacts MuJoCo 2.2 preallocates (its default, 100, overflowed with a cube on a slope: its
// warning, and contacts dropped); 3 constraint rows each (elliptic cones), whose dense
// matrices are its square (2000 contacts did not fit in memory).
constexpr int kMaxContacts = 500;

// Each piece's point pairs (a surface point, the same point inside: convexPieces) kept at least
// kMinThickness apart, so that MuJoCo's hull of the piece has a volume; a piece whose pairs
// coincide everywhere (no inward direction) is dropped.
bool thickened(std::vector<Eigen::Vector3d>& pts) {
  Eigen::Vector3d dir = Eigen::Vector3d::Zero();
  for (size_t i = 0; i + 1 < pts.size(); i += 2) dir += pts[i + 1] - pts[i];
  if (dir.norm() < 1e-12) return false;
  dir.normalize();
  for (size_t i = 0; i + 1 < pts.size(); i += 2)
    if ((pts[i + 1] - pts[i]).dot(dir) < kMinThickness) pts[i + 1] = pts[i] + kMinThickness * dir;
  return true;
}

// The mesh with every triangle longer than `max_edge` split at its longest edge's middle (the
// middles shared, so neighbours stay neighbours), until none is. MuJoCo 2.2 finds the contact
// of two convex shapes by MPR, along the line between their centres: a contact near the end of
// a long slab came out along that line, sideways (a plate beside the seam of a two-triangle
// table slid 6 cm). Pieces about as long as they are thick keep the contact normal true.
Mesh subdivided(const Mesh& mesh, double max_edge) {
  std::vector<Eigen::Vector3d> v = mesh.vertices;
  std::map<std::pair<int, int>, int> middle;
  auto mid = [&](int a, int b) {
    const std::pair<int, int> key(std::min(a, b), std::max(a, b));
    auto it = middle.find(key);
    if (it != middle.end()) return it->second;
    v.push_back(0.5 * (v[a] + v[b]));
    return middle[key] = static_cast<int>(v.size()) - 1;
  };
  std::vector<std::array<int, 3>> todo(mesh.triangles.rbegin(), mesh.triangles.rend());
  std::vector<std::vector<int>> out;
  while (!todo.empty()) {
    const std::array<int, 3> t = todo.back();
    todo.pop_back();
    int longest = 0;
    double len = 0;
    for (int k = 0; k < 3; ++k) {
      const double l = (v[t[(k + 1) % 3]] - v[t[k]]).norm();
      if (l > len) len = l, longest = k;
    }
    if (len <= max_edge || out.size() + todo.size() > kMaxTriangles) {
      out.push_back({t[0], t[1], t[2]});
      continue;
    }
    const int a = t[longest], b = t[(longest + 1) % 3], c = t[(longest + 2) % 3], m = mid(a, b);
    todo.push_back({m, b, c});
    todo.push_back({a, m, c});
  }
  return buildMesh(v, out, "subdivided mesh");
}

// A scan of an area may be wound either way: the shared RGB-D scan of a tissue box on a table
// has 90 % of its level surface facing down, into the table. A piece is thickened against its
// normal, so that scan's table became slabs standing up to 2 cm above it, and MuJoCo threw a mug
// let go on the table 5 cm (Bullet, which takes the area's triangles as they are, kept it). An
// open area (a scan) whose level faces mostly face down (more than twice the area facing up) is
// turned over. A closed one (a table, a bin with walls) faces down underneath by right, about
// as much as up, and is kept.
Mesh facingUp(const Mesh& area, const Eigen::Vector3d& up) {
  double facing_up = 0, facing_down = 0;  // faces within 45 degrees of level (twice their area)
  for (const auto& t : area.triangles) {
    const Eigen::Vector3d n = (area.vertices[t[1]] - area.vertices[t[0]]).cross(area.vertices[t[2]] - area.vertices[t[0]]);
    const double c = n.dot(up), level = std::cos(M_PI / 4) * n.norm();
    if (c > level) facing_up += n.norm();
    if (c < -level) facing_down += n.norm();
  }
  if (facing_down <= 2.0 * facing_up || closedMesh(area, false)) return area;
  return turnedOver(area);
}

void appendMesh(std::ostringstream& xml, const std::string& name, const std::vector<Eigen::Vector3d>& pts,
                const Eigen::Vector3d& offset) {
  xml << "<mesh name=\"" << name << "\" vertex=\"";
  for (const auto& p : pts) xml << (p.x() - offset.x()) << ' ' << (p.y() - offset.y()) << ' ' << (p.z() - offset.z()) << ' ';
  xml << "\"/>\n";
}

// Pieces without margins (MuJoCo has none to make up for); the object's no larger than half
// its narrowest loop's radius: a hull must not bridge a handle's opening (as for Bullet), and
// a piece as long as the radius still bulges into it (a key ring of 7 mm wire bent to 2.2 cm
// started 1.1 cm inside the rail it hung on, and MuJoCo threw it off; at half, no contact:
// held-out hanging racks in both engines 6 -> 11 of 25, doc/validation.md).
ValidatorConfig objectPieceConfig(const ValidatorConfig& config, double piece_size, const std::vector<Loop>& loops) {
  ValidatorConfig pc = config;
  pc.margin = 0.0;
  pc.piece_max_triangles = 1000;  // pieces bounded by their size (a fine mesh's too)
  pc.piece_max_size = std::min(config.piece_max_size, piece_size);
  // A piece whose triangles cover under 0.6 of its outline is cut again: a bent wire's flat
  // flank (a J-hook's arm and its turned-up tip) made one L whose hull filled the corner where
  // a mug's handle hangs, and MuJoCo threw the mug off. At 0.8 the ragged outlines of curved
  // pieces were cut too (a key ring on the pegboard: 3x the pieces, 3x the time).
  pc.piece_min_fill = 0.6;
  for (const Loop& l : loops) pc.piece_max_size = std::min(pc.piece_max_size, 0.5 * l.radius);
  return pc;
}

std::vector<std::vector<Eigen::Vector3d>> piecesOf(const Mesh& object_O, const ValidatorConfig& config,
                                                  const ValidatorConfig& pc, const std::vector<Loop>& loops) {
  std::vector<std::vector<Eigen::Vector3d>> pieces = convexPieces(subdivided(object_O, 0.5 * pc.piece_max_size), pc);
  // A nearly convex closed object without a loop (the one hull Bullet simulates: a box, a bottle,
  // a cone) has its slabs kept inside that hull. A slab thickened inwards along a cone's side
  // reached 3.6 mm below its base at the rim, and MuJoCo tipped the cone standing on its base
  // 21 degrees (doc/validation.md, "Held-out objects").
  if (loops.empty() && convexity(object_O) >= config.convex_volume_ratio) clipToHull(pieces, object_O.vertices);
  return pieces;
}

}  // namespace

std::vector<std::vector<Eigen::Vector3d>> mujocoObjectPieces(const Mesh& object_O, const ValidatorConfig& config,
                                                             double piece_size) {
  const std::vector<Loop> loops = findLoops(object_O);
  return piecesOf(object_O, config, objectPieceConfig(config, piece_size, loops), loops);
}

struct MujocoValidator::Impl {
  ValidatorConfig cfg;
  mjModel* model = nullptr;
  Eigen::Vector3d c_O = Eigen::Vector3d::Zero();
  int object_pieces = 0, area_pieces = 0;
  double build_ms = 0.0;
  ~Impl() {
    if (model) mj_deleteModel(model);
  }
};

MujocoValidator::MujocoValidator(const Mesh& object_O, const Mesh& area_W, const ValidatorConfig& config,
                                 double piece_size)
    : impl_(std::make_unique<Impl>()) {
  if (object_O.triangles.empty()) throw std::invalid_argument("MujocoValidator: empty object mesh");
  if (area_W.triangles.empty()) throw std::invalid_argument("MujocoValidator: empty area mesh");
  const auto t0 = Clock::now();
  Impl& d = *impl_;
  d.cfg = config;
  d.c_O = object_O.properties.center_of_mass;

  const std::vector<Loop> loops = findLoops(object_O);
  const ValidatorConfig pc = objectPieceConfig(config, piece_size, loops);
  // The area's slabs: its surface with 2 cm under it (less in thin walls), pieces twice as large
  // as the object's. A slab's contact normal stays true while it is about as thick as it is
  // long (subdivided() above): at 1 cm under 4 cm pieces a YCB bowl resting on the true table
  // tipped 29 degrees and a plate slid 6 cm where Bullet kept them (0.6 and 0.4 degrees); at
  // 2 cm both stay (0.6, 0.3 degrees), as two sugar box poses that had turned 7 and 25 degrees.
  ValidatorConfig ac = pc;
  ac.piece_max_size = 2.0 * piece_size;
  ac.piece_thickness = 0.02;
  ac.piece_full_depth_along = -config.gravity;  // floors and shelves: thick even where thin
  std::vector<std::vector<Eigen::Vector3d>> object_pieces = piecesOf(object_O, config, pc, loops);
  std::vector<std::vector<Eigen::Vector3d>> area_pieces =
      convexPieces(subdivided(facingUp(area_W, -config.gravity.normalized()), 0.5 * ac.piece_max_size), ac);

  const BoxBody body = boxBody(object_O, config.density);  // as Bullet's
  const double mass = body.mass;
  const Eigen::Vector3d& inertia = body.inertia;

  std::ostringstream xml;
  xml.precision(9);
  xml << "<mujoco model=\"placement\">\n<compiler inertiafromgeom=\"false\"/>\n<size nconmax=\"" << kMaxContacts << "\" njmax=\"" << 3 * kMaxContacts << "\"/>\n<option timestep=\"" << kTimeStep << "\" gravity=\"" << config.gravity.x()
      << ' ' << config.gravity.y() << ' ' << config.gravity.z() << "\" cone=\"elliptic\" impratio=\"10\"" << "/>\n"
      << "<default><geom condim=\"3\" friction=\"" << config.friction
      << " 0 0\" solref=\"" << "0.004 1" << "\"/></default>\n<asset>\n";
  std::vector<std::string> area_names, object_names;
  for (auto& p : area_pieces) {
    if (!thickened(p)) continue;
    area_names.push_back("a" + std::to_string(area_names.size()));
    appendMesh(xml, area_names.back(), p, Eigen::Vector3d::Zero());
  }
  for (auto& p : object_pieces) {
    if (!thickened(p)) continue;
    object_names.push_back("o" + std::to_string(object_names.size()));
    appendMesh(xml, object_names.back(), p, d.c_O);  // body frame: origin c_O, axes of O
  }
  xml << "</asset>\n<worldbody>\n";
  // Each area piece a static body of its own: MuJoCo 2.2 prunes by bodies (sweep and prune),
  // then tests every geom pair of two bodies; in one world body the object met every piece.
  for (const auto& n : area_names) xml << "<body><geom type=\"mesh\" mesh=\"" << n << "\"/></body>\n";
  xml << "<body name=\"object\"><freejoint/>\n<inertial pos=\"0 0 0\" mass=\"" << mass << "\" diaginertia=\""
      << inertia.x() << ' ' << inertia.y() << ' ' << inertia.z() << "\"/>\n";
  for (const auto& n : object_names) xml << "<geom type=\"mesh\" mesh=\"" << n << "\"/>\n";
  xml << "</body>\n</worldbody>\n</mujoco>\n";
  if (object_names.empty()) throw std::runtime_error("MujocoValidator: the object has no convex piece");

  // Compiled from memory (a virtual file).
  const std::string text = xml.str();
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), "placement.xml", static_cast<int>(text.size())) != 0)
    throw std::runtime_error("MujocoValidator: the model does not fit MuJoCo's virtual file");
  std::memcpy(vfs->filedata[vfs->nfile - 1], text.data(), text.size());
  // MuJoCo's warnings (a full contact buffer) to stderr, not to a MUJOCO_LOG.TXT in the
  // caller's folder; a handler the program set stays.
  if (!mju_user_warning) mju_user_warning = [](const char* msg) { std::fprintf(stderr, "MuJoCo: %s\n", msg); };
  char error[1000] = "";
  static std::mutex compiling;  // MuJoCo's XML compiler is not known to be reentrant
  std::lock_guard<std::mutex> lock(compiling);
  d.model = mj_loadXML("placement.xml", vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!d.model) throw std::runtime_error(std::string("MujocoValidator: MuJoCo did not compile the scene: ") + error);
  // Velocity damping as Bullet's: the share lost per second, per degree of freedom.
  const double k = -std::log(1.0 - std::clamp(config.linear_damping, 0.0, 0.99));
  const double ka = -std::log(1.0 - std::clamp(config.angular_damping, 0.0, 0.99));
  for (int i = 0; i < 3; ++i) {
    d.model->dof_damping[i] = k * mass;
    d.model->dof_damping[3 + i] = ka * inertia[i];
  }
  d.object_pieces = static_cast<int>(object_names.size());
  d.area_pieces = static_cast<int>(area_names.size());
  d.build_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

MujocoValidator::~MujocoValidator() = default;

int MujocoValidator::objectPieces() const { return impl_->object_pieces; }
int MujocoValidator::areaPieces() const { return impl_->area_pieces; }
double MujocoValidator::buildMs() const { return impl_->build_ms; }

PoseCheck MujocoValidator::check(const Eigen::Isometry3d& X_WO_goal) const {
  const auto t0 = Clock::now();
  const Impl& d = *impl_;
  const ValidatorConfig& c = d.cfg;
  mjData* data = mj_makeData(d.model);
  const Eigen::Vector3d up = -c.gravity.normalized();
  // The body's frame: origin at the centre of mass, axes of O; released release_gap higher.
  const Eigen::Vector3d p0 = X_WO_goal * d.c_O + c.release_gap * up;
  const Eigen::Quaterniond q0(X_WO_goal.linear());
  const double qpos[7] = {p0.x(), p0.y(), p0.z(), q0.w(), q0.x(), q0.y(), q0.z()};
  std::copy(qpos, qpos + 7, data->qpos);
  mj_forward(d.model, data);
  const Eigen::Vector3d p_goal = X_WO_goal * d.c_O;
  auto pose = [&] {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = Eigen::Quaterniond(data->qpos[3], data->qpos[4], data->qpos[5], data->qpos[6]).normalized().toRotationMatrix();
    X.translation() = Eigen::Vector3d(data->qpos[0], data->qpos[1], data->qpos[2]) - X.linear() * d.c_O;
    return X;
  };
  const int steps = static_cast<int>(std::ceil(c.settle_time / kTimeStep - 1e-9));
  // Bullet's early accept is counted in its steps (1/480 s): the same stretch of time here.
  const int calm_steps = static_cast<int>(std::lround(c.early_accept_steps * c.time_step / kTimeStep));
  PoseCheck r;
  int calm = 0;
  for (int i = 0; i < steps; ++i) {
    mj_step(d.model, data);
    r.sim_time += kTimeStep;
    if (calm_steps > 0) {
      const Eigen::Vector3d v(data->qvel[0], data->qvel[1], data->qvel[2]);
      const Eigen::Vector3d w(data->qvel[3], data->qvel[4], data->qvel[5]);
      calm = (v.norm() < c.early_accept_linear && w.norm() < c.early_accept_angular) ? calm + 1 : 0;
      if (calm >= calm_steps) {
        const Eigen::Isometry3d X = pose();
        if ((X * d.c_O - p_goal).norm() < 0.5 * c.max_translation &&
            rotationAngleDeg(X.linear(), X_WO_goal.linear()) < 0.5 * c.max_rotation_deg) {
          r.early_accepted = true;
          break;
        }
      }
    }
    if ((i & 31) == 31) {
      const Eigen::Isometry3d X = pose();
      if ((X * d.c_O - p_goal).norm() > c.abort_translation ||
          rotationAngleDeg(X.linear(), X_WO_goal.linear()) > c.abort_rotation_deg) {
        r.aborted = true;
        break;
      }
    }
  }
  r.X_WO_final = pose();
  mj_deleteData(data);
  r.moved_m = (r.X_WO_final * d.c_O - p_goal).norm();
  r.turned_deg = rotationAngleDeg(r.X_WO_final.linear(), X_WO_goal.linear());
  r.confirmed = !r.aborted && (r.early_accepted || (r.moved_m < c.max_translation && r.turned_deg < c.max_rotation_deg));
  r.wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return r;
}

}  // namespace validation
}  // namespace place_planner
