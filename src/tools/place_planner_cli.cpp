// place_planner_cli: plan placements of an object mesh on an area mesh from the shell.
// Arguments by CLI11, the JSON answer by nlohmann::json, written by the project's output-file
// rules (infra/output_file.h): a regular file is replaced atomically, a device or FIFO is written
// in place, a symlink's target is replaced, "-" is standard output.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "place_planner/model/area_up.h"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/manipulation/gripper.h"
#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/output_file.h"
#include "place_planner/planner.h"
#include "place_planner/infra/scenes.h"
#ifdef PLACE_PLANNER_HAVE_VALIDATION
#include "place_planner/validation/physics_validator.h"
#include "place_planner/validation/plot.h"
#endif

using namespace place_planner;
using Json = nlohmann::ordered_json;  // keys in the order written, as a reader expects them

namespace {

// Exit codes (doc/cli.md; also in --help).
constexpr int kExitStable = 0;       // stable candidates (search complete, or a partial answer)
constexpr int kExitNoStable = 1;     // search complete, nothing stable
constexpr int kExitBadInput = 2;     // bad option, value out of range, unreadable mesh, unwritable --json
constexpr int kExitTimedOut = 3;     // budget ran out before anything stable
constexpr int kExitOutputError = 4;  // planned, but writing --json failed (disk full, I/O error)

const char* kFooter =
    "Meshes: .ply (ASCII or binary), .obj, .stl, or builtin:NAME (table, dish_rack, open_box,\n"
    "binder_stack, mug, plate, pen, cube).\n"
    "--gravity auto: against the normal of the area's largest flat region (a scan in its camera\n"
    "frame). --backend gpu is the same as cuda: an error (exit 2) when no CUDA device is usable;\n"
    "auto plans on CUDA where a GPU answers, else on the CPU.\n"
    "--verify K: simulate the best K stable candidates in Bullet (released 2 mm above the pose;\n"
    "stayed = moved < 1 cm, turned < 5 deg) within what is left of --budget-ms; one that falls is\n"
    "moved behind the other stable candidates. --verify-engines both: the same check in MuJoCo too\n"
    "(about a second more per candidate); a candidate stayed when both engines kept it.\n"
    "--json OUT: a regular file is replaced atomically (a temporary file beside it, then\n"
    "rename); a device, FIFO or socket (/dev/null, a named pipe) is written in place; a symlink's\n"
    "target is replaced; --json - writes the JSON to stdout and the report to stderr.\n"
    "\n"
    "The last line of the report is always 'outcome: ...' (stdout; stderr with --json -).\n"
    "Exit codes:\n"
    "  0  stable candidates found (outcome stable, or timed_out_partial: a partial answer)\n"
    "  1  the search completed and nothing is stable (no_stable_pose)\n"
    "  2  bad input: unknown or malformed option, value out of range, unreadable mesh, --json\n"
    "     not writable, CUDA requested but unavailable (bad_input; one error line on stderr)\n"
    "  3  the budget ran out before anything stable was found (timed_out)\n"
    "  4  planned, but the --json file could not be written (output_error)\n";

// An error that is the input's fault (exit 2), or the output's (exit 4).
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Doubles must be finite: CLI11 would accept "nan" and "inf".
const CLI::Validator kFinite(
    [](std::string& s) -> std::string {
      double v = 0;
      if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
      return std::isfinite(v) ? std::string() : "'" + s + "' is not a finite number";
    },
    "FINITE");

// "x,y,z", each element converted by CLI11's own number conversion.
Eigen::Vector3d parseVector(const std::string& flag, const std::string& s) {
  const std::vector<std::string> parts = CLI::detail::split(s, ',');
  Eigen::Vector3d v;
  bool ok = parts.size() == 3;
  for (size_t i = 0; ok && i < 3; ++i) ok = CLI::detail::lexical_cast(parts[i], v[i]) && std::isfinite(v[i]);
  if (!ok) throw CLI::ValidationError(flag, "expects x,y,z: three finite numbers (got '" + s + "')");
  return v;
}

// "x,y,z,qx,qy,qz,qw": the pose of the gripper frame F in the object frame O.
Eigen::Isometry3d parsePose(const std::string& flag, const std::string& s) {
  const std::vector<std::string> parts = CLI::detail::split(s, ',');
  double v[7] = {0, 0, 0, 0, 0, 0, 0};
  bool ok = parts.size() == 7;
  for (size_t i = 0; ok && i < 7; ++i) ok = CLI::detail::lexical_cast(parts[i], v[i]) && std::isfinite(v[i]);
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (!ok || std::abs(q.norm() - 1.0) > 1e-3)
    throw CLI::ValidationError(flag, "expects x,y,z,qx,qy,qz,qw with a unit quaternion (got '" + s + "')");
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q.normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return X;
}

// validate() names the config field; the user typed a flag: name both.
const std::map<std::string, std::string> kFlagOfField = {
    {"gravity", "--gravity"},
    {"approach", "--approach"},
    {"friction", "--friction"},
    {"floor_point_spacing", "--spacing"},
    {"max_rotations", "--max-rotations"},
    {"max_resting_faces", "--max-resting-faces"},
    {"robust_shift", "--robust-shift"},
    {"robust_tilt_deg", "--robust-tilt-deg"},
    {"robust_com_offset", "--robust-com-offset"},
    {"robust_min_share", "--robust-min-share"},
    {"robust_min_share_hanging", "--robust-min-share-hanging"},
    {"time_budget_ms", "--budget-ms"},
    {"max_candidates", "--max-candidates"},
    {"threads", "--threads"},
    {"max_triangles", "--max-triangles"},
    {"max_floor_points", "--max-floor-points"},
    {"max_tree_nodes", "--max-tree-nodes"},
    {"max_model_mb", "--max-model-mb"},
    {"max_object_size", "--max-object-size"},
    {"max_area_size", "--max-area-size"},
    {"max_gripper_tilt_deg", "--max-gripper-tilt-deg"},
    {"gripper_min_clearance", "--gripper-min-clearance"},
    {"approach_distance", "--approach-distance"},
    {"approach_min_distance", "--approach-min-distance"},
    {"retreat_distance", "--retreat-distance"},
    {"retreat_min_distance", "--retreat-min-distance"},
    {"min_edge_clearance", "--min-edge-clearance"},
    {"scan_noise", "--scan-noise"},
    {"scan_unseen_reach", "--scan-unseen-reach"},
    {"prefer_near", "--prefer-near"},
    {"grasp", "--grasp"},
};

void validateNamingFlags(const PlannerConfig& c) {
  try {
    validate(c);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    const auto it = kFlagOfField.find(what.substr(0, what.find(' ')));
    throw InputError(it == kFlagOfField.end() ? what : it->second + ": " + what);
  }
}

Mesh load(const std::string& flag, const std::string& spec) {
  try {
    if (spec.rfind("builtin:", 0) == 0) return scenes::byName(spec.substr(8));
    return loadMesh(spec);
  } catch (const std::invalid_argument& e) {
    throw InputError(flag + ": " + e.what());
  }
}

std::string errnoText(const std::string& what, const std::string& path) {
  return what + " " + path + ": " + std::strerror(errno);
}

// Progress on standard error while a plan runs longer than a second, when it is a terminal
// (as the node's action feedback): floor points done, stable poses so far. One line, redrawn.
class ProgressLine {
 public:
  ProgressLine() : enabled_(isatty(STDERR_FILENO) == 1) {}
  ~ProgressLine() { finish(); }

  bool operator()(const Progress& p) {
    if (!enabled_ || p.elapsed_ms < 1000.0) return true;
    const auto now = std::chrono::steady_clock::now();
    if (shown_ && now - last_ < std::chrono::milliseconds(200)) return true;
    last_ = now;
    shown_ = true;
    std::string done;
    if (p.floor_points_total > 0) done = "floor points " + std::to_string(p.floor_points_done) + " of " + std::to_string(p.floor_points_total);
    if (p.hanging_starts_total > 0)
      done += (done.empty() ? "" : ", ") + std::string("threaded starts ") + std::to_string(p.hanging_starts_done) + " of " +
              std::to_string(p.hanging_starts_total);
    std::fprintf(stderr, "\rplanning: %s, %d stable so far, %.1f s\033[K", done.c_str(), p.candidates, p.elapsed_ms / 1000.0);
    std::fflush(stderr);
    return true;
  }

  // Clears the line before the report is printed.
  void finish() {
    if (!shown_) return;
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    shown_ = false;
  }

 private:
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_;
};

Json vecJson(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }
Json quatJson(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return Json::array({q.x(), q.y(), q.z(), q.w()});
}

// The candidate's placement (placeability.h): the PlaceLocation-shaped fields.
Json placementJson(const Candidate& k) {
  const Placement& p = k.placement;
  auto motion = [](const LinearMotion& m) {
    return Json{{"direction", vecJson(m.direction)},
                {"min_distance", m.min_distance},
                {"desired_distance", m.desired_distance},
                {"free_distance", m.free_distance}};
  };
  Json j{{"checked", p.checked},
         {"pre_place",
          {{"position", vecJson(p.pre_place_W.translation())}, {"orientation_xyzw", quatJson(p.pre_place_W.linear())}}},
         {"straight_approach", p.straight},
         {"approach", motion(p.approach)},
         {"retreat_in_gripper_frame", motion(p.retreat)},
         {"gripper_clearance", p.gripper_clearance},
         {"blocked", p.blocked}};
  if (k.has_gripper_pose)
    j["gripper_pose"] = {{"position", vecJson(k.X_WF.translation())}, {"orientation_xyzw", quatJson(k.X_WF.linear())}};
  return j;
}

Json resultJson(const std::string& object, const std::string& area, const PlannerConfig& c,
                const PlanResult& r) {
  const auto& st = r.stats;
  Json j;
  j["object"] = object;
  j["area"] = area;
  j["outcome"] = toString(r.outcome());
  j["stable_candidates"] = r.stableCount();
  j["planning_ms"] = st.total_ms;
  j["first_stable_ms"] = st.first_stable_ms;
  j["floor_points"] = st.floor_points_total;
  j["floor_points_done"] = st.floor_points_done;
  j["hanging_starts"] = st.hanging_starts;
  j["hanging_starts_done"] = st.hanging_starts_done;
  j["tree_nodes"] = st.tree_nodes;
  j["trees_without_rest"] = st.trees_without_rest;  // cut by max_rotations while still tilting
  j["spikes_flattened"] = st.spikes_flattened;      // noise spikes of a scanned object flattened
  j["roll_bottoms"] = st.roll_bottoms;              // leaves at the bottom of a roll
  j["trees_fallen"] = st.trees_fallen;              // cut while falling over a ledge
  j["backend"] = st.backend;
  j["gravity"] = vecJson(c.gravity);
  j["warnings"] = r.warnings;
  j["gripper_rejected"] = st.gripper_rejected;
  j["gripper_tilt_rejected"] = st.gripper_tilt_rejected;
  j["unseen_withheld"] = st.unseen_withheld;  // stable on unseen surface, not offered: a seen pose holds
  Json candidates = Json::array();
  for (const auto& k : r.candidates) {
    Json contacts = Json::array();
    for (const auto& p : k.contacts) contacts.push_back({{"p", vecJson(p.p_W)}, {"n", vecJson(p.n_W)}});
    Json poses = Json::array();
    for (const auto& X : k.intermediate_poses)
      poses.push_back({{"position", vecJson(X.translation())}, {"orientation_xyzw", quatJson(X.linear())}});
    candidates.push_back({
        {"position", vecJson(k.X_WO.translation())},
        {"orientation_xyzw", quatJson(k.X_WO.linear())},
        {"quality", k.quality},
        {"stable", k.stable},
        {"support", toString(k.support)},
        {"curved_support", k.curved_support},
        {"push_resistance",
         {{"min", k.push_resistance}, {"mean", k.push_resistance_mean}, {"weakest_direction", vecJson(k.push_weakest_W)}}},
        {"drop_margin", k.drop_margin},
        {"start", toString(k.start)},
        {"kind", k.hanging ? "hanging" : "standing"},
        {"robustness",
         {{"trials", k.robustness.trials},
          {"held", k.robustness.held},
          {"share", k.robustness.share()},
          {"min_tipping_angle", k.robustness.min_tipping_angle}}},
        {"physics",
         {{"checked", k.physics.checked},
          {"stayed", k.physics.stayed},
          {"moved_m", k.physics.moved_m},
          {"turned_deg", k.physics.turned_deg},
          {"planner_rank", k.physics.planner_rank},
          {"bullet", {{"checked", k.physics.bullet_checked}, {"stayed", k.physics.bullet_stayed}}},
          {"mujoco",
           {{"checked", k.physics.mujoco_checked},
            {"stayed", k.physics.mujoco_stayed},
            {"moved_m", k.physics.mujoco_moved_m},
            {"turned_deg", k.physics.mujoco_turned_deg}}}}},
        {"floor_point", vecJson(k.floor_point_W)},
        {"contacts", contacts},
        {"intermediate_poses", poses},
        {"placement", placementJson(k)},
    });
  }
  j["candidates"] = candidates;
  return j;
}

int exitCode(PlanOutcome o) {
  switch (o) {
    case PlanOutcome::kStable:
    case PlanOutcome::kTimedOutWithStable: return kExitStable;
    case PlanOutcome::kNoStable: return kExitNoStable;
    case PlanOutcome::kTimedOutNone:
    case PlanOutcome::kCancelled: return kExitTimedOut;  // the CLI never cancels
  }
  return kExitTimedOut;
}

std::string physicsCell(const PhysicsCheck& p) { return p.checked ? (p.stayed ? "yes" : "no") : "-"; }

std::string robustnessCell(const Robustness& r) {
  if (r.trials == 0) return "-";
  return std::to_string(r.held) + "/" + std::to_string(r.trials);
}

void printReport(const std::string& object_spec, const Mesh& object, const std::string& area_spec,
                 const Mesh& area, const PlannerConfig& c, const PlanResult& r) {
  const auto& st = r.stats;
  std::printf("object %s (%zu triangles), area %s (%zu triangles), orientation %s\n", object_spec.c_str(),
              object.triangles.size(), area_spec.c_str(), area.triangles.size(), toString(c.orientation).c_str());
  // The times block names the backend once: the CPU is the normal case for `auto`, not a warning.
  // With placement hanging the floor points are found (the answer lists them) but not searched.
  if (st.start_orientations > 0)
    std::printf("floor points %d of %d, ", st.floor_points_done, st.floor_points_total);
  else
    std::printf("floor points not searched (no start orientation), ");
  std::printf("tree nodes %ld, planning %.1f ms, first stable %.1f ms, %s backend\n", st.tree_nodes, st.total_ms,
              st.first_stable_ms, st.backend == "cuda" ? "CUDA" : "CPU");
  if (st.pegs > 0)
    std::printf("hanging: %d pegs on the area, %d loops of the object, %d threaded starts (%d searched)\n", st.pegs,
                st.loops, st.hanging_starts, st.hanging_starts_done);
  if (st.trees_without_rest > 0 || st.roll_bottoms > 0 || st.trees_fallen > 0)
    std::printf("trees: %d cut by max_rotations while still tilting, %d ended at the bottom of a roll, "
                "%d cut while falling over a ledge\n",
                st.trees_without_rest, st.roll_bottoms, st.trees_fallen);
  if (st.unseen_withheld > 0)
    std::printf("support: %d statically stable poses on surface the scans never saw not offered (a pose on seen surface holds)\n",
                st.unseen_withheld);
  std::printf("steps [ms]: setup %.1f, floor points %.1f, distance %.1f, contacts %.1f, vertex/surface %.1f, "
              "edge/edge %.1f, stability %.1f, local optimisation %.1f, robustness %.1f\n",
              st.steps.setup, st.steps.floor_points, st.steps.first_contact, st.steps.contact_points,
              st.steps.tilt_vertex, st.steps.tilt_edge, st.steps.stability, st.steps.local_optimisation,
              st.robustness_ms);
}

void printTable(const PlanResult& r) {
  std::printf("%4s %7s %6s %6s %7s %-14s %-8s %26s %32s %8s\n", "rank", "quality", "stable", "robust",
              "physics", "start", "kind", "position [m]", "orientation xyzw", "contacts");
  for (size_t i = 0; i < r.candidates.size(); ++i) {
    const auto& k = r.candidates[i];
    const Eigen::Quaterniond q(k.X_WO.linear());
    const Eigen::Vector3d p = k.X_WO.translation();
    std::printf("%4zu %7.3f %6s %6s %7s %-14s %-8s (%7.3f %7.3f %7.3f) (%6.3f %6.3f %6.3f %6.3f) %8zu\n", i + 1,
                k.quality, k.stable ? "yes" : "no", robustnessCell(k.robustness).c_str(),
                physicsCell(k.physics).c_str(), toString(k.start), k.hanging ? "hanging" : "standing", p.x(), p.y(), p.z(), q.x(), q.y(), q.z(),
                q.w(), k.contacts.size());
  }
}

// The answer in one line, always last on stdout (scripts read it with tail -1).
void printOutcome(const PlannerConfig& c, const PlanResult& r) {
  const auto& st = r.stats;
  const int n_stable = r.stableCount();
  const PlanOutcome outcome = r.outcome();
  switch (outcome) {
    case PlanOutcome::kStable:
      std::printf("outcome: stable (%d stable candidate%s)\n", n_stable, n_stable == 1 ? "" : "s");
      break;
    case PlanOutcome::kTimedOutWithStable:
      std::printf("partial answer: the time budget of %.1f ms ran out after %s\n", c.time_budget_ms,
                  searchedRoots(st).c_str());
      std::printf("outcome: timed_out_partial (%d stable candidate%s so far)\n", n_stable,
                  n_stable == 1 ? "" : "s");
      break;
    case PlanOutcome::kNoStable:
      std::printf("outcome: no_stable_pose (%zu candidates, none stable, %s searched)\n", r.candidates.size(),
                  searchedRoots(st).c_str());
      break;
    case PlanOutcome::kTimedOutNone:
    case PlanOutcome::kCancelled:
      std::printf("outcome: %s (nothing stable in %s within %.1f ms)\n", toString(outcome), searchedRoots(st).c_str(),
                  c.time_budget_ms);
      break;
  }
}

// The JSON answer by the output-file rules, or to `json_fd` (standard output) for "-".
// Throws OutputError (exit 4).
void writeJson(const std::string& path, int json_fd, const std::string& text) {
  try {
    if (json_fd >= 0) return writeOutputFd(json_fd, text, "standard output");
    writeOutputFile(path, text);
  } catch (const std::runtime_error& e) {
    throw OutputError(e.what());
  }
}

int fail(int code, const std::string& outcome, const std::string& what) {
  std::fflush(stdout);
  std::fprintf(stderr, "place_planner_cli: error: %s\n", what.c_str());
  std::printf("outcome: %s\n", outcome.c_str());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Plans stable placements of an object mesh on a placement area mesh.",
               "place_planner_cli"};
  app.footer(kFooter);
  app.get_formatter()->column_width(34);

  PlannerConfig c;
  std::string object_spec, area_spec, json_path;
  int json_fd = -1;  // --json -: the original standard output
  bool auto_gravity = false, no_robust_check = false;
  int verify_k = 0;
  std::string picture_path;

  app.add_option("--object", object_spec, "object mesh (its own frame O): file or builtin:NAME")
      ->required();
  app.add_option("--area", area_spec, "placement area mesh (the planning frame W)")->required();
  app.add_option_function<std::string>(
         "--gravity",
         [&](const std::string& s) {
           auto_gravity = s == "auto";
           if (!auto_gravity) c.gravity = parseVector("--gravity", s);
         },
         "gravity direction d_g, or auto (default 0,0,-1)")
      ->type_name("x,y,z|auto");
  app.add_option_function<std::string>(
         "--approach", [&](const std::string& s) { c.approach = parseVector("--approach", s); },
         "approach direction d_vis (default: along gravity)")
      ->type_name("x,y,z");
  app.add_option("--friction", c.friction, "friction coefficient mu")->check(kFinite)->capture_default_str();
  app.add_option("--spacing", c.floor_point_spacing, "floor point spacing [m]")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--max-rotations", c.max_rotations, "depth of the rotation tree")->capture_default_str();
  app.add_option_function<std::string>(
         "--orientation",
         [&](const std::string& s) {
           try {
             c.orientation = orientationModeFromString(s);
           } catch (const std::invalid_argument& e) {
             throw CLI::ValidationError("--orientation", e.what());
           }
         },
         "start orientations: auto | principal_axis | keep | all_axes (default auto)")
      ->type_name("MODE");
  app.add_option("--max-resting-faces", c.max_resting_faces, "auto: resting faces tried")->capture_default_str();
  app.add_option("--robust-shift", c.robust_shift, "robustness: release offset [m]")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--robust-tilt-deg", c.robust_tilt_deg, "robustness: release tilt [deg]")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--robust-com-offset", c.robust_com_offset, "robustness: centre of mass offset (share of size)")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--robust-min-share", c.robust_min_share, "robustness: share of releases that must hold")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--robust-min-share-hanging", c.robust_min_share_hanging,
                 "robustness: share of a hanging pose's releases that must hold")
      ->check(kFinite)
      ->capture_default_str();
  app.add_flag("--no-robust-check", no_robust_check, "static stability only (the paper)");
  app.add_flag("--robust-recheck-caught,!--no-robust-recheck-caught", c.robust_recheck_caught,
               "robustness: tilted releases caught where they land hold if that pose holds (default on; peg tops, cups)");
  app.add_flag("--rock-settle,!--no-rock-settle", c.rock_settle,
               "stable poses rocked to the bottom of their rock (default on; racks, cups, trays)");
  app.add_option("--budget-ms", c.time_budget_ms, "time budget [ms], 0 = none")->check(kFinite)->capture_default_str();
  app.add_option("--max-candidates", c.max_candidates, "candidates returned")->capture_default_str();
  app.add_option("--threads", c.threads, "CPU threads, 0 = all")->capture_default_str();
  // gpu is cuda by another name, never a silent auto: unavailable CUDA is an error.
  const std::map<std::string, BackendKind> backends = {
      {"auto", BackendKind::kAuto}, {"cpu", BackendKind::kCpu}, {"cuda", BackendKind::kCuda}, {"gpu", BackendKind::kCuda}};
  std::string backend_name = "auto";
  app.add_option("--backend", backend_name, "auto: CUDA where a GPU answers, else the CPU; cuda: the GPU or an error; gpu = cuda")
      ->check(CLI::IsMember(backends))
      ->capture_default_str()
      ->type_name("NAME");
  app.add_option("--picture", picture_path,
                 "draw the best candidate in the area with its approach (PNG), seen from the approach's side");
  app.add_option("--verify", verify_k, "physics check of the best K stable candidates, 0 = off")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  std::string engines_name = "bullet";
  app.add_option("--verify-engines", engines_name, "--verify in bullet, mujoco or both (both: a pose stays when both keep it)")
      ->check(CLI::IsMember({"bullet", "mujoco", "both"}))
      ->capture_default_str()
      ->type_name("ENGINES");
  app.add_option("--json", json_path, "write the answer as JSON to this file; - = stdout (the report then goes to stderr)")
      ->type_name("OUT");
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "also say which backend auto chose, and why");
  // Bounded work (doc/reliability.md): the limits of PlannerConfig.
  app.add_option("--max-triangles", c.max_triangles, "per mesh; larger ones are decimated")->capture_default_str();
  app.add_option("--max-floor-points", c.max_floor_points, "rays cast; a finer spacing is coarsened")
      ->capture_default_str();
  app.add_option("--max-tree-nodes", c.max_tree_nodes, "poses evaluated; the search stops there")->capture_default_str();
  app.add_option("--max-model-mb", c.max_model_mb, "estimated model memory [MB]; above: bad input")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--max-object-size", c.max_object_size, "object across [m]; above: bad input (millimetres?)")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--max-area-size", c.max_area_size, "area across [m]; above: bad input")
      ->check(kFinite)
      ->capture_default_str();
  // The budget in seconds, as the node takes it; --budget-ms is the same in milliseconds.
  app.add_option_function<double>(
         "--budget-s", [&](double s) { c.time_budget_ms = 1000.0 * s; }, "time budget [s], 0 = none")
      ->check(kFinite);
  // Manipulation (doc/manipulation.md): the gripper from its URDF, the grasp, the motions.
  std::string urdf_path, gripper_links;
  std::map<std::string, double> joint_positions;
  app.add_option("--urdf", urdf_path, "the robot's URDF (the gripper's collision geometry)")->type_name("FILE");
  app.add_option("--gripper-links", gripper_links, "links riding with the object; the first is F")
      ->type_name("a,b,...");
  app.add_option_function<std::vector<std::string>>(
         "--gripper-joint",
         [&](const std::vector<std::string>& v) {
           for (const std::string& kv : v) {
             const size_t eq = kv.find('=');
             double q = 0;
             if (eq == std::string::npos || !CLI::detail::lexical_cast(kv.substr(eq + 1), q) || !std::isfinite(q))
               throw CLI::ValidationError("--gripper-joint", "expects NAME=VALUE (got '" + kv + "')");
             joint_positions[kv.substr(0, eq)] = q;
           }
         },
         "joint position at release [rad or m], repeatable")
      ->type_name("NAME=VALUE");
  app.add_option_function<std::string>(
         "--grasp",
         [&](const std::string& s) {
           c.grasp = parsePose("--grasp", s);
           c.has_grasp = true;
         },
         "pose of the gripper frame F in the object frame O (F's z: palm to fingertips)")
      ->type_name("x,y,z,qx,qy,qz,qw");
  app.add_flag("--keep-colliding", c.keep_colliding, "keep candidates the gripper blocks, marked");
  app.add_option("--max-gripper-tilt-deg", c.max_gripper_tilt_deg, "F's z at most this far from down")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--gripper-min-clearance", c.gripper_min_clearance, "[m]")->check(kFinite)->capture_default_str();
  app.add_option("--approach-distance", c.approach_distance, "[m]")->check(kFinite)->capture_default_str();
  app.add_option("--approach-min-distance", c.approach_min_distance, "[m]")->check(kFinite)->capture_default_str();
  app.add_option("--retreat-distance", c.retreat_distance, "[m]")->check(kFinite)->capture_default_str();
  app.add_option("--retreat-min-distance", c.retreat_min_distance, "[m]")->check(kFinite)->capture_default_str();
  // Preferences (ranking.h).
  const std::map<std::string, RankOrder> orders = {
      {"quality", RankOrder::kQuality}, {"lowest", RankOrder::kLowest}, {"nearest", RankOrder::kNearest}};
  const std::map<std::string, PlacementKind> kinds = {
      {"any", PlacementKind::kAny}, {"standing", PlacementKind::kStanding}, {"hanging", PlacementKind::kHanging}};
  std::string placement_name = "any";
  app.add_option("--placement", placement_name,
                 "any | standing | hanging (by a loop of the object on a peg of the area)")
      ->check(CLI::IsMember(kinds))
      ->capture_default_str();
  std::string order_name = "quality";
  app.add_option("--rank-order", order_name, "quality | lowest | nearest (to --prefer-near)")
      ->check(CLI::IsMember(orders))
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--prefer-near", [&](const std::string& s) { c.prefer_near = parseVector("--prefer-near", s); },
         "point for --rank-order nearest (planning frame)")
      ->type_name("x,y,z");
  app.add_option("--scan-noise", c.scan_noise,
                 "[m] uncertainty of a scanned surface: a scanned object's hanging pose is cleared of the area by this much more")
      ->check(kFinite)
      ->capture_default_str();
  app.add_option("--scan-unseen-reach", c.scan_unseen_reach,
                 "[m] how far a scan's unseen part may reach past a cap: a pose resting on one is released this much higher")
      ->check(kFinite)
      ->capture_default_str();
  app.add_flag("--closed-scan,!--exact-mesh", c.closed_scan,
               "a closed object mesh is a scan too (fused all around): planned with its noise as an open scan is, "
               "and again as exact where nothing holds within it; --exact-mesh: a closed mesh is exact (a CAD model)")
      ->capture_default_str();
  app.add_option("--min-edge-clearance", c.min_edge_clearance, "[m] from a drop-off of the area, 0 = off")
      ->check(kFinite)
      ->capture_default_str();

  try {
    app.parse(argc, argv);
    // --json -: the JSON keeps standard output; everything else printed goes to standard error.
    if (json_path == "-") {
      std::fflush(stdout);
      json_fd = dup(STDOUT_FILENO);
      if (json_fd < 0 || dup2(STDERR_FILENO, STDOUT_FILENO) < 0) return fail(kExitOutputError, "output_error", "--json -: cannot redirect the report");
    }
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help
    return fail(kExitBadInput, "bad_input", std::string(e.what()) + " (see --help)");
  }

  PlanResult r;
  try {
    if (no_robust_check) c.robust_check = false;
#ifndef PLACE_PLANNER_HAVE_VALIDATION
    if (verify_k > 0) throw InputError("--verify: built without Bullet (no validation library)");
    if (!picture_path.empty()) throw InputError("--picture: built without the validation library (OpenCV)");
#endif
    c.rank_order = orders.at(order_name);
    c.placement = kinds.at(placement_name);
    if (!urdf_path.empty() || !gripper_links.empty()) {
      if (urdf_path.empty() || gripper_links.empty())
        throw InputError("--urdf and --gripper-links go together (the gripper needs both)");
      if (!c.has_grasp) throw InputError("--urdf: the gripper needs --grasp (where it holds the object)");
      try {
        c.gripper = std::make_shared<GripperModel>(
            gripperFromUrdfFile(urdf_path, CLI::detail::split(gripper_links, ','), joint_positions));
      } catch (const std::invalid_argument& e) {
        throw InputError(std::string("--urdf: ") + e.what());
      }
    }
    validateNamingFlags(c);
    c.backend = backends.at(backend_name);
    if (c.backend == BackendKind::kCuda) {
      std::string why;
      if (!cuda::available(&why))
        throw InputError("--backend " + backend_name + ": the CUDA backend is unavailable (" + why + ")");
    }
    // Before planning: a typo in the output path should not cost the plan.
    if (!json_path.empty() && json_path != "-") {
      try {
        const OutputTarget t = resolveOutput(json_path);
        const std::string dir = t.path.substr(0, t.path.rfind('/') == std::string::npos ? 0 : t.path.rfind('/') + 1);
        if (t.kind == OutputTarget::Kind::kReplace && access(dir.empty() ? "." : dir.c_str(), W_OK) != 0)
          throw std::runtime_error(errnoText("cannot create a file in the directory of", json_path));
      } catch (const std::runtime_error& e) {
        throw InputError(std::string("--json: ") + e.what());
      }
    }
    const Mesh object = load("--object", object_spec);
    const Mesh area = load("--area", area_spec);
    if (auto_gravity) {
      // Against the normal of the area's largest flat region (area_up.h).
      const UpEstimate e = estimateUp(area, -c.gravity);
      c.gravity = -e.up;
      std::printf("gravity (auto): (%.3f, %.3f, %.3f), the largest flat region being %.0f %% of the area\n",
                  c.gravity.x(), c.gravity.y(), c.gravity.z(), 100 * e.share);
    }
    ProgressLine progress;
    r = Planner().plan(object, area, c, [&](const Progress& p) { return progress(p); });
    progress.finish();
    if (verbose && !r.stats.backend_note.empty()) std::fprintf(stderr, "note: %s\n", r.stats.backend_note.c_str());
    for (const auto& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    printReport(object_spec, object, area_spec, area, c, r);
#ifdef PLACE_PLANNER_HAVE_VALIDATION
    if (verify_k > 0) {
      // Within what is left of the plan's budget (none: no limit).
      const double budget = validation::remainingBudgetMs(c.time_budget_ms, r.stats.total_ms);
      const validation::Engines engines = validation::enginesFromString(engines_name);
      const validation::VerifyStats v =
          validation::verifyTopK(object, area, c, r, verify_k, budget, c.threads, {}, engines);
      const char* names[] = {"Bullet", "MuJoCo", "Bullet and MuJoCo"};
      std::printf("physics (%s): %d of %d checked, %d stayed, %d moved down the ranking; "
                  "%.1f ms (shapes %.1f ms, %.1f ms per candidate, %d threads)\n",
                  names[static_cast<int>(engines)], v.checked, v.selected, v.stayed, v.demoted, v.total_ms,
                  v.shape_ms, v.per_check_ms, v.threads);
      if (engines == validation::Engines::kBoth)
        std::printf("physics by engine: Bullet kept %d, MuJoCo kept %d of %d\n", v.bullet_stayed, v.mujoco_stayed,
                    v.checked);
    }
#endif
#ifdef PLACE_PLANNER_HAVE_VALIDATION
    if (!picture_path.empty() && !r.candidates.empty()) {
      // Seen from beside the approach, a little from above: a threading along a peg shows.
      const Candidate& best = r.candidates.front();
      const Eigen::Vector3d a = best.placement.approach.direction.norm() > 0 ? best.placement.approach.direction
                                                                             : Eigen::Vector3d(0, 0, -1);
      const Eigen::Vector3d g = c.gravity.normalized();
      Eigen::Vector3d side = a.cross(g);
      if (side.norm() < 1e-6) side = a.unitOrthogonal();
      const Eigen::Vector3d view = (side.normalized() + 0.6 * a + 0.4 * g).normalized();
      const Eigen::Vector3d com = object.properties.center_of_mass;
      validation::renderPlacement(picture_path, area, object, best.X_WO, view, best.placement.pre_place_W * com,
                                  best.intermediate_poses.empty() ? best.X_WO * com
                                                                  : best.intermediate_poses.front() * com);
      std::printf("picture: %s\n", picture_path.c_str());
    }
#endif
    printTable(r);
    if (!json_path.empty()) {
      // Invalid UTF-8 in a path (any bytes are legal there) becomes U+FFFD rather than an
      // exception: the answer is still written.
      const std::string text =
          resultJson(object_spec, area_spec, c, r).dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
      writeJson(json_path, json_fd, text);
    }
  } catch (const OutputError& e) {
    return fail(kExitOutputError, "output_error", e.what());
  } catch (const std::exception& e) {
    // InputError, MeshError, std::invalid_argument from the planner (a config it refuses) and
    // std::runtime_error (e.g. CUDA failing mid-plan) all mean this input cannot be planned.
    return fail(kExitBadInput, "bad_input", e.what());
  }
  printOutcome(c, r);
  return exitCode(r.outcome());
}
