// The benchmark suite: per object/area pair, the planner and Bullet in one process —
// planner times, candidates, physics-confirmed precision, coverage and the drop-and-settle
// baseline over the same floor points.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "place_planner/config.h"
#include "place_planner/model/mesh.h"
#include "place_planner/planner.h"
#include "place_planner/validation/physics_validator.h"

namespace place_planner {
namespace validation {

// A mesh source: "builtin:<name>" (scenes::byName) or a path (loadMesh).
Mesh loadSceneMesh(const std::string& source);

struct ScenePair {
  std::string name;    // e.g. "mug_ycb025_1k@table"
  std::string object;  // mesh source: the true object, validated against
  std::string area;    // mesh source: the true area, validated on
  // Scans (../shared/data/scans): planned on these, validated on the true meshes above. Empty:
  // planned on the true meshes.
  std::string object_plan;
  std::string area_plan;
  std::string mode;    // the object scan's mode (all_around, upper, in_hand), "" for meshes
};

// The default list: the YCB objects x areas of ../shared/data (when data_dir is not empty and
// exists) and the built-in objects x built-in areas.
std::vector<ScenePair> defaultPairs(const std::string& data_dir);

// The scan suite: every object scan of DATA/scans/MANIFEST.tsv on the robot-head scan of each
// of `areas` (names of DATA/areas), planned on the scans and validated on the true meshes.
std::vector<ScenePair> scanPairs(const std::string& data_dir, const std::vector<std::string>& areas);

// The hanging suite: objects with a loop (the YCB mug, its three scans, a low-poly mug, a ring,
// a mug with a flat-bar handle) on areas with pegs and nothing else to stand on (built-in
// peg_wall, peg_wall_rising, mug_tree). A scan is planned on and validated on the true mug
// (DATA/objects/mug_ycb025.ply). mode: "mesh" or the scan's mode. Built-ins only without data.
std::vector<ScenePair> hangingPairs(const std::string& data_dir);

struct SuiteConfig {
  PlannerConfig planner;        // threads is set to 1 by default (Bullet is single-threaded)
  ValidatorConfig validator;    // friction is overwritten by planner.friction
  int max_validated = 5;        // stable candidates validated per scene (best ranked first)
  int max_drops = 8;            // floor points dropped per scene (evenly spread); 0 = none
  double hole_fraction = 0.0;   // > 0: plan on a copy with this fraction deleted in patches
  std::uint32_t hole_seed = 1;
  // Where under 5 % of an area faces against planner.gravity (a scan in its camera frame),
  // plan and validate with gravity against the area's largest flat region (area_up.h).
  bool auto_gravity = false;
  // Also check each validated pose in MuJoCo (mujoco_validator.h), the second engine: a pose
  // is then confirmed in both engines when both keep it.
  bool mujoco = false;
  SuiteConfig() { planner.threads = 1; }
};

struct CandidateCheck {
  int rank = 0;
  double quality = 0.0;
  Eigen::Isometry3d X_WO = Eigen::Isometry3d::Identity();
  SupportKind support = SupportKind::kSeen;  // the planner's flag: seen, or unseen surface under it
  PoseCheck check;
  bool mujoco_checked = false;  // SuiteConfig::mujoco
  PoseCheck mujoco;
  bool bothConfirmed() const { return check.confirmed && mujoco_checked && mujoco.confirmed; }
};

struct DropRecord {
  int floor_point = 0;           // index into PlanResult::floor_points_W
  Eigen::Isometry3d X_WO_start = Eigen::Isometry3d::Identity();
  DropResult result;
};

struct SceneResult {
  ScenePair pair;
  std::string variant = "full";  // "full" or "holes_10" etc.
  int object_triangles = 0;      // as planned (after holes)
  int area_triangles = 0;
  PlanStats stats;
  int candidates = 0;
  int stable = 0;                // returned as stable
  int validated = 0;             // stable candidates simulated (<= max_validated)
  int confirmed = 0;             // of those, confirmed by Bullet
  int confirmed_mujoco = 0;      // ... by MuJoCo (SuiteConfig::mujoco)
  int confirmed_both = 0;        // ... by both engines
  std::vector<CandidateCheck> checks;
  std::vector<DropRecord> drops;
  int drops_at_rest = 0;
  int drops_fell = 0;
  double drop_ms_mean = 0.0;     // wall time per drop
  double drop_ms_median = 0.0;
  double planner_ms_per_floor_point = 0.0;  // stats.total_ms / floor_points_total
  double validate_ms = 0.0;      // wall time of all checks of this scene
  std::string error;             // non-empty when the scene could not run (load/plan failed)

  double precision() const { return validated ? double(confirmed) / validated : 0.0; }
  // The best stable pose (the first validated) was confirmed.
  bool bestConfirmed() const { return !checks.empty() && checks.front().check.confirmed; }
  bool bestConfirmedBoth() const { return !checks.empty() && checks.front().bothConfirmed(); }
  // Confirmed among the first k validated (the top-k stable poses).
  int confirmedOfTop(int k, int* validated_top) const {
    int n = 0, c = 0;
    for (const auto& ch : checks)
      if (n < k) {
        ++n;
        c += ch.check.confirmed ? 1 : 0;
      }
    *validated_top = n;
    return c;
  }
  // The same among those of the first k that rest on seen surface (the planner's flag).
  int confirmedSeenOfTop(int k, int* validated_seen) const {
    int n = 0, v = 0, c = 0;
    for (const auto& ch : checks)
      if (n++ < k && ch.support == SupportKind::kSeen) {
        ++v;
        c += ch.check.confirmed ? 1 : 0;
      }
    *validated_seen = v;
    return c;
  }
  int confirmedBothOfTop(int k) const {
    int n = 0, c = 0;
    for (const auto& ch : checks)
      if (n++ < k) c += ch.bothConfirmed() ? 1 : 0;
    return c;
  }
  bool plannerConfirmed() const { return confirmed > 0; }
  bool bulletRests() const { return drops_at_rest > 0; }
  double speedup() const {  // Bullet ms per drop / planner ms per floor point
    return planner_ms_per_floor_point > 0 && !drops.empty()
               ? drop_ms_mean / planner_ms_per_floor_point : 0.0;
  }
};

// Plans, validates the top stable candidates on the full object mesh, and drops the object from
// the pre-placement pose above up to max_drops floor points. Never throws: errors go to .error.
SceneResult runScene(const ScenePair& pair, const SuiteConfig& config);
// Same, with meshes already loaded (object_full is validated against; planned on after holes).
SceneResult runScene(const ScenePair& pair, const Mesh& object_full, const Mesh& area,
                     const SuiteConfig& config);
// Planned on object_plan / area_plan (scans), validated on object_true / area_true.
SceneResult runScene(const ScenePair& pair, const Mesh& object_true, const Mesh& area_true,
                     const Mesh& object_plan, const Mesh& area_plan, const SuiteConfig& config);

struct SuiteSummary {
  int scenes = 0, errors = 0;
  int validated = 0, confirmed = 0;
  double precision = 0.0;          // confirmed / validated over all scenes
  int bullet_rest_scenes = 0;      // scenes where some drop came to rest
  int covered_scenes = 0;          // of those, scenes with a confirmed planner pose
  double coverage = 0.0;           // covered_scenes / bullet_rest_scenes
  int planner_scenes_confirmed = 0;  // scenes with a confirmed pose (any)
  long floor_points = 0;
  double planner_ms_total = 0.0;
  int drops = 0;
  double drop_ms_total = 0.0;
  double planner_ms_per_floor_point = 0.0;
  double drop_ms_per_drop = 0.0;
  double speedup = 0.0;            // drop_ms_per_drop / planner_ms_per_floor_point
  double median_first_stable_ms = -1.0;
  double median_total_ms = 0.0;
};

SuiteSummary summarize(const std::vector<SceneResult>& results);

// One line per scene; one line per validated candidate; one line per drop.
void writeScenesCsv(const std::vector<SceneResult>& results, const std::string& path);
void writeChecksCsv(const std::vector<SceneResult>& results, const std::string& path);
void writeDropsCsv(const std::vector<SceneResult>& results, const std::string& path);
// Markdown: a per-scene table and the summary line.
std::string markdownTable(const std::vector<SceneResult>& results);
std::string markdownSummary(const SuiteSummary& s, const std::string& label);

}  // namespace validation
}  // namespace place_planner
