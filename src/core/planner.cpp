// The paper's method, step by step (Sections IV-VII). Each step has its own file; plan() reads
// as the sequence: models, floor points, start orientations, the trees of rotations over all
// roots (batched), robustness, ranking. Frames: W planning frame, G = W turned so that gravity
// is -z, O the object's mesh frame.
#include "place_planner/planner.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <future>
#include <mutex>
#include <optional>

#include "place_planner/area_model_cache.h"
#include "place_planner/area_up.h"
#include "place_planner/backend.h"
#include "place_planner/cuda_backend.h"
#include "place_planner/floor_points.h"
#include "place_planner/parallel_for.h"
#include "place_planner/penetration.h"
#include "place_planner/placeability.h"
#include "place_planner/ranking.h"
#include "place_planner/robustness.h"
#include "place_planner/root_search.h"
#include "place_planner/start_orientations.h"
#include "place_planner/work_limits.h"

namespace place_planner {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::once_flag g_backend_log;
// Below this share of surface facing against gravity (within 20 degrees), the plan warns.
constexpr double kMinUpFacingShare = 0.05;
// With the robustness check on, the search stops at this share of the time budget.
constexpr double kSearchShareOfBudget = 0.8;

// Sphere radii and the collision distance (Section V-B), from the object's size: about 1 % of
// it within 0.75 .. 4 mm (down to 5 % of it for objects under 15 mm); the area's spheres
// coarser, in steps shared by similar objects.
struct Radii {
  double r, r_area, cd, cell;
};
Radii sphereRadii(const Mesh& object, const PlannerConfig& config) {
  Radii s;
  const double size = 2.0 * object.properties.bounding_radius;
  s.r = config.sphere_radius > 0 ? config.sphere_radius
                                 : std::clamp(0.01 * size, std::max(1e-5, std::min(0.00075, 0.05 * size)), 0.004);
  s.r_area = areaSphereRadius(s.r);
  // The grid holds for every object radius of this step (up to r_area / 1.5).
  s.cd = s.r_area + s.r_area / 1.5;
  s.cell = config.grid_cell_size > 0 ? config.grid_cell_size : s.cd;
  return s;
}

std::unique_ptr<Backend> chooseBackend(const ObjectModel& om, const AreaModel& am, const TiltParams& tilt,
                                       const PlannerConfig& config) {
  if (config.backend != BackendKind::kCpu) {
    std::string why;
    if (cuda::available(&why)) return makeCudaBackend(om, am, tilt);
    if (config.backend == BackendKind::kCuda)
      throw std::runtime_error("backend = cuda requested but unavailable: " + why);
    std::call_once(g_backend_log, [&] {
      std::fprintf(stderr, "[place_planner] no usable GPU (%s): using the CPU backend\n", why.c_str());
    });
  }
  return makeCpuBackend(om, am, tilt, config.threads);
}

// With gravity wrong for the area (a scan in its camera frame) nothing is flat; say so.
void warnAboutGravity(const Mesh& area, const AreaModel& am, const Eigen::Vector3d& d_g_W, PlanResult& r) {
  if (am.up_facing_share >= kMinUpFacingShare) return;
  const UpEstimate e = estimateUp(area, -d_g_W);
  char msg[320];
  std::snprintf(msg, sizeof msg,
                "placement area: under %.0f %% of its surface faces against gravity; its largest "
                "flat region (%.0f %%) faces (%.3f, %.3f, %.3f): is gravity right?",
                100 * kMinUpFacingShare, 100 * e.share, e.up.x(), e.up.y(), e.up.z());
  r.warnings.push_back(msg);
}

// Floor points (IV-B) in G, in the anytime order, restricted to the region when one is set.
std::vector<V3> findFloorPoints(const AreaModel& am, const PlannerConfig& config, const V3& d_vis,
                                const StopSignal* stop, std::vector<std::string>& warnings) {
  FloorPointParams fpp;
  fpp.d_vis = d_vis;
  fpp.spacing = config.floor_point_spacing;
  fpp.min_points = config.min_floor_points;
  fpp.lowest_n = config.lowest_n;
  fpp.max_rays = config.max_floor_points;
  FloorPoints fp = floorPoints(am, fpp, stop);
  if (fp.coarsened) {
    char msg[200];
    std::snprintf(msg, sizeof msg, "floor_point_spacing %.3g m coarsened to %.3g m (max_floor_points = %d)",
                  config.floor_point_spacing, fp.spacing, config.max_floor_points);
    warnings.push_back(msg);
  }
  std::vector<V3> kept;
  for (const V3& p : fp.points) {
    const Eigen::Vector3d pw = am.R_GW.transpose() * toEigen(p);
    if (!config.hasRegion() || ((pw.array() >= config.region_min.array()).all() &&
                                (pw.array() <= config.region_max.array()).all()))
      kept.push_back(p);
  }
  return orderFloorPoints(kept, fp.spacing);
}

// What the tree steps need (Sections V, VI): models, backend, stability parameters.
TreeContext treeContext(const Mesh& object, const ObjectModel& om, const AreaModel& am, Backend& backend,
                        const Radii& rad, const PlannerConfig& config, PlanStats& st) {
  // Support at least min_support_width wide, or a quarter of the object's middle extent.
  Eigen::Vector3d ext = object.properties.bounds_max - object.properties.bounds_min;
  std::sort(ext.data(), ext.data() + 3);
  const StabilityParams sp{config.friction, 1.5 * rad.cd, config.min_tipping_angle_deg * M_PI / 180.0,
                           std::min(config.min_support_width, 0.25 * ext[1])};
  return TreeContext{om, am, backend, sp, rad.cd, config.max_rotations, config.max_local_optimisation_steps,
                     config.threads, &st.steps, &st.tree_nodes};
}

RobustnessParams robustnessParams(const PlannerConfig& config) {
  RobustnessParams rp;
  rp.shift = config.robust_shift;
  rp.tilt = config.robust_tilt_deg * M_PI / 180.0;
  rp.com_offset = config.robust_com_offset;
  rp.min_share = config.robust_min_share;
  return rp;
}

// Between steps and while a setup step runs: false once the budget (`limit`, ms; 0 = none) is
// spent or the caller cancels through the progress callback (called on the planner's thread).
bool keepGoing(Clock::time_point t0, double limit, const ProgressCallback& progress, Progress p,
               PlanResult& result) {
  if (limit > 0 && msSince(t0) > limit) return !(result.timed_out = true);
  if (!progress) return true;
  p.elapsed_ms = msSince(t0);
  if (!progress(p)) return !(result.cancelled = true);
  return true;
}

// Runs a setup step on a worker while this thread watches the budget and the cancel every
// 10 ms; when either says stop, the step is signalled and its end awaited (within ms: the
// steps poll the signal). Empty when stopped.
template <typename F>
auto runStoppable(F&& step, StopSignal& stop, const std::function<bool()>& keep_going)
    -> std::optional<decltype(step())> {
  auto done = std::async(std::launch::async, std::forward<F>(step));
  while (done.wait_for(std::chrono::milliseconds(10)) != std::future_status::ready)
    if (!keep_going()) {
      stop.request();
      break;
    }
  try {
    auto value = done.get();
    if (stop.requested()) return std::nullopt;
    return value;
  } catch (const Stopped&) {
    return std::nullopt;
  }
}

// Bounded work (work_limits.h): sizes that say "millimetres", model memory; before any model.
// Both models are estimated, the area's even when cached (one that is over the limit was never
// built): O(triangles), no hash of the area on top of the cache's own.
void checkLimits(const Mesh& object, const Mesh& area, const Radii& rad, const PlannerConfig& config,
                 PlanResult& result) {
  for (std::string& w : checkMeshSizes(object, area, config)) result.warnings.push_back(std::move(w));
  for (const Mesh* m : {&object, &area})
    if (m->report.fanned_polygons > 0)
      result.warnings.push_back(std::string(m == &object ? "object" : "placement area") + " mesh: " +
                                std::to_string(m->report.fanned_polygons) +
                                " self-intersecting polygons triangulated as fans (their shape is approximate)");
  const size_t max_tri = static_cast<size_t>(config.max_triangles);
  const double mb = (estimateModelBytes(object, rad.r, 0, 0, max_tri) +
                     estimateModelBytes(area, rad.r_area, rad.cd, rad.cell, max_tri)) /
                    (1024.0 * 1024.0);
  if (mb > config.max_model_mb) {
    char msg[400];
    std::snprintf(msg, sizeof msg,
                  "the sphere models would take about %.0f MB, over max_model_mb = %.0f (object %.3g m, "
                  "area %.3g m across, sphere radius %.2g m): raise the limit, a larger sphere_radius, "
                  "or check the meshes' unit (metres)",
                  mb, config.max_model_mb,
                  (object.properties.bounds_max - object.properties.bounds_min).norm(),
                  (area.properties.bounds_max - area.properties.bounds_min).norm(), rad.r);
    throw LimitError(msg);
  }
}

PlanResult& stopped(PlanResult& result, Clock::time_point t0) {  // by a cancel or the budget
  result.stats.total_ms = msSince(t0);
  return result;
}

std::string decimationWarning(const char* what, size_t from, size_t to, double cell) {
  char msg[200];
  std::snprintf(msg, sizeof msg, "%s decimated from %zu to %zu triangles (max_triangles; detail under %.2g m lost)",
                what, from, to, cell);
  return msg;
}

// The search's bookkeeping between batched steps: the penetration guard, the first robust
// stable pose (each new stable leaf is checked at once until one holds), progress, budget.
struct SearchMonitor {
  const ObjectModel& om;
  const AreaModel& am;
  const PlannerConfig& config;
  const ProgressCallback& progress;
  Clock::time_point t0;
  double search_budget, penetration_limit;
  int orientations;
  std::function<std::vector<Robustness>(const std::vector<size_t>&)> robustness;
  PlanResult& result;
  std::vector<std::pair<size_t, Robustness>> checked;  // leaf index, its robustness
  size_t seen = 0;
  double best_q = 0;
  int stable_count = 0;

  bool keepGoing(double limit) {
    const PlanStats& st = result.stats;
    return place_planner::keepGoing(t0, limit, progress,
                                    Progress{st.floor_points_done, st.floor_points_total, best_q, stable_count, 0},
                                    result);
  }

  bool afterStep(std::vector<TreeLeaf>& all, int started, int open) {
    PlanStats& st = result.stats;
    for (; seen < all.size(); ++seen) {
      TreeLeaf& l = all[seen];
      // Penetration guard: an object inside the area by more than a sphere radius is not stable.
      if (l.stable && penetrationDepth(om, am, l.X_GO) > penetration_limit) l.stable = false;
      if (!l.stable) continue;
      if (st.first_stable_ms < 0 && config.robust_check) {
        const Robustness r = robustness({seen}).front();
        checked.emplace_back(seen, r);
        if (r.share() < config.robust_min_share - 1e-9) continue;
      }
      if (st.first_stable_ms < 0) st.first_stable_ms = msSince(t0);
      ++stable_count;
      best_q = std::max(best_q, l.quality);
    }
    st.floor_points_done = (started - open) / std::max(1, orientations);
    if (st.tree_nodes >= config.max_tree_nodes) {
      result.warnings.push_back("search stopped after max_tree_nodes = " + std::to_string(config.max_tree_nodes) +
                                " poses; " + std::to_string(st.floor_points_done) + " of " +
                                std::to_string(st.floor_points_total) + " floor points done");
      return false;
    }
    return keepGoing(search_budget);
  }

  // Robustness for the ranking: what the search checked already, the rest now.
  std::vector<Robustness> robustnessOf(const std::vector<size_t>& idx) {
    std::vector<Robustness> out(idx.size());
    std::vector<size_t> todo, where;
    for (size_t j = 0; j < idx.size(); ++j) {
      auto it = std::find_if(checked.begin(), checked.end(), [&](const auto& c) { return c.first == idx[j]; });
      if (it != checked.end()) out[j] = it->second;
      else todo.push_back(idx[j]), where.push_back(j);
    }
    if (!todo.empty()) {
      const auto rs = robustness(todo);
      for (size_t j = 0; j < where.size(); ++j) out[where[j]] = rs[j];
    }
    return out;
  }
};

}  // namespace

Planner::Planner() : cache_(std::make_shared<AreaModelCache>()) {}

void Planner::clearAreaCache() const { cache_->clear(); }

PlanResult Planner::plan(const Mesh& object, const Mesh& area, const PlannerConfig& config,
                         const ProgressCallback& progress) const {
  validate(config);
  if (object.empty()) throw std::invalid_argument("object mesh is empty");
  if (area.empty()) throw std::invalid_argument("placement area mesh is empty");
  const auto t0 = Clock::now();
  PlanResult result;
  PlanStats& st = result.stats;
  const double budget = config.time_budget_ms;

  // ---- models (III, V-B): the object's built while the area's is built or fetched
  const Eigen::Vector3d d_g_W = config.gravity.normalized();
  const Eigen::Vector3d d_vis_W = config.approach.norm() > 1e-9 ? Eigen::Vector3d(config.approach.normalized()) : d_g_W;
  const Radii rad = sphereRadii(object, config);
  st.sphere_radius = rad.r;
  const size_t max_tri = static_cast<size_t>(config.max_triangles);
  checkLimits(object, area, rad, config, result);
  StopSignal stop;  // a cancel or the budget reaches the setup steps through it
  const std::function<bool()> setup_going = [&] { return keepGoing(t0, budget, progress, Progress{}, result); };
  auto tp = Clock::now();
  struct Models {
    std::optional<Mesh> object_small;  // the object decimated to max_triangles, if it had more
    double object_cell = 0;             // ... with clusters of this size (m)
    ObjectModel om;
    std::shared_ptr<const AreaModel> am;
  };
  auto models = runStoppable(
      [&] {
        Models m;
        auto area_model = std::async(std::launch::async, [&] {
          return cache_->get(area, d_g_W, rad.r_area, rad.cd, rad.cell, max_tri, &stop);
        });
        if (object.triangles.size() > max_tri) m.object_small = decimated(object, max_tri, &m.object_cell, &stop);
        m.om = buildObjectModel(m.object_small ? *m.object_small : object, rad.r, &stop);
        m.am = area_model.get();
        return m;
      },
      stop, setup_going);
  st.steps.setup = msSince(tp);
  if (!models) return stopped(result, t0);
  const Mesh& obj = models->object_small ? *models->object_small : object;
  if (models->object_small)
    result.warnings.push_back(
        decimationWarning("object mesh", object.triangles.size(), obj.triangles.size(), models->object_cell));
  const ObjectModel& om = models->om;
  const AreaModel& am = *models->am;
  if (am.triangles.size() < am.source_triangles)
    result.warnings.push_back(
        decimationWarning("placement area mesh", am.source_triangles, am.triangles.size(), am.decimation_cell));
  warnAboutGravity(area, am, d_g_W, result);
  const V3 d_vis = toV3(am.R_GW * d_vis_W);
  const std::unique_ptr<Backend> backend = chooseBackend(om, am, TiltParams{0.002, 1e-6 + 1e-4 * rad.r}, config);
  st.backend = backend->name();

  // ---- floor points (IV-B) and start orientations (IV-A): the roots
  tp = Clock::now();
  const Eigen::Matrix3d R_held_G = am.R_GW * config.start_orientation.normalized().toRotationMatrix();
  using Roots = std::pair<std::vector<V3>, std::vector<StartOrientation>>;
  std::vector<std::string> floor_warnings;
  const std::optional<Roots> root_parts = runStoppable(
      [&] {
        return Roots(findFloorPoints(am, config, d_vis, &stop, floor_warnings),
                     startOrientations(obj, R_held_G, toEigen(d_vis), am, config, &stop));
      },
      stop, setup_going);
  st.steps.floor_points = msSince(tp);
  for (std::string& w : floor_warnings) result.warnings.push_back(std::move(w));
  if (!root_parts) return stopped(result, t0);
  const std::vector<V3>& floor_G = root_parts->first;
  // With a grasp, orientations pointing the gripper over max_gripper_tilt_deg are not searched.
  std::vector<StartOrientation> orientations;
  for (const StartOrientation& o : root_parts->second)
    if (gripperTiltOk(o.R_GO, config)) orientations.push_back(o);
  if (orientations.empty())
    result.warnings.push_back("no start orientation points the gripper within max_gripper_tilt_deg of straight down");
  for (const V3& p : floor_G) result.floor_points_W.push_back(am.R_GW.transpose() * toEigen(p));
  const RootSearch roots(floor_G, orientations, obj.properties, am, d_vis);
  st.floor_points_total = static_cast<int>(floor_G.size());
  st.start_orientations = static_cast<int>(orientations.size());
  st.roots_total = roots.size();

  // ---- the trees of rotations (V, VI), every pending pose batched (VII-C)
  const TreeContext ctx = treeContext(obj, om, am, *backend, rad, config, st);
  const RobustnessParams rp = robustnessParams(config);
  std::vector<TreeLeaf> leaves;
  std::function<bool()> robustness_going;  // the monitor's, once it exists
  auto robustness = [&](const std::vector<size_t>& idx) {  // robust stability, beyond the paper
    const auto tr = Clock::now();
    std::vector<Rigid> X;
    for (size_t i : idx) X.push_back(leaves[i].X_GO);
    auto out = checkRobustness(X, ctx, rp, robustness_going);
    st.robustness_ms += msSince(tr);
    return out;
  };
  // With the robustness check on, the search leaves a share of the budget for it.
  SearchMonitor monitor{om, am, config, progress, t0,
                        budget * (config.robust_check ? kSearchShareOfBudget : 1.0), rad.r,
                        static_cast<int>(orientations.size()), robustness, result, {}, 0, 0.0, 0};
  robustness_going = [&] { return monitor.keepGoing(budget); };
  TreeStepper stepper(ctx);
  streamRoots(roots, stepper, om.com, static_cast<int>(backend->preferredBatch()), leaves,
              [&](int started, int open) { return monitor.afterStep(leaves, started, open); });
  for (const TreeLeaf& l : leaves) {
    st.trees_without_rest += !l.at_rest;
    st.roll_bottoms += l.rolled;
  }

  // ---- ranking (VI's Q, robust stability, re-orientation)
  std::vector<StartKind> kinds(roots.size());
  std::vector<Eigen::Vector3d> floor_W(roots.size());
  for (int k = 0; k < roots.size(); ++k) {
    kinds[k] = roots.kind(k);
    floor_W[k] = result.floor_points_W[roots.floorPoint(k)];
  }
  RankingInput in{leaves, kinds, floor_W, am.R_GW, R_held_G, obj.properties.bounding_radius,
                  obj.properties.center_of_mass};
  for (const auto& [leaf, r] : monitor.checked)
    if (r.share() >= config.robust_min_share - 1e-9) in.robust_leaves.push_back(leaf);
  const PlaceabilityContext pc{om, am, *backend, d_vis, config};
  result.candidates = rankCandidates(
      in, config, [&](const std::vector<size_t>& idx) { return monitor.robustnessOf(idx); }, &st,
      [&](size_t i) { return checkPlacement(leaves[i], pc); });
  if (config.has_grasp && config.gripper && result.stableCount() == 0 && st.gripper_rejected > 0)
    result.warnings.push_back("the gripper blocks every stable pose checked (" + std::to_string(st.gripper_rejected) +
                              " candidates): at the goal, on the approach or the retreat");
  if (budget > 0 && msSince(t0) > budget) result.timed_out = true;
  st.total_ms = msSince(t0);
  return result;
}

}  // namespace place_planner
