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

#include "place_planner/area_model_cache.h"
#include "place_planner/area_up.h"
#include "place_planner/backend.h"
#include "place_planner/cuda_backend.h"
#include "place_planner/floor_points.h"
#include "place_planner/parallel_for.h"
#include "place_planner/penetration.h"
#include "place_planner/ranking.h"
#include "place_planner/robustness.h"
#include "place_planner/root_search.h"
#include "place_planner/start_orientations.h"

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
// it within 0.75 .. 4 mm; the area's spheres coarser, in steps shared by similar objects.
struct Radii {
  double r, r_area, cd, cell;
};
Radii sphereRadii(const Mesh& object, const PlannerConfig& config) {
  Radii s;
  s.r = config.sphere_radius > 0 ? config.sphere_radius
                                 : std::clamp(0.01 * 2.0 * object.properties.bounding_radius, 0.00075, 0.004);
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
std::vector<V3> findFloorPoints(const AreaModel& am, const PlannerConfig& config, const V3& d_vis) {
  FloorPointParams fpp;
  fpp.d_vis = d_vis;
  fpp.spacing = config.floor_point_spacing;
  fpp.min_points = config.min_floor_points;
  fpp.lowest_n = config.lowest_n;
  FloorPoints fp = floorPoints(am, fpp);
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
    if (search_budget > 0 && msSince(t0) > search_budget) return !(result.timed_out = true);
    if (!progress) return true;
    const Progress p{st.floor_points_done, st.floor_points_total, best_q, stable_count, msSince(t0)};
    if (!progress(p)) return !(result.cancelled = true);
    return true;
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
  auto tp = Clock::now();
  auto object_model = std::async(std::launch::async, [&] { return buildObjectModel(object, rad.r); });
  const std::shared_ptr<const AreaModel> area_model = cache_->get(area, d_g_W, rad.r_area, rad.cd, rad.cell);
  const ObjectModel om = object_model.get();
  const AreaModel& am = *area_model;
  st.steps.setup = msSince(tp);
  warnAboutGravity(area, am, d_g_W, result);
  const V3 d_vis = toV3(am.R_GW * d_vis_W);
  const std::unique_ptr<Backend> backend = chooseBackend(om, am, TiltParams{0.002, 1e-6 + 1e-4 * rad.r}, config);
  st.backend = backend->name();

  // ---- floor points (IV-B) and start orientations (IV-A): the roots
  tp = Clock::now();
  const std::vector<V3> floor_G = findFloorPoints(am, config, d_vis);
  for (const V3& p : floor_G) result.floor_points_W.push_back(am.R_GW.transpose() * toEigen(p));
  st.steps.floor_points = msSince(tp);
  const Eigen::Matrix3d R_held_G = am.R_GW * config.start_orientation.normalized().toRotationMatrix();
  const auto orientations = startOrientations(object, R_held_G, toEigen(d_vis), am, config);
  const RootSearch roots(floor_G, orientations, object.properties, am, d_vis);
  st.floor_points_total = static_cast<int>(floor_G.size());
  st.start_orientations = static_cast<int>(orientations.size());
  st.roots_total = roots.size();

  // ---- the trees of rotations (V, VI), every pending pose batched (VII-C)
  const TreeContext ctx = treeContext(object, om, am, *backend, rad, config, st);
  const RobustnessParams rp = robustnessParams(config);
  std::vector<TreeLeaf> leaves;
  auto robustness = [&](const std::vector<size_t>& idx) {  // robust stability, beyond the paper
    const auto tr = Clock::now();
    std::vector<Rigid> X;
    for (size_t i : idx) X.push_back(leaves[i].X_GO);
    auto out = checkRobustness(X, ctx, rp, [&] { return budget <= 0 || msSince(t0) < budget; });
    st.robustness_ms += msSince(tr);
    return out;
  };
  // With the robustness check on, the search leaves a share of the budget for it.
  SearchMonitor monitor{om, am, config, progress, t0,
                        budget * (config.robust_check ? kSearchShareOfBudget : 1.0), rad.r,
                        static_cast<int>(orientations.size()), robustness, result, {}, 0, 0.0, 0};
  TreeStepper stepper(ctx);
  streamRoots(roots, stepper, om.com, std::max(16, 12 * resolveThreads(config.threads)), leaves,
              [&](int started, int open) { return monitor.afterStep(leaves, started, open); });
  for (const TreeLeaf& l : leaves) st.trees_without_rest += !l.at_rest;

  // ---- ranking (VI's Q, robust stability, re-orientation)
  std::vector<StartKind> kinds(roots.size());
  std::vector<Eigen::Vector3d> floor_W(roots.size());
  for (int k = 0; k < roots.size(); ++k) {
    kinds[k] = roots.kind(k);
    floor_W[k] = result.floor_points_W[roots.floorPoint(k)];
  }
  const RankingInput in{leaves, kinds, floor_W, am.R_GW, R_held_G, object.properties.bounding_radius};
  result.candidates = rankCandidates(
      in, config, [&](const std::vector<size_t>& idx) { return monitor.robustnessOf(idx); }, &st);
  if (budget > 0 && msSince(t0) > budget) result.timed_out = true;
  st.total_ms = msSince(t0);
  return result;
}

}  // namespace place_planner
