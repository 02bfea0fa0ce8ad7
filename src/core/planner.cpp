// Orchestration of the paper's method (Sections IV-VI): every tree of every floor point advances
// together, one batched step at a time (Section VII-C), through the Backend interface.
#include "place_planner/planner.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <memory>
#include <mutex>

#include "place_planner/area_up.h"
#include "place_planner/backend.h"
#include "place_planner/contact_points.h"
#include "place_planner/cuda_backend.h"
#include "place_planner/floor_points.h"
#include "place_planner/local_optimisation.h"
#include "place_planner/parallel_for.h"
#include "place_planner/penetration.h"
#include "place_planner/pre_orientation.h"
#include "place_planner/stability.h"
#include "place_planner/tilt_axis.h"

namespace place_planner {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Rotation by `angle` about the axis (s, d) applied after X.
Rigid rotated(const Rigid& X, const Eigen::Vector3d& s, const Eigen::Vector3d& d, double angle) {
  Eigen::Isometry3d T = toIsometry(X);
  Eigen::Isometry3d Rot = Eigen::Isometry3d::Identity();
  Rot.linear() = Eigen::AngleAxisd(angle, d.normalized()).toRotationMatrix();
  Rot.translation() = s - Rot.linear() * s;
  return toRigid(Rot * T);
}

Rigid translated(Rigid X, const V3& d) {
  X.t = X.t + d;
  return X;
}

struct Node {
  Rigid X;
  int root = 0;
  int depth = 0;  // rotations of the tree (Section V-C), not counting small ones
  int turns = 0;  // all rotations, small ones included
  int opt = 0;    // local optimisation steps (Section VI)
  std::vector<Rigid> path;
  std::vector<V3> pending;  // translations still to do, directions
  std::vector<double> pending_tmax;
  // Rotation request.
  Eigen::Vector3d s_A, d_A;
  bool both_directions = true;
  bool local_rotation = false;
  std::vector<ContactPoint> contacts;
};

struct Leaf {
  Rigid X;
  int root;
  bool stable;
  double quality;
  std::vector<ContactPoint> contacts;
  std::vector<Rigid> path;
};

// A direction is blocked when a contact away from the axis would move into the area.
bool blocked(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& s,
             const Eigen::Vector3d& d, int sigma, double lever_tol) {
  for (const auto& c : contacts) {
    const Eigen::Vector3d r = c.p_W - s;
    const Eigen::Vector3d v = sigma * d.cross(r);
    if (v.norm() < lever_tol) continue;  // on the axis
    if (v.normalized().dot(c.n_W) < -0.3) return true;
  }
  return false;
}

double angleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

std::once_flag g_backend_log;
// PP_TRACE=1 in the environment prints every tree node and rotation to stderr.
const bool kTrace = std::getenv("PP_TRACE") != nullptr;
// Below this share of surface facing against gravity (within 20 degrees), the plan warns.
constexpr double kMinUpFacingShare = 0.05;
constexpr double kSmallTurn = 2.0 * M_PI / 180.0;
constexpr int kMaxTurnsPerRotation = 4;
const double kSteepLine = std::sin(30.0 * M_PI / 180.0);

// FNV-1a over the bytes of the area mesh and the model parameters.
uint64_t fingerprint(const Mesh& area, const Eigen::Vector3d& g, double r, double cd, double cell) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, size_t n) {
    const unsigned char* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  for (const auto& v : area.vertices) mix(v.data(), 3 * sizeof(double));
  for (const auto& t : area.triangles) mix(t.data(), 3 * sizeof(int));
  const double p[6] = {g.x(), g.y(), g.z(), r, cd, cell};
  mix(p, sizeof p);
  return h;
}

// The area model (sphere model, BVHs, height grid) is the costly part of a plan and depends
// only on the area and the radii: the last few are kept, as a node re-plans on the same area.
std::mutex g_cache_mutex;
std::vector<std::pair<uint64_t, std::shared_ptr<const AreaModel>>> g_cache;

std::shared_ptr<const AreaModel> cachedAreaModel(const Mesh& area, const Eigen::Vector3d& g,
                                                 double r, double cd, double cell) {
  std::mutex& mutex = g_cache_mutex;
  auto& cache = g_cache;
  const uint64_t key = fingerprint(area, g, r, cd, cell);
  {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& e : cache)
      if (e.first == key) return e.second;
  }
  auto model = std::make_shared<const AreaModel>(buildAreaModel(area, g, r, cd, cell));
  std::lock_guard<std::mutex> lock(mutex);
  cache.emplace_back(key, model);
  if (cache.size() > 4) cache.erase(cache.begin());
  return model;
}


}  // namespace

void Planner::clearAreaCache() {
  std::lock_guard<std::mutex> lock(g_cache_mutex);
  g_cache.clear();
}

PlanResult Planner::plan(const Mesh& object, const Mesh& area, const PlannerConfig& config,
                         const ProgressCallback& progress) const {
  validate(config);
  if (object.empty()) throw std::invalid_argument("object mesh is empty");
  if (area.empty()) throw std::invalid_argument("placement area mesh is empty");
  const auto t0 = Clock::now();
  PlanResult result;
  PlanStats& st = result.stats;

  // ------------------------------------------------------------------ frames and models
  const Eigen::Vector3d d_g_W = config.gravity.normalized();
  const Eigen::Vector3d d_vis_W =
      config.approach.norm() > 1e-9 ? Eigen::Vector3d(config.approach.normalized()) : d_g_W;
  const double R_obj = object.properties.bounding_radius;
  // Sphere radius: about 1% of the object's size, within 0.75 .. 4 mm (Section V-B).
  const double r = config.sphere_radius > 0 ? config.sphere_radius
                                            : std::clamp(0.01 * 2.0 * R_obj, 0.00075, 0.004);
  // The area's spheres may be coarser: its model is built once per area and cached.
  const double r_area = 1.5 * r;
  const double cd = r + r_area;  // collision distance: the sum of the radii (V-B)
  const double cell = config.grid_cell_size > 0 ? config.grid_cell_size : cd;
  st.sphere_radius = r;
  auto tp = Clock::now();
  // The object's model is built while the area's is built or fetched from the cache.
  auto object_model = std::async(std::launch::async, [&] { return buildObjectModel(object, r); });
  const std::shared_ptr<const AreaModel> area_model = cachedAreaModel(area, d_g_W, r_area, cd, cell);
  const ObjectModel om = object_model.get();
  const AreaModel& am = *area_model;
  const Eigen::Matrix3d R_GW = am.R_GW;
  st.steps.setup = msSince(tp);
  // With gravity wrong for the area (a scan in its camera frame) nothing is flat; say so.
  if (am.up_facing_share < kMinUpFacingShare) {
    const UpEstimate e = estimateUp(area, -d_g_W);
    char msg[320];
    std::snprintf(msg, sizeof msg,
                  "placement area: under %.0f %% of its surface faces against gravity; its largest "
                  "flat region (%.0f %%) faces (%.3f, %.3f, %.3f): is gravity right?",
                  100 * kMinUpFacingShare, 100 * e.share, e.up.x(), e.up.y(), e.up.z());
    result.warnings.push_back(msg);
  }
  const V3 d_vis = toV3(R_GW * d_vis_W);
  const V3 d_g = v3(0, 0, -1);

  std::unique_ptr<Backend> backend;
  TiltParams tilt{0.002, 1e-6 + 1e-4 * r};
  if (config.backend != BackendKind::kCpu) {
    std::string why;
    if (cuda::available(&why)) {
      backend = makeCudaBackend(om, am, tilt);
    } else if (config.backend == BackendKind::kCuda) {
      throw std::runtime_error("backend = cuda requested but unavailable: " + why);
    } else {
      std::call_once(g_backend_log, [&] {
        std::fprintf(stderr, "[place_planner] no usable GPU (%s): using the CPU backend\n", why.c_str());
      });
    }
  }
  if (!backend) backend = makeCpuBackend(om, am, tilt, config.threads);
  st.backend = backend->name();

  // ------------------------------------------------------------------ floor points (IV-B)
  tp = Clock::now();
  FloorPointParams fpp;
  fpp.d_vis = d_vis;
  fpp.spacing = config.floor_point_spacing;
  fpp.min_points = config.min_floor_points;
  fpp.lowest_n = config.lowest_n;
  FloorPoints fp = floorPoints(am, fpp);
  if (config.hasRegion()) {
    // The region is a box in W: hits are mapped back from G and tested there.
    std::vector<V3> kept;
    for (const V3& p : fp.points) {
      const Eigen::Vector3d pw = R_GW.transpose() * toEigen(p);
      if ((pw.array() >= config.region_min.array()).all() && (pw.array() <= config.region_max.array()).all())
        kept.push_back(p);
    }
    fp.points = kept;
  }
  // Anytime order: floor points amid a wide flat neighbourhood first (more neighbours at the
  // same height), then central ones; such points rarely let the object hang over an edge, so
  // good poses come early. The set tried is the paper's; only the order changes.
  if (!fp.points.empty()) {
    V3 c = v3(0, 0, 0);
    for (const V3& p : fp.points) c = c + p;
    c = (1.0 / fp.points.size()) * c;
    std::vector<std::pair<int, double>> key(fp.points.size());
    for (size_t i = 0; i < fp.points.size(); ++i) {
      int flat = 0;
      for (const V3& q : fp.points) {
        const V3 d = q - fp.points[i];
        flat += d.x * d.x + d.y * d.y < 2.5 * fp.spacing * fp.spacing && std::abs(d.z) < 0.005;
      }
      const V3 dc = fp.points[i] - c;
      key[i] = {-flat, dc.x * dc.x + dc.y * dc.y};
    }
    std::vector<size_t> idx(fp.points.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
    std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return key[a] < key[b]; });
    std::vector<V3> sorted;
    for (size_t i : idx) sorted.push_back(fp.points[i]);
    fp.points = sorted;
  }
  for (const V3& p : fp.points) result.floor_points_W.push_back(R_GW.transpose() * toEigen(p));
  st.steps.floor_points = msSince(tp);

  // ------------------------------------------------------------------ orientations (IV-A)
  const Eigen::Matrix3d R_start = R_GW * config.start_orientation.normalized().toRotationMatrix();
  const std::vector<Eigen::Matrix3d> orientations =
      preOrientations(object.properties, R_start, toEigen(d_vis), config.orientation);

  // Height of the area along -d_vis, to start every object clear of it (V-A, first step).
  double hmax = -kInf, hmin = kInf;
  for (const V3& v : am.vertices) {
    hmax = std::max(hmax, -dot(v, d_vis));
    hmin = std::min(hmin, -dot(v, d_vis));
  }
  const double diag = norm(am.bounds.hi - am.bounds.lo);

  const int num_roots = static_cast<int>(fp.points.size() * orientations.size());
  st.floor_points_total = static_cast<int>(fp.points.size());
  // Support at least min_support_width wide, or a quarter of the object's middle extent.
  Eigen::Vector3d ext = object.properties.bounds_max - object.properties.bounds_min;
  std::sort(ext.data(), ext.data() + 3);
  const StabilityParams sp{config.friction, 1.5 * cd, config.min_tipping_angle_deg * M_PI / 180.0,
                           std::min(config.min_support_width, 0.25 * ext[1])};
  const int max_opt = config.max_local_optimisation_steps;
  std::vector<Leaf> leaves;
  double best_q = 0;
  int stable_count = 0;
  auto report = [&]() -> bool {
    if (config.time_budget_ms > 0 && msSince(t0) > config.time_budget_ms) {
      result.timed_out = true;
      return false;
    }
    if (!progress) return true;
    Progress p;
    p.floor_points_done = st.floor_points_done;
    p.floor_points_total = st.floor_points_total;
    p.best_quality = best_q;
    p.candidates = stable_count;
    p.elapsed_ms = msSince(t0);
    if (!progress(p)) {
      result.cancelled = true;
      return false;
    }
    return true;
  };

  // Roots are streamed into the batch (anytime behaviour): whenever trees end, new roots take
  // their places, so a pose that settles in a few steps is not held up by a long tree and the
  // batch stays full. The batch starts small (the first stable pose comes quickly) and doubles
  // every other step up to `batch`. Each tree depends on its root only: the leaves are the same.
  const int batch = std::max(16, 12 * resolveThreads(config.threads));
  std::vector<Node> translate, contact, rotating;
  int next_root = 0;
  auto startRoot = [&](int k) {
    const int f = k / static_cast<int>(orientations.size());
    const Eigen::Matrix3d& R = orientations[k % orientations.size()];
    const V3 p_f = fp.points[f];
    // Centre of mass above the floor point along -d_vis, clear of everything (V-A).
    const double h = hmax + dot(p_f, d_vis) + R_obj + 0.01;
    const Eigen::Vector3d com_G = toEigen(p_f) - h * toEigen(d_vis);
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = R;
    X.translation() = com_G - R * object.properties.center_of_mass;
    Node n;
    n.X = toRigid(X);
    n.root = k;
    n.path.push_back(n.X);  // pre-placement pose
    n.pending.push_back(d_vis);
    n.pending_tmax.push_back(h + R_obj + (hmax - hmin) + 0.01);
    translate.push_back(std::move(n));
  };
  bool stop = !report();
  const int first_batch = std::max(4, batch / 6);
  for (int step = 0, target = first_batch; !stop; ++step) {
    if (step > 0 && step % 2 == 0) target = std::min(batch, 2 * target);
    for (size_t active = translate.size() + contact.size() + rotating.size();
         static_cast<int>(active) < target && next_root < num_roots; ++active)
      startRoot(next_root++);
    if (translate.empty() && contact.empty() && rotating.empty()) break;
    {  // one batched step of every pending pose
      // -------------------------------------------------------------- distance kernel (V-A)
      if (!translate.empty()) {
        tp = Clock::now();
        std::vector<TranslationQuery> q;
        for (const Node& n : translate) q.push_back({n.X, n.pending.front(), n.pending_tmax.front()});
        std::vector<double> t;
        backend->distance(q, t);
        std::vector<Node> again;
        for (size_t i = 0; i < translate.size(); ++i) {
          Node& n = translate[i];
          if (t[i] >= kInf) continue;  // nothing below: the object would fall off the area
          n.X = translated(n.X, t[i] * n.pending.front());
          n.path.push_back(n.X);
          n.pending.erase(n.pending.begin());
          n.pending_tmax.erase(n.pending_tmax.begin());
          (n.pending.empty() ? contact : again).push_back(std::move(n));
        }
        translate.swap(again);
        st.steps.first_contact += msSince(tp);
      }
      // -------------------------------------------------------------- contact kernel (V-B)
      if (!contact.empty()) {
        tp = Clock::now();
        std::vector<Rigid> X;
        for (const Node& n : contact) X.push_back(n.X);
        std::vector<std::vector<SphereContact>> raw;
        backend->contactPoints(X, raw);
        st.steps.contact_points += msSince(tp);
        tp = Clock::now();
        st.tree_nodes += static_cast<long>(contact.size());
        // Contacts, stability (VI) and tilt axis (V-C.1) of every node are independent: computed
        // on the pool; the tree decisions below stay serial, in node order.
        std::vector<Stability> stab(contact.size());
        std::vector<TiltAxis> axes(contact.size());
        parallelFor(contact.size(), config.threads, [&](size_t i) {
          Node& n = contact[i];
          n.contacts = reduceContacts(raw[i], cd);
          const Eigen::Vector3d com = toEigen(apply(n.X, om.com));
          stab[i] = evaluateStability(n.contacts, com, sp);
          const Eigen::Vector3d k1 = toEigen(rotate(n.X, toV3(om.principal_axes.col(0))));
          axes[i] = tiltAxis(n.contacts, com, k1, toEigen(d_g), 1.5 * cd, n.root + 7919u * n.depth);
        });
        for (size_t i = 0; i < contact.size(); ++i) {
          Node& n = contact[i];
          const Eigen::Vector3d com = toEigen(apply(n.X, om.com));
          const Stability& s = stab[i];
          const TiltAxis& axis = axes[i];
          auto leaf = [&](bool stable) {
            leaves.push_back(Leaf{n.X, n.root, stable, s.quality, n.contacts, n.path});
            if (stable) {
              if (stable_count++ == 0) st.first_stable_ms = msSince(t0);
              best_q = std::max(best_q, s.quality);
            }
          };
          if (kTrace) std::fprintf(stderr, "node root %d depth %d opt %d: %zu contacts layout %d planar %d stable %d friction %d inside %d tip %.1f deg Q %.3f failure %d com (%.3f %.3f %.3f) zmin %.4f\n", n.root, n.depth, n.opt, n.contacts.size(), (int)axis.layout, s.planar, s.stable, s.friction_ok, s.com_inside, s.tipping_angle*180/M_PI, s.quality, (int)s.failure, com.x(), com.y(), com.z(), n.contacts.empty()?0.0:n.contacts[0].p_W.z());
          if (n.contacts.empty()) continue;
          // A steep line of contacts (a pen leaning from a cup's floor to its rim) can hold the
          // object by friction; it goes to the stability test like independent contacts. A
          // single contact or a flat line (a cylinder on its side) never holds.
          const bool steep = axis.layout == ContactLayout::kCollinear && std::abs(axis.d_A.z()) > kSteepLine;
          const bool line = !steep && (axis.layout == ContactLayout::kSingle || axis.layout == ContactLayout::kCollinear);
          if (line && n.depth < config.max_rotations && n.turns < kMaxTurnsPerRotation * config.max_rotations) {
            // One contact or a line of contacts never holds an object: tilt (Section V-C).
            n.s_A = axis.s_A;
            n.d_A = axis.d_A;
            n.both_directions = true;
            n.local_rotation = false;
            rotating.push_back(std::move(n));
          } else if (line) {
            leaf(false);
          } else if (s.stable) {
            leaf(true);
          } else if (n.opt < max_opt) {
            const auto tl = Clock::now();
            const LocalStep step = localOptimisationStep(s, com, cd);
            st.steps.local_optimisation += msSince(tl);
            if (step.kind == LocalStep::kSlide) {
              ++n.opt;
              n.X = translated(n.X, toV3(step.lift));
              n.path.push_back(n.X);
              n.pending = {toV3(step.slide), d_g};
              n.pending_tmax = {0.5 * diag, diag};
              translate.push_back(std::move(n));
            } else if (step.kind == LocalStep::kRotate) {
              ++n.opt;
              n.s_A = step.s_A;
              n.d_A = step.d_A;
              if (kTrace) std::fprintf(stderr, "  local rotate d_f (%.3f %.3f %.3f) pivot (%.3f %.3f %.3f) axis (%.3f %.3f %.3f) n_P (%.3f %.3f %.3f)\n", s.d_f.x(), s.d_f.y(), s.d_f.z(), s.pivot.x(), s.pivot.y(), s.pivot.z(), step.d_A.x(), step.d_A.y(), step.d_A.z(), s.plane_normal.x(), s.plane_normal.y(), s.plane_normal.z());
              n.both_directions = false;
              n.local_rotation = true;
              rotating.push_back(std::move(n));
            } else {
              leaf(false);
            }
          } else {
            leaf(false);
          }
        }
        contact.clear();
        st.steps.stability += msSince(tp);
      }
      // -------------------------------------------------------------- rotation kernels (V-C)
      if (!rotating.empty()) {
        std::vector<RotationQuery> q;
        for (const Node& n : rotating) {
          RotationQuery rq{n.X, toV3(n.s_A), toV3(n.d_A)};
          // Of the tree's two branches (Section V-C) only those that lower the centre of mass
          // are followed: gravity cannot tip a free object the other way, and the cut keeps
          // the tree linear in the number of rotations instead of exponential.
          const Eigen::Vector3d c = toEigen(apply(n.X, om.com));
          const double dz = n.d_A.cross(c - n.s_A).z();  // d(com.z)/d(angle) for +rotation
          const double lever = (c - n.s_A).norm();
          if (!n.local_rotation && dz > 1e-3 * lever) rq.limit_ccw = 0;
          if (!n.local_rotation && dz < -1e-3 * lever) rq.limit_cw = 0;
          // Directions a contact blocks, or not asked for, are not searched (limit 0).
          if (blocked(n.contacts, n.s_A, n.d_A, 1, 1.5 * cd)) rq.limit_ccw = 0;
          if (!n.both_directions || blocked(n.contacts, n.s_A, n.d_A, -1, 1.5 * cd)) rq.limit_cw = 0;
          q.push_back(rq);
        }
        std::vector<AnglePair> av, ae;
        tp = Clock::now();
        backend->vertexSurfaceRotation(q, av);
        st.steps.tilt_vertex += msSince(tp);
        // Edge/edge only has to beat the vertex/surface angle. Where no vertex meets a patch
        // within the 60 degree search, the object turns off the area (an edge crossing alone
        // would only be a single contact to tilt further about): no edge/edge search.
        for (size_t i = 0; i < q.size(); ++i) {
          q[i].limit_ccw = av[i].ccw >= kInf ? 0.0 : std::min(q[i].limit_ccw, av[i].ccw);
          q[i].limit_cw = av[i].cw >= kInf ? 0.0 : std::min(q[i].limit_cw, av[i].cw);
        }
        tp = Clock::now();
        backend->edgeEdgeRotation(q, ae);
        st.steps.tilt_edge += msSince(tp);
        for (size_t i = 0; i < rotating.size(); ++i) {
          const Node& n = rotating[i];
          for (int sigma : {1, -1}) {
            if (sigma < 0 && !n.both_directions) continue;
            const double a = sigma > 0 ? std::min(av[i].ccw, ae[i].ccw) : std::min(av[i].cw, ae[i].cw);
            if (kTrace) std::fprintf(stderr, "root %d depth %d opt %d local %d sigma %d contacts %zu angle %.2f deg (v %.2f e %.2f)\n", n.root, n.depth, n.opt, (int)n.local_rotation, sigma, n.contacts.size(), a*180/M_PI, (sigma>0?av[i].ccw:av[i].cw)*180/M_PI, (sigma>0?ae[i].ccw:ae[i].cw)*180/M_PI);
            if (a >= kInf) continue;  // blocked, or turns freely: no resting pose that way
            Node c;
            c.X = rotated(n.X, n.s_A, n.d_A, sigma * a);
            c.root = n.root;
            // Rolling over the facets of a curved surface takes many small turns; only turns of
            // a few degrees count against max_rotations (all of them against a hard cap).
            c.depth = n.depth + (n.local_rotation || a < kSmallTurn ? 0 : 1);
            c.turns = n.turns + 1;
            c.opt = n.opt;
            c.path = n.path;
            c.path.push_back(c.X);
            contact.push_back(std::move(c));
          }
        }
        rotating.clear();
      }
    }
    // Floor points done: roots started whose trees have all ended.
    std::vector<int> open;
    for (const auto* list : {&translate, &contact, &rotating})
      for (const Node& n : *list) open.push_back(n.root);
    std::sort(open.begin(), open.end());
    const int open_roots = static_cast<int>(std::unique(open.begin(), open.end()) - open.begin());
    st.floor_points_done = (next_root - open_roots) / static_cast<int>(orientations.size());
    if (!report()) stop = true;
  }

  // ------------------------------------------------------------------ candidates
  std::vector<size_t> order(leaves.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  // Penetration guard: a stable leaf whose object vertices lie inside the area by more than
  // the sphere radius is not returned as stable.
  for (Leaf& l : leaves)
    if (l.stable && penetrationDepth(om, am, l.X) > r) l.stable = false;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (leaves[a].stable != leaves[b].stable) return leaves[a].stable;
    if (leaves[a].quality != leaves[b].quality) return leaves[a].quality > leaves[b].quality;
    return leaves[a].root < leaves[b].root;
  });
  const Eigen::Matrix3d R_WG = R_GW.transpose();
  const double merge_angle = config.merge_angle_deg * M_PI / 180.0;
  for (size_t idx : order) {
    const Leaf& l = leaves[idx];
    if (l.quality < config.min_quality) continue;
    Candidate c;
    Eigen::Isometry3d X_GO = toIsometry(l.X);
    c.X_WO.linear() = R_WG * X_GO.linear();
    c.X_WO.translation() = R_WG * X_GO.translation();
    bool dup = false;
    for (const Candidate& k : result.candidates)
      if ((k.X_WO.translation() - c.X_WO.translation()).norm() < config.merge_distance &&
          angleBetween(k.X_WO.linear(), c.X_WO.linear()) < merge_angle) {
        dup = true;
        break;
      }
    if (dup) continue;
    c.quality = l.quality;
    c.stable = l.stable;
    // The result summarises the contacts in cells of a third of the object's radius.
    for (const auto& p : reduceContacts(l.contacts, R_obj / 3.0)) c.contacts.push_back({R_WG * p.p_W, R_WG * p.n_W});
    c.floor_point_W = result.floor_points_W[l.root / orientations.size()];
    for (const Rigid& X : l.path) {
      const Eigen::Isometry3d T = toIsometry(X);
      Eigen::Isometry3d W = Eigen::Isometry3d::Identity();
      W.linear() = R_WG * T.linear();
      W.translation() = R_WG * T.translation();
      c.intermediate_poses.push_back(W);
    }
    result.candidates.push_back(std::move(c));
    if (static_cast<int>(result.candidates.size()) >= config.max_candidates) break;
  }
  st.total_ms = msSince(t0);
  return result;
}

}  // namespace place_planner
