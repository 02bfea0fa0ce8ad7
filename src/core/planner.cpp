// The paper's method, step by step (Sections IV-VII). Each step has its own file; plan() reads
// as the sequence: models (buildModels), floor points and start orientations (findRoots), the
// trees of rotations over all roots, batched, with robustness (TreeSearch::run), ranking
// (TreeSearch::rank). Frames: W planning frame, G = W turned so that gravity
// is -z, O the object's mesh frame.
#include "place_planner/planner.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <limits>
#include <future>
#include <mutex>
#include <optional>

#include "place_planner/infra/stable_sort.h"
#include "place_planner/model/area_model_cache.h"
#include "place_planner/model/completion.h"
#include "place_planner/model/despike.h"
#include "place_planner/model/area_up.h"
#include "place_planner/model/winding.h"
#include "place_planner/infra/backend.h"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/search/floor_points.h"
#include "place_planner/search/hanging_starts.h"
#include "place_planner/infra/parallel_for.h"
#include "place_planner/judgement/penetration.h"
#include "place_planner/manipulation/level_release.h"
#include "place_planner/manipulation/placeability.h"
#include "place_planner/judgement/ranking.h"
#include "place_planner/judgement/robustness.h"
#include "place_planner/judgement/drop_margin.h"
#include "place_planner/search/opening_points.h"
#include "place_planner/search/root_search.h"
#include "place_planner/search/start_orientations.h"
#include "place_planner/infra/work_limits.h"

namespace place_planner {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

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
// `r` > 0: the object's sphere radius as given (a hanging object's tight loop, fineRadius).
Radii sphereRadii(const Mesh& object, const PlannerConfig& config, double r = 0) {
  Radii s;
  const double size = 2.0 * object.properties.bounding_radius;
  s.r = r > 0 ? r
        : config.sphere_radius > 0 ? config.sphere_radius
                                   : std::clamp(0.01 * size, std::max(1e-5, std::min(0.00075, 0.05 * size)), 0.004);
  s.r_area = areaSphereRadius(s.r);
  // The grid holds for every object radius of this step (up to r_area / 1.5).
  s.cd = s.r_area + s.r_area / 1.5;
  s.cell = config.grid_cell_size > 0 ? config.grid_cell_size : s.cd;
  return s;
}

// `auto` is CUDA where a GPU answers: on an H200 the split kernels plan the paper's workload 1.6x
// faster than two CPU threads (doc/gpu.md, "Measured"), else the CPU. `note` says which and why,
// for the caller to show (the CLI with -v, the node once in its log), not a warning.
std::unique_ptr<Backend> chooseBackend(const ObjectModel& om, const AreaModel& am, const TiltParams& tilt,
                                       const PlannerConfig& config, std::string* note) {
  if (config.backend != BackendKind::kCpu) {
    std::string why;
    if (cuda::available(&why)) {
      if (config.backend == BackendKind::kAuto) *note = "backend auto: CUDA (a usable GPU, doc/gpu.md)";
      return makeCudaBackend(om, am, tilt);
    }
    if (config.backend == BackendKind::kCuda) throw std::runtime_error("backend = cuda requested but unavailable: " + why);
    *note = "backend auto: the CPU (no usable GPU: " + why + ")";
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

// A step of the area the object notices (m): a quarter of its middle extent, at least 1 cm; an
// opening's wall (opening_points.h), a drop-off (drop_margin.h).
double noticeableStep(const MeshProperties& object) {
  Eigen::Vector3d ext = object.bounds_max - object.bounds_min;
  std::sort(ext.data(), ext.data() + 3);
  return std::max(0.01, 0.25 * ext[1]);
}

// Whether the point p (G) lies in the config's region (W), or no region is set.
bool inRegion(const PlannerConfig& config, const AreaModel& am, const V3& p) {
  const Eigen::Vector3d pw = am.R_GW.transpose() * toEigen(p);
  return !config.hasRegion() ||
         ((pw.array() >= config.region_min.array()).all() && (pw.array() <= config.region_max.array()).all());
}

// Floor points (IV-B) in G, in the anytime order, restricted to the region when one is set.
std::vector<V3> findFloorPoints(const AreaModel& am, const MeshProperties& object, const PlannerConfig& config,
                                const V3& d_vis, const StopSignal* stop, std::vector<std::string>& warnings,
                                int* openings) {
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
  for (const V3& p : fp.points)
    if (inRegion(config, am, p)) kept.push_back(p);
  std::vector<V3> ordered = orderFloorPoints(kept, fp.spacing);
  // The middles of the openings the grid's rays fell into (opening_points.h), first: where a
  // person puts an object into a cup or a compartment. Lowered along gravity only.
  if (norm(d_vis - v3(0, 0, -1)) > 1e-6) return ordered;
  Eigen::Vector3d ext = object.bounds_max - object.bounds_min;
  std::sort(ext.data(), ext.data() + 3);
  OpeningParams op;
  op.reach = 1.25 * object.bounding_radius;  // walls the object would meet
  op.wall_height = noticeableStep(object);
  op.min_clearance = 0.5 * ext[0];           // its narrowest side fits
  op.merge = std::max(0.01, 0.25 * fp.spacing);
  std::vector<V3> points;
  for (const V3& c : openingCentres(am.grid, ordered, op, stop))
    if (inRegion(config, am, c)) points.push_back(c);
  *openings = static_cast<int>(points.size());
  points.insert(points.end(), ordered.begin(), ordered.end());
  return points;
}

// Sideways penetration allowed, in sphere radii: the contact distance of the object's spheres
// against the area's (1.5 r, area_model_cache.h, before its rounding). The swing lowers an
// object along gravity only, so against a wall it settles within that band of the wall, not
// on it (penetration.h; measured on the hanging suites, doc/method.md).
constexpr double kSidewaysPenetration = 2.5;
// m: a returned hanging pose is moved out of the area and this far beyond (clearOfTheArea).
constexpr double kResultClearance = 0.0005;

// What the tree steps need (Sections V, VI): models, backend, stability parameters.
TreeContext treeContext(const Mesh& object, const ObjectModel& om, const AreaModel& am, Backend& backend,
                        const Radii& rad, const PlannerConfig& config, PlanStats& st, bool scanned) {
  // Support at least min_support_width wide, or a quarter of the object's middle extent.
  Eigen::Vector3d ext = object.properties.bounds_max - object.properties.bounds_min;
  std::sort(ext.data(), ext.data() + 3);
  const StabilityParams sp{config.friction, 1.5 * rad.cd, config.min_tipping_angle_deg * M_PI / 180.0,
                           std::min(config.min_support_width, 0.25 * ext[1])};
  TreeContext ctx{om, am, backend, sp, rad.cd, config.max_rotations, config.max_local_optimisation_steps,
                  config.threads, &st.steps, &st.tree_nodes};
  ctx.rock_settle = config.rock_settle;
  ctx.shape_uncertainty = scanned ? config.scan_noise : 0.0;  // a scan's crests are its noise's
  ctx.penetration_limit = rad.r;  // as the result's guard (SearchMonitor::afterStep)
  ctx.penetration_sideways = kSidewaysPenetration * rad.r;
  return ctx;
}

RobustnessParams robustnessParams(const PlannerConfig& config, bool scanned) {
  RobustnessParams rp;
  // Shape noise of a scan (config.h scan_noise) through the centre-of-mass trials.
  rp.min_com_offset = scanned ? config.scan_noise : 0.0;
  if (scanned && config.scan_noise > 0) rp.end_roll_move = 0;  // its rolls are its shape's noise
  rp.shift = config.robust_shift;
  rp.tilt = config.robust_tilt_deg * M_PI / 180.0;
  rp.com_offset = config.robust_com_offset;
  rp.min_share = config.robust_min_share;
  rp.min_share_hanging = config.robust_min_share_hanging;
  rp.recheck_caught = config.robust_recheck_caught;
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

// The sphere models' estimated memory (MB) at these radii.
double modelMegabytes(const Mesh& object, const Mesh& area, const Radii& rad, const PlannerConfig& config) {
  const size_t max_tri = static_cast<size_t>(config.max_triangles);
  return (estimateModelBytes(object, rad.r, 0, 0, max_tri) + estimateModelBytes(area, rad.r_area, rad.cd, rad.cell, max_tri)) /
         (1024.0 * 1024.0);
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
  const double mb = modelMegabytes(object, area, rad, config);
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
  double search_budget, penetration_limit, penetration_sideways;
  int orientations;
  int hanging;  // roots before the floor points' (root_search.h)
  std::function<std::vector<Robustness>(const std::vector<size_t>&)> robustness;
  PlanResult& result;
  std::vector<std::pair<size_t, Robustness>> checked;  // leaf index, its robustness
  size_t seen = 0;
  size_t chunk = 1;  // leaves checked together while no robust one is found
  double best_q = 0;
  int stable_count = 0;

  bool keepGoing(double limit) {
    const PlanStats& st = result.stats;
    return place_planner::keepGoing(t0, limit, progress,
                                    Progress{st.floor_points_done, orientations > 0 ? st.floor_points_total : 0,
                                             st.hanging_starts_done, st.hanging_starts, best_q, stable_count, 0},
                                    result);
  }

  bool afterStep(std::vector<TreeLeaf>& all, int started, int open) {
    PlanStats& st = result.stats;
    // Penetration guard: an object inside the area by more than a sphere radius below a
    // surface, or by more than 2.5 radii (the contact distance) in a wall or a post, is not
    // stable (the new stable leaves tested on the pool; penetration.h, kSidewaysPenetration).
    // Hanging leaves by all the object's probes, standing ones by its vertices (penetration.h).
    std::vector<size_t> fresh;
    for (; seen < all.size(); ++seen)
      if (all[seen].stable) fresh.push_back(seen);
    std::vector<char> inside(fresh.size(), 0);
    parallelFor(fresh.size(), config.threads, [&](size_t k) {
      const TreeLeaf& l = all[fresh[k]];
      inside[k] = !penetration(om, am, l.X_GO, 0.03, l.hanging).within(penetration_limit, penetration_sideways);
    });
    for (size_t k = 0; k < fresh.size(); ++k)
      if (inside[k]) all[fresh[k]].stable = false, all[fresh[k]].inside = true;
    fresh.erase(std::remove_if(fresh.begin(), fresh.end(), [&](size_t i) { return !all[i].stable; }), fresh.end());
    // Until a robust stable pose is found, the new stable leaves are checked at once, in chunks
    // that double while none holds (1, 2, 4, 8: many trials in flight where poses keep failing,
    // as on peg tops; one check where the first holds). Bounded work: after 2 x rankedCandidates()
    // checks without one, or past max_tree_nodes (the trials' nodes count), the ranking checks
    // the best of the rest (it would check them anyway).
    size_t j = 0;
    const size_t max_checks = 2 * static_cast<size_t>(config.rankedCandidates());
    while (j < fresh.size() && st.first_stable_ms < 0 && config.robust_check && checked.size() < max_checks &&
           st.tree_nodes < config.max_tree_nodes) {
      const size_t n = std::min({fresh.size() - j, chunk, max_checks - checked.size()});
      const std::vector<size_t> batch(fresh.begin() + j, fresh.begin() + j + n);
      const std::vector<Robustness> rs = robustness(batch);
      for (size_t k = 0; k < n; ++k) {
        checked.emplace_back(batch[k], rs[k]);
        if (!config.robustShare(rs[k].share(), all[batch[k]].hanging)) continue;
        if (st.first_stable_ms < 0) st.first_stable_ms = msSince(t0);
        ++stable_count;
        best_q = std::max(best_q, all[batch[k]].quality);
      }
      j += n;
      chunk = std::min<size_t>(2 * chunk, 8);
    }
    // The rest: stable without a robustness check, or once a robust pose was found (the ranking
    // checks them); unchecked leaves past the bound are the ranking's.
    if (!config.robust_check || st.first_stable_ms >= 0)
      for (; j < fresh.size(); ++j) {
        if (st.first_stable_ms < 0) st.first_stable_ms = msSince(t0);
        ++stable_count;
        best_q = std::max(best_q, all[fresh[j]].quality);
      }
    // The hanging roots come first (root_search.h): trees done count against them, then
    // against the floor points (each with its start orientations).
    const int done = std::max(0, started - open);
    st.hanging_starts_done = std::min(done, hanging);
    st.floor_points_done = std::max(0, done - hanging) / std::max(1, orientations);
    if (st.tree_nodes >= config.max_tree_nodes) {
      result.warnings.push_back("search stopped after max_tree_nodes = " + std::to_string(config.max_tree_nodes) +
                                " poses; " + searchedRoots(st) + " done");
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

// ------------------------------------------------------------------ one plan, step by step
// One plan's state shared by its steps: the inputs, the clock and the budget, the answer being
// built, and the stop signal that a cancel or the budget sends to the setup steps.
struct PlanRun {
  PlanRun(const Completion& o, const Mesh& a, const PlannerConfig& c, const ProgressCallback& p)
      : completion(o), object(o.mesh()), area(a), config(c), progress(p) {}
  PlanRun(const PlanRun&) = delete;  // setup_going points at this one
  const Completion& completion;  // the object with its open regions capped (completion.h)
  const Mesh& object;
  const Mesh& area;
  const PlannerConfig& config;
  const ProgressCallback& progress;
  Clock::time_point t0 = Clock::now();
  double budget = config.time_budget_ms;
  PlanResult result;
  StopSignal stop;
  std::function<bool()> setup_going = [this] { return keepGoing(t0, budget, progress, Progress{}, result); };
  PlanStats& st() { return result.stats; }
  // A scan: open (capped), or closed and said to be one (PlannerConfig::closed_scan).
  bool scanned() const { return completion.completed() || config.closed_scan; }
};

// The models (III, V-B) and what the steps need of them. Frames: W planning, G gravity -z.
struct Models {
  Radii rad{};
  Eigen::Vector3d d_g_W, d_vis_W;
  std::optional<Mesh> object_small;  // the object decimated to max_triangles, if it had more
  double object_cell = 0;             // ... with clusters of this size (m)
  ObjectModel om;
  std::shared_ptr<const AreaModel> am;
  V3 d_vis{0, 0, -1};  // approach direction, G
  std::unique_ptr<Backend> backend;
  // The area's pegs (search/pegs.h), found beside the object's model while it is built; empty
  // unless hanging is asked for.
  std::vector<Peg> pegs;
  // The object's loops (search/loops.h), found where the area has pegs (findObjectLoops).
  std::vector<Loop> loops;
  const Mesh& searched(const Mesh& object) const { return object_small ? *object_small : object; }
};

// The object's model is built while the area's is built or fetched from the cache; both poll
// the stop signal. Empty when stopped. `r` > 0: built again finer (fineRadius), the pegs kept.
std::optional<Models> buildModels(PlanRun& run, AreaModelCache& cache, double r = 0) {
  const PlannerConfig& config = run.config;
  Models m;
  m.d_g_W = config.gravity.normalized();
  m.d_vis_W = config.approach.norm() > 1e-9 ? Eigen::Vector3d(config.approach.normalized()) : m.d_g_W;
  m.rad = sphereRadii(run.object, config, r);
  run.st().sphere_radius = m.rad.r;
  const size_t max_tri = static_cast<size_t>(config.max_triangles);
  checkLimits(run.object, run.area, m.rad, config, run.result);
  const auto tp = Clock::now();
  const bool built = runStoppable(
                         [&] {
                           auto area_model = std::async(std::launch::async, [&] {
                             auto am = cache.get(run.area, m.d_g_W, m.rad.r_area, m.rad.cd, m.rad.cell, max_tri, &run.stop);
                             if (config.placement != PlacementKind::kStanding && r == 0) m.pegs = findPegs(*am, {}, &run.stop);
                             return am;
                           });
                           if (run.object.triangles.size() > max_tri)
                             m.object_small = decimated(run.object, max_tri, &m.object_cell, &run.stop);
                           m.om = buildObjectModel(m.searched(run.object), m.rad.r, &run.stop);
                           m.am = area_model.get();
                           return true;
                         },
                         run.stop, run.setup_going)
                         .has_value();
  run.st().steps.setup += msSince(tp);
  if (!built) return std::nullopt;
  if (m.object_small)
    run.result.warnings.push_back(decimationWarning("object mesh", run.object.triangles.size(),
                                                    m.object_small->triangles.size(), m.object_cell));
  const AreaModel& am = *m.am;
  if (am.triangles.size() < am.source_triangles)
    run.result.warnings.push_back(
        decimationWarning("placement area mesh", am.source_triangles, am.triangles.size(), am.decimation_cell));
  warnAboutGravity(run.area, am, m.d_g_W, run.result);
  if (am.winding_reversed)
    run.result.warnings.push_back("placement area mesh: wound inwards (its normals point into the solid, or down on a "
                                  "scan seen from above); planned wound outwards (model/winding.h)");
  m.d_vis = toV3(am.R_GW * m.d_vis_W);
  m.backend = chooseBackend(m.om, am, TiltParams{0.002, 1e-6 + 1e-4 * m.rad.r}, config, &run.st().backend_note);
  run.st().backend = m.backend->name();
  return m;
}

// Where the area has pegs and hanging is searched (buildModels found them): the object's loops,
// for fineRadius and findRoots (counted in the setup step). False when stopped.
bool findObjectLoops(PlanRun& run, Models& m) {
  if (m.pegs.empty()) return true;
  const auto tp = Clock::now();
  const bool found = runStoppable(
                         [&] {
                           m.loops = findLoops(m.searched(run.object), {}, &run.stop);
                           return true;
                         },
                         run.stop, run.setup_going)
                         .has_value();
  run.st().steps.setup += msSince(tp);
  return found;
}

// Where the models close even the widest loop-on-peg fit (the contact distance at least the
// loop's room round the peg: its largest circle less the peg's half width; a loop centred on
// the peg touches it on both sides), the sphere radius whose contact distance is at most half
// that room: a pan handle's slot 2 cm wide on a J-hook's 8 mm wire, 6 mm either side, at 9.4 mm.
// Where a loop's bar and a peg are both thinner than the contact distance (half its thickness
// and the peg's half width under it), the contact distance at most the thinner of the two: the
// contact normals there blend across both round surfaces (a basket's 8 mm arched handle on a
// cup hook's 6 mm wire at 6.7 mm spread 45 degrees along the wire) and their forces did not
// balance below a centre of mass hanging straight under the wire.
// 0: the models built serve (a given sphere_radius is kept; a finer model than needed changed
// the mugs' answers, measured on the held-out racks). At least the smallest default radius.
double fineRadius(const PlanRun& run, const Models& m) {
  if (run.config.sphere_radius > 0) return 0;
  double room = 0, thin = 0;
  for (const Peg& peg : m.pegs)
    for (const Loop& loop : m.loops)
      if (loop.radius >= peg.half_width + 0.001) {
        room = std::max(room, loop.radius - peg.half_width);
        if (m.rad.cd > peg.half_width && m.rad.cd > 0.5 * loop.thickness)
          thin = std::max(thin, std::min(peg.half_width, 0.5 * loop.thickness));
      }
  // The largest contact distance that serves.
  double cd_max = room > 0 && m.rad.cd >= room ? 0.5 * room : kInf;
  if (thin > 0) cd_max = std::min(cd_max, thin);
  if (cd_max == kInf) return 0;
  // cd = r_area (1 + 1 / 1.5), r_area a step of sqrt(2) from 1 mm and at least 1.5 r
  // (sphereRadii, areaSphereRadius): the largest such r_area under the bound, r a third smaller.
  const double r_area = 0.001 * std::pow(std::sqrt(2.0), std::floor(std::log(0.6 * cd_max / 0.001) / std::log(std::sqrt(2.0))));
  const double r = std::max(r_area / 1.5, 0.00075);
  if (r >= m.rad.r) return 0;
  // Within the model memory limit (checkLimits), else as built.
  const double mb = modelMegabytes(run.object, run.area, sphereRadii(run.object, run.config, r), run.config);
  return mb <= run.config.max_model_mb ? r : 0;
}

// The roots (IV): floor points (IV-B) by ray casting and start orientations (IV-A); with a
// grasp, orientations pointing the gripper over max_gripper_tilt_deg are not searched.
struct Roots {
  Eigen::Matrix3d R_held_G;
  std::vector<V3> floor_G;
  int openings = 0;  // the first floor points: middles of openings (opening_points.h)
  std::vector<StartOrientation> orientations;
  std::vector<HangingStart> hanging;  // the object threaded by a loop on a peg (beyond the paper)
};

// The roots over the floor points and start orientations, those over openings turned to fit.
RootSearch rootSearch(const Roots& r, const Models& m, const Mesh& object) {
  RootSearch roots(r.floor_G, r.orientations, m.searched(object).properties, *m.am, m.d_vis, r.hanging);
  roots.fitOpenings(r.openings, *m.am, m.om.spheres.centres);
  return roots;
}

std::optional<Roots> findRoots(PlanRun& run, const Models& m) {
  const AreaModel& am = *m.am;
  Roots r;
  r.R_held_G = am.R_GW * run.config.start_orientation.normalized().toRotationMatrix();
  const auto tp = Clock::now();
  std::vector<std::string> floor_warnings;
  std::vector<StartOrientation> all;
  const std::vector<Peg>& pegs = m.pegs;
  const std::vector<Loop>& loops = m.loops;
  const PlacementKind kind = run.config.placement;
  const bool found = runStoppable(
                         [&] {
                           r.floor_G = findFloorPoints(am, m.searched(run.object).properties, run.config, m.d_vis, &run.stop, floor_warnings, &r.openings);
                           if (kind != PlacementKind::kHanging)
                             all = startOrientations(m.searched(run.object), r.R_held_G, toEigen(m.d_vis), am,
                                                     run.config, &run.stop);
                           return true;
                         },
                         run.stop, run.setup_going)
                         .has_value();
  for (std::string& w : floor_warnings) run.result.warnings.push_back(std::move(w));
  if (!found) return std::nullopt;
  int threaded = 0;
  for (const HangingStart& h : hangingStarts(pegs, loops, m.om, *m.backend, m.rad.cd, run.config.friction)) {
    ++threaded;
    if (gripperTiltOk(toIsometry(h.X_GO).linear(), run.config)) r.hanging.push_back(h);
  }
  run.st().steps.floor_points = msSince(tp);
  run.st().pegs = static_cast<int>(pegs.size());
  run.st().loops = static_cast<int>(loops.size());
  run.st().hanging_starts = static_cast<int>(r.hanging.size());
  if (kind == PlacementKind::kHanging && r.hanging.empty())
    run.result.warnings.push_back(
        "placement = hanging, but nothing to hang on: " + std::to_string(pegs.size()) + " pegs on the area, " +
        std::to_string(loops.size()) + " loops of the object" +
        (pegs.empty() || loops.empty() ? ""
         : threaded == 0           ? ", none threaded free (too short, too thick or blocked)"
                                   : ", " + std::to_string(threaded) +
                                         " threaded, none with the gripper within max_gripper_tilt_deg of straight down"));
  for (const StartOrientation& o : all)
    if (gripperTiltOk(o.R_GO, run.config)) r.orientations.push_back(o);
  if (r.orientations.empty() && kind != PlacementKind::kHanging)
    run.result.warnings.push_back("no start orientation points the gripper within max_gripper_tilt_deg of straight down");
  for (const V3& p : r.floor_G) run.result.floor_points_W.push_back(am.R_GW.transpose() * toEigen(p));
  run.st().floor_points_total = static_cast<int>(r.floor_G.size());
  run.st().start_orientations = static_cast<int>(r.orientations.size());
  return r;
}

// The trees of rotations (V, VI) over every root, every pending pose batched (VII-C), with the
// robustness check (beyond the paper) of new stable leaves while they come, then the ranking.
class TreeSearch {
 public:
  TreeSearch(PlanRun& run, const Models& m, const Roots& r)
      : run_(run),
        m_(m),
        roots_(rootSearch(r, m, run.object)),
        ctx_(treeContext(m.searched(run.object), m.om, *m.am, *m.backend, m.rad, run.config, run.st(),
                         run.scanned())),
        rp_(robustnessParams(run.config, run.scanned())),
        // With the robustness check on, the search leaves a share of the budget for it.
        monitor_{m.om, *m.am, run.config, run.progress, run.t0,
                 run.budget * (run.config.robust_check ? kSearchShareOfBudget : 1.0), m.rad.r,
                 kSidewaysPenetration * m.rad.r, static_cast<int>(r.orientations.size()),
                 static_cast<int>(r.hanging.size()),
                 [this](const std::vector<size_t>& idx) { return robustness(idx); }, run.result, {}, 0, 1, 0.0, 0} {
    run.st().roots_total = roots_.size();
  }

  void run() {
    TreeStepper stepper(ctx_);
    // A step adds about one node per active pose: a batch under a quarter of max_tree_nodes
    // keeps the stop near the limit on a backend that would take every pose at once (CUDA).
    const long batch = std::min<long>(static_cast<long>(m_.backend->preferredBatch()),
                                      std::max<long>(16, run_.config.max_tree_nodes / 4));
    streamRoots(roots_, stepper, m_.om.com, static_cast<int>(batch), leaves_,
                [&](int started, int open) { return monitor_.afterStep(leaves_, started, open); });
    for (const TreeLeaf& l : leaves_) {
      run_.st().trees_without_rest += !l.at_rest;
      run_.st().roll_bottoms += l.rolled;
      run_.st().trees_fallen += l.fell;
      rolls_not_held_ += l.rolled && !l.stable;
    }
  }

  // Trees that ended lying at the bottom of a roll that does not hold a release (its crests
  // lower than the shape's uncertainty, or than kMinRollRise: tree_stepper.cpp).
  int rollsNotHeld() const { return rolls_not_held_; }

  // Ranking (VI's Q, robust stability, re-orientation, the gripper's placement).
  void rank(const Roots& r) {
    const PlannerConfig& config = run_.config;
    std::vector<StartKind> kinds(roots_.size());
    std::vector<Eigen::Vector3d> floor_W(roots_.size());
    for (int k = 0; k < roots_.size(); ++k) {
      kinds[k] = roots_.kind(k);
      floor_W[k] = m_.am->R_GW.transpose() * toEigen(roots_.floorPointG(k));
    }
    const MeshProperties& props = m_.searched(run_.object).properties;
    RankingInput in{leaves_, kinds, floor_W, m_.am->R_GW, r.R_held_G, props.bounding_radius, props.center_of_mass};
    for (const auto& [leaf, rb] : monitor_.checked)
      if (config.robustShare(rb.share(), leaves_[leaf].hanging)) in.robust_leaves.push_back(leaf);
    in.cut = [this] { return run_.result.cancelled || run_.result.timed_out; };
    if (run_.scanned() || !m_.am->open_edges.empty()) {
      // A contact on a cap of the object, away from the seen rim by more than the contact
      // spheres' reach, or a contact the object leans on (its normal outside the friction cone
      // about the vertical: a wall, a peg's side) at the border of what the area's scan saw
      // (completion.h). Resting on a top face near its edge is not leaning on the unseen side.
      const double margin = std::max(0.003, 2.0 * m_.rad.r);
      const double floor_cos = std::cos(std::atan(run_.config.friction));
      in.completed_support = [this, margin, floor_cos](size_t i) {
        const TreeLeaf& l = leaves_[i];
        const Eigen::Isometry3d X_OG = toIsometry(l.X_GO).inverse();
        for (const ContactPoint& c : l.contacts) {
          if (run_.scanned() && (onCompletedSurface(run_.completion, X_OG * c.p_W, margin) ||
                                        onOpenRimFacing(run_.completion, X_OG * c.p_W, X_OG.linear() * c.n_W, margin)))
            return SupportKind::kCompleted;
          if (c.n_W.z() < floor_cos && nearOpenEdge(m_.am->open_edges, c.p_W, margin))  // G: z up
            return SupportKind::kAreaBorder;
        }
        return SupportKind::kSeen;
      };
    }
    {
      // Drop-offs within the object's size from its centre of mass (drop_margin.h).
      DropMarginParams dp;
      dp.reach = props.bounding_radius;
      dp.drop = dp.wall = noticeableStep(props);
      in.drop_margin = [this, dp](size_t i) {
        const TreeLeaf& l = leaves_[i];
        double low = kInf;
        for (const ContactPoint& c : l.contacts) low = std::min(low, c.p_W.z());
        if (!std::isfinite(low)) return 1.0;
        return dropMargin(m_.am->grid, toEigen(apply(l.X_GO, ctx_.om.com)), low, dp);
      };
    }
    const PlaceabilityContext pc{m_.om, *m_.am, *m_.backend, m_.d_vis, config};
    run_.result.candidates = rankCandidates(
        in, config, [&](const std::vector<size_t>& idx) { return monitor_.robustnessOf(idx); }, &run_.st(),
        [&](size_t i) { return checkPlacement(leaves_[i], pc, roots_.hanging(leaves_[i].root)); });
    if (config.has_grasp && config.gripper && run_.result.stableCount() == 0 && run_.st().gripper_rejected > 0)
      run_.result.warnings.push_back("the gripper blocks every stable pose checked (" +
                                     std::to_string(run_.st().gripper_rejected) +
                                     " candidates): at the goal, on the approach or the retreat");
  }

 private:
  // Robust stability of leaves (robustness.cpp), within what is left of the budget.
  std::vector<Robustness> robustness(const std::vector<size_t>& idx) {
    const auto tr = Clock::now();
    std::vector<Rigid> X;
    std::vector<Eigen::Vector3d> supports;  // hanging leaves: the middle of their contacts above the centre of mass
    std::vector<PegLine> pegs;
    for (size_t i : idx) {
      const TreeLeaf& l = leaves_[i];
      X.push_back(l.X_GO);
      pegs.push_back(l.peg);
      pegs.back().swing_first = false;  // released at its rest
      Eigen::Vector3d c = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
      if (l.hanging && !l.contacts.empty()) {
        // The peg's contacts, not a wall's it leans on below (stability.cpp).
        const double com_z = apply(l.X_GO, ctx_.om.com).z;
        int n = 0;
        c.setZero();
        for (const ContactPoint& p : l.contacts)
          if (p.p_W.z() > com_z) c += p.p_W, ++n;
        c /= static_cast<double>(std::max(n, 1));
      }
      supports.push_back(c);
    }
    auto out = checkRobustness(X, ctx_, rp_, [this] { return monitor_.keepGoing(run_.budget); }, supports, pegs);
    run_.st().robustness_ms += msSince(tr);
    return out;
  }

  PlanRun& run_;
  const Models& m_;
  const RootSearch roots_;
  const TreeContext ctx_;
  const RobustnessParams rp_;
  std::vector<TreeLeaf> leaves_;
  int rolls_not_held_ = 0;
  SearchMonitor monitor_;
};

// A candidate moved by D_W (frame W, applied on the left) with its path, its pre-place pose and
// the gripper's pose.
void moveCandidate(Candidate& c, const Eigen::Isometry3d& D_W, const PlannerConfig& config) {
  c.X_WO = D_W * c.X_WO;
  for (Eigen::Isometry3d& X : c.intermediate_poses) X = D_W * X;
  c.placement.pre_place_W = D_W * c.placement.pre_place_W;
  if (c.has_gripper_pose) c.X_WF = c.X_WO * config.grasp;
}

// A returned hanging pose moved out of the area, `gap` beyond it (penetration.h,
// clearedPose), with its path and pre-place pose (its contacts stay where it touches, where
// it swings back to when let go): the guard lets it lie up to a contact distance inside a wall
// it swung against, where a robot's release collides (MuJoCo threw such a mug off a J-hook;
// doc/method.md, "The returned pose is clear of the area"). Where no shift clears it, a turn of
// up to 4 degrees about its support first; one that neither clears within 3 sphere radii is
// not stable.
void clearOfTheArea(const Models& m, const PlannerConfig& config, double gap, std::vector<Candidate>& candidates) {
  Eigen::Isometry3d X_GW = Eigen::Isometry3d::Identity();
  X_GW.linear() = m.am->R_GW;
  const double max_shift = 3.0 * m.rad.r + 2 * gap;
  for (Candidate& c : candidates) {
    if (!c.hanging || c.contacts.empty()) continue;
    const Eigen::Isometry3d X_GO = X_GW * c.X_WO;
    // Turned, where it must be, about its support: the highest contact.
    Eigen::Vector3d pivot = X_GW * c.contacts.front().p_W;
    for (const ContactPoint& p : c.contacts)
      if ((X_GW * p.p_W).z() > pivot.z()) pivot = X_GW * p.p_W;
    const std::optional<Rigid> Y = clearedPose(m.om, *m.am, toRigid(X_GO), toV3(pivot), gap, max_shift);
    if (!Y) {
      c.stable = false;
      continue;
    }
    // The move, applied to the pose, its path and its pre-place pose (frame W).
    const Eigen::Isometry3d D_W = X_GW.inverse() * toIsometry(*Y) * X_GO.inverse() * X_GW;
    moveCandidate(c, D_W, config);
  }
  std::stable_partition(candidates.begin(), candidates.end(), [](const Candidate& c) { return c.stable; });
}

// A candidate's contact points and normals in the gravity frame G.
void contactsInG(const Candidate& c, const Eigen::Isometry3d& X_GW, std::vector<Eigen::Vector3d>& p,
                 std::vector<Eigen::Vector3d>& n) {
  p.clear();
  n.clear();
  for (const ContactPoint& k : c.contacts) {
    p.push_back(X_GW * k.p_W);
    n.push_back(X_GW.linear() * k.n_W);
  }
}

// The release pose of each stable standing candidate levelled on its support where the scan's
// noise tilted it (manipulation/level_release.h), with its path and pre-place pose; then moved
// out of the area where the turn took part of it in (clearingShift), or left as it was.
void levelOnTheSupport(const Models& m, const Mesh& object_O, const PlannerConfig& config, bool scanned,
                       bool open, std::vector<Candidate>& candidates) {
  const LevelReleaseParams lp = levelReleaseParams(config.scan_noise, scanned, open);
  if (lp.band <= 0) return;
  LevelReleaseParams walls_only = lp;
  walls_only.walls_only = true;
  Eigen::Isometry3d X_GW = Eigen::Isometry3d::Identity();
  X_GW.linear() = m.am->R_GW;
  std::vector<Eigen::Vector3d> p, n;
  for (Candidate& c : candidates) {
    if (c.hanging || !c.stable) continue;
    // On a cap the face is the completion's guess, and at the area scan's border the area under
    // it is partly unseen: only the seen walls square it (the cap's own lift follows, below).
    if (c.support != SupportKind::kSeen && !lp.square_to_walls) continue;
    const Eigen::Isometry3d X_GO = X_GW * c.X_WO;
    contactsInG(c, X_GW, p, n);
    const std::optional<Eigen::Isometry3d> turn =
        levelingTurn(object_O, X_GO, p, n, c.support == SupportKind::kSeen ? lp : walls_only, m.am.get());
    if (!turn) continue;
    Rigid Y = toRigid(*turn * X_GO);
    const std::optional<V3> out = clearingShift(m.om, *m.am, Y, kResultClearance, lp.band);
    if (!out) continue;
    Y.t = Y.t + *out;
    const Eigen::Isometry3d D_W = X_GW.inverse() * toIsometry(Y) * X_GO.inverse() * X_GW;
    moveCandidate(c, D_W, config);
  }
}

// A scanned object's stable standing poses on seen surface that rest on a curved face of the
// scan (a can or a bottle on its side, a rounded rim) marked, and ranked after those on a flat
// face: where on a curved face the true object comes to rest is finer than the scan (Bullet
// rolled the held-out can, planned lying on its in-hand scan, by 18 degrees), while a flat face
// holds whatever the scan's noise (doc/method.md, "Curved supports after flat ones").
//
// And beyond a cap (unseen is not empty there either): the part a scan never saw may reach past
// its cap, so a pose whose cap faces a wall of the area within the cap's own size (at least
// scan_unseen_reach) may put that part into it. Rays along the cap's outward normal turned
// horizontal (G), from its middle and from points 0.8 of the way to its rim, lifted 1 mm against
// gravity: the floor the object rests on is no wall. A cap facing more up or down than sideways
// is not tested (down: it carries the object, onCompletedSurface's; up: open space). A hit marks
// the pose, ranked after the other seen ones. (The held-out hexagonal prism seen in the hand, its
// hidden end 3 cm from the bin's wall: its true end reaches 2.3 cm past the cap, and Bullet
// pushed it 2 cm back.)
bool capFacesTheArea(const Completion& completion, const AreaModel& am, const Eigen::Isometry3d& X_GO, double reach_min) {
  const BvhView tris = view(am.triangle_bvh);
  for (const CompletionCap& cap : completion.caps) {
    double radius = 0;
    for (const Eigen::Vector3d& q : cap.loop) radius = std::max(radius, (q - cap.centroid).norm());
    const double reach = std::max(reach_min, radius);
    Eigen::Vector3d out = X_GO.linear() * cap.normal;
    out.z() = 0;
    if (out.norm() < std::sqrt(0.5)) continue;  // facing more up or down than sideways
    const V3 d = toV3(out.normalized());
    std::vector<Eigen::Vector3d> from{cap.centroid};
    const size_t step = std::max<size_t>(1, cap.loop.size() / 16);
    for (size_t i = 0; i < cap.loop.size(); i += step) from.push_back(cap.centroid + 0.8 * (cap.loop[i] - cap.centroid));
    for (const Eigen::Vector3d& q : from) {
      const V3 o = toV3(X_GO * q) + v3(0, 0, 0.001);
      const double t = bvhRay(tris, o, d, reach, [&](int k) {
        const auto& tri = am.triangles[k];
        return rayTriangle(o, d, am.vertices[tri[0]], am.vertices[tri[1]], am.vertices[tri[2]]);
      });
      if (t < reach) return true;
    }
  }
  return false;
}

void curvedSupportsLast(const Mesh& object_O, const Completion& completion, const AreaModel& am,
                        const PlannerConfig& config, std::vector<Candidate>& candidates) {
  const LevelReleaseParams lp = levelReleaseParams(config.scan_noise, true);  // the support face as levelOnTheSupport takes it
  if (lp.band <= 0) return;
  Eigen::Isometry3d X_GW = Eigen::Isometry3d::Identity();
  X_GW.linear() = am.R_GW;
  std::vector<Eigen::Vector3d> p, n;
  std::vector<int> group(candidates.size(), 0);
  for (size_t i = 0; i < candidates.size(); ++i) {
    Candidate& c = candidates[i];
    if (!c.stable) {
      group[i] = 4;
      continue;
    }
    if (c.support != SupportKind::kSeen) {
      group[i] = 3;
      continue;
    }
    if (c.hanging) continue;
    contactsInG(c, X_GW, p, n);
    c.curved_support = restsOnCurvedFace(object_O, X_GW * c.X_WO, p, n, lp);
    group[i] = c.curved_support ? 1 : 0;
    if (completion.completed() && capFacesTheArea(completion, am, X_GW * c.X_WO, config.scan_unseen_reach)) group[i] = 2;
  }
  // Stable on a flat seen face; on a curved one; with a cap facing the area; stable on unseen
  // surface; the rest.
  std::vector<size_t> order(candidates.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return group[a] < group[b]; });
  std::vector<Candidate> sorted;
  sorted.reserve(candidates.size());
  for (size_t i : order) sorted.push_back(std::move(candidates[i]));
  candidates.swap(sorted);
}

}  // namespace

Planner::Planner() : cache_(std::make_shared<AreaModelCache>()) {}

void Planner::clearAreaCache() const { cache_->clear(); }

PlanResult Planner::plan(const Mesh& object_in, const Mesh& area, const PlannerConfig& config,
                         const ProgressCallback& progress) const {
  validate(config);
  if (object_in.empty()) throw std::invalid_argument("object mesh is empty");
  if (area.empty()) throw std::invalid_argument("placement area mesh is empty");
  // A closed object wound inwards is wound outwards (model/winding.h: its sphere model's normals
  // tell its outside; an open scan has no inside to judge it by and is kept as given), once for
  // both plans below. The area is wound outwards with its model (buildAreaModel), by gravity.
  const bool inwards = woundInwards(object_in, Eigen::Vector3d::Zero());
  const Mesh reversed = inwards ? reversedWinding(object_in) : Mesh();
  const Mesh& object = inwards ? reversed : object_in;
  auto said = [inwards](PlanResult res) {
    if (inwards)
      res.warnings.insert(res.warnings.begin(), "object mesh: wound inwards (its normals point into the solid); "
                                                "planned wound outwards (model/winding.h)");
    return res;
  };
  bool closed = false;
  PlanResult r = planOnce(object, area, config, progress, &closed);
  // A closed mesh planned as a scan (closed_scan) with no pose that holds within its noise, where
  // some pose held by statics (a rod whose roll valley is finer than scan_noise: its rolls, or
  // trials of the centre of mass moved by the noise): planned again as exact, and said so. With
  // nothing held even by statics (a ramp steeper than the friction angle) it is not.
  const bool noise_turned_down = r.stats.roll_bottoms > 0 || r.stats.robustness_checked > 0;
  if (!config.closed_scan || !closed || r.outcome() != PlanOutcome::kNoStable || !noise_turned_down) return said(std::move(r));
  PlannerConfig exact = config;
  exact.closed_scan = false;
  if (exact.time_budget_ms > 0) exact.time_budget_ms = std::max(1.0, exact.time_budget_ms - r.stats.total_ms);
  PlanResult again = planOnce(object, area, exact, progress, &closed);
  again.stats.total_ms += r.stats.total_ms;  // both plans' time, from the call
  if (again.stats.first_stable_ms >= 0) again.stats.first_stable_ms += r.stats.total_ms;
  char noise[32];
  std::snprintf(noise, sizeof noise, "%.1f mm", 1e3 * config.scan_noise);
  again.warnings.push_back(std::string("no pose of the closed object mesh holds within scan_noise (") + noise +
                           "): planned again as an exact mesh, so its poses trust the mesh's shape finer than a scan's noise (closed_scan)");
  return said(std::move(again));
}

PlanResult Planner::planOnce(const Mesh& object, const Mesh& area, const PlannerConfig& config,
                             const ProgressCallback& progress, bool* closed) const {
  // Unseen is not empty: open regions of a scanned object capped (model/completion.h), after
  // its noise spikes are flattened (model/despike.h; an open mesh is a scan).
  int spikes = 0;
  Mesh scan;  // outlives the completion, which refers to it when it was despiked
  Completion completion = completeOpenRegions(object);
  *closed = !completion.completed();
  if (completion.completed() || config.closed_scan) {
    scan = despiked(object, config.scan_noise, &spikes);
    if (spikes > 0) completion = completeOpenRegions(scan);
  }
  PlanRun run(completion, area, config, progress);
  run.result.stats.spikes_flattened = spikes;
  // ---- models (III, V-B)
  const size_t warnings = run.result.warnings.size();
  std::optional<Models> models = buildModels(run, *cache_);
  if (!models) return stopped(run.result, run.t0);
  // A loop whose room round the pegs is under a contact distance (a pan handle's slot on a
  // J-hook's wire) touches the peg on both sides in the sphere models: rebuilt finer for it.
  if (!findObjectLoops(run, *models)) return stopped(run.result, run.t0);
  if (const double r = fineRadius(run, *models); r > 0) {
    // The pegs and loops are the meshes' geometry, found once: on the finer area model the
    // pegs' probes sample other tops (a J-hook's arm rising 15 degrees came out at 13.5, not
    // 20, and a basket threaded on the first no longer threaded).
    std::vector<Loop> loops = std::move(models->loops);
    std::vector<Peg> pegs = std::move(models->pegs);
    run.result.warnings.resize(warnings);  // said again by the second build
    models = buildModels(run, *cache_, r);
    if (!models) return stopped(run.result, run.t0);
    models->loops = std::move(loops);
    models->pegs = std::move(pegs);
  }
  // Where the area has pegs, a hanging pose's guard probes the object's long faces
  // (penetration.h), on the models searched.
  if (!models->pegs.empty()) {
    const auto tp = Clock::now();
    addProbes(models->om, 4.0 * models->rad.r);
    run.st().steps.setup += msSince(tp);
  }
  // ---- floor points (IV-B) and start orientations (IV-A): the roots
  const std::optional<Roots> roots = findRoots(run, *models);
  if (!roots) return stopped(run.result, run.t0);
  // ---- the trees of rotations (V, VI, VII-C) with robust stability, then the ranking
  TreeSearch search(run, *models, *roots);
  search.run();
  search.rank(*roots);
  // A scan's true surface may lie scan_noise beyond it: a scanned object is cleared by that too.
  clearOfTheArea(*models, config, kResultClearance + (completion.completed() ? config.scan_noise : 0.0),
                 run.result.candidates);
  levelOnTheSupport(*models, models->searched(run.object), config, run.scanned(), completion.completed(),
                    run.result.candidates);
  if (run.scanned()) curvedSupportsLast(models->searched(run.object), completion, *models->am, config, run.result.candidates);
  // A scanned object resting on a cap: its unseen part may reach below the cap, so it is
  // released higher by the scan's noise or by how far the unseen may reach, whichever is more
  // (config.h scan_unseen_reach), with its path and pre-place pose. A hanging one is raised by
  // the noise alone: its cap does not carry it, and a pose released higher falls onto its peg.
  const double cap_lift = std::max(config.scan_noise, config.scan_unseen_reach);
  if (completion.completed() && cap_lift > 0) {
    for (Candidate& c : run.result.candidates) {
      if (c.support != SupportKind::kCompleted) continue;
      const Eigen::Vector3d lift = -(c.hanging ? config.scan_noise : cap_lift) * config.gravity.normalized();
      moveCandidate(c, Eigen::Isometry3d(Eigen::Translation3d(lift)), config);
    }
  }
  // The first robust stable pose was found by the ranking (the search's checks were bounded).
  if (run.st().first_stable_ms < 0 && run.result.stableCount() > 0) run.st().first_stable_ms = msSince(run.t0);
  // Nothing stable on a scan where trees ended lying on a roll: why, and what would help. Where a
  // nearly round object comes to rest about its axis is finer than a scan's noise (the marker:
  // valleys 0.2 mm deep under 2 mm of noise; doc/method.md, "Nothing stable on a scan, said why").
  if (run.scanned() && run.result.stableCount() == 0 && search.rollsNotHeld() > 0) {
    char msg[320];
    std::snprintf(msg, sizeof msg,
                  "nothing stable: %d trees ended lying on a roll that does not hold a release within scan_noise "
                  "(%.1f mm): where this object comes to rest about its axis is finer than its scan (a finer scan: "
                  "a smaller scan_noise)",
                  search.rollsNotHeld(), 1e3 * config.scan_noise);
    run.result.warnings.push_back(msg);
  }
  if (run.budget > 0 && msSince(run.t0) > run.budget) run.result.timed_out = true;
  run.st().total_ms = msSince(run.t0);
  return std::move(run.result);
}

}  // namespace place_planner
