// place_planner_cli: plan placements of an object mesh on an area mesh from the shell.
#include <Eigen/Geometry>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include "place_planner/area_up.h"
#include "place_planner/mesh_io.h"
#include "place_planner/planner.h"
#include "place_planner/scenes.h"
#ifdef PLACE_PLANNER_HAVE_VALIDATION
#include "place_planner/validation/physics_validator.h"
#endif

using namespace place_planner;

namespace {

const char* kUsage =
    "usage: place_planner_cli --object O.ply --area P.ply [--gravity x,y,z|auto] [--approach x,y,z]\n"
    "       [--friction F] [--spacing M] [--max-rotations N] [--orientation MODE]\n"
    "       [--max-resting-faces N] [--robust-shift M] [--robust-tilt-deg D]\n"
    "       [--robust-com-offset F] [--robust-min-share S] [--no-robust-check]\n"
    "       [--budget-ms T] [--max-candidates K] [--threads N] [--backend auto|cpu|cuda]\n"
    "       [--verify K] [--json OUT]\n"
    "  O and P are .ply/.obj/.stl files or builtin:NAME (table, dish_rack, open_box,\n"
    "  binder_stack, mug, plate, pen, cube). MODE: auto | principal_axis | keep | all_axes.\n"
    "  --gravity auto: against the normal of the area's largest flat region (a scan in its\n"
    "  camera frame).\n"
    "  --verify K: simulate the best K stable candidates in Bullet (released 2 mm above the pose;\n"
    "  stayed = moved < 1 cm, turned < 5 deg) within what is left of --budget-ms; one that falls\n"
    "  is moved behind the other stable candidates. 0 (default) = off.\n"
    "  Exit: 0 stable candidates found (also a partial answer when the budget ran out),\n"
    "  1 no stable pose (search complete), 3 budget ran out with nothing stable, 2 bad input.\n"
    "  The last line of stdout is always 'outcome: ...'.\n";

Eigen::Vector3d parseVec(const std::string& flag, const std::string& s) {
  Eigen::Vector3d v;
  char c1, c2;
  std::istringstream is(s);
  if (!(is >> v.x() >> c1 >> v.y() >> c2 >> v.z()) || c1 != ',' || c2 != ',')
    throw std::invalid_argument(flag + " expects x,y,z (got '" + s + "')");
  return v;
}

double parseNum(const std::string& flag, const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end) throw std::invalid_argument(flag + " expects a number (got '" + s + "')");
  return v;
}

Mesh load(const std::string& spec) {
  if (spec.rfind("builtin:", 0) == 0) return scenes::byName(spec.substr(8));
  return loadMesh(spec);
}

void vecJson(std::ostream& o, const Eigen::Vector3d& v) {
  o << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
}
void quatJson(std::ostream& o, const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  o << "[" << q.x() << ", " << q.y() << ", " << q.z() << ", " << q.w() << "]";
}

std::string jsonEscaped(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out;
}

// Exit codes (README "Using it"): 0 stable (complete or partial), 1 no stable pose, 3 timed out
// with nothing stable, 2 bad input (main's catch).
int exitCode(PlanOutcome o) {
  switch (o) {
    case PlanOutcome::kStable:
    case PlanOutcome::kTimedOutWithStable: return 0;
    case PlanOutcome::kNoStable: return 1;
    case PlanOutcome::kTimedOutNone:
    case PlanOutcome::kCancelled: return 3;  // the CLI never cancels
  }
  return 3;
}

std::string physicsCell(const PhysicsCheck& p) { return p.checked ? (p.stayed ? "yes" : "no") : "-"; }

std::string robustnessCell(const Robustness& r) {
  if (r.trials == 0) return "-";
  return std::to_string(r.held) + "/" + std::to_string(r.trials);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    // Options that take no value.
    static const char* flags[] = {"--no-robust-check"};
    static const char* known[] = {"--object", "--area", "--gravity", "--approach", "--friction",
                                  "--spacing", "--max-rotations", "--orientation", "--budget-ms",
                                  "--max-candidates", "--threads", "--json", "--backend",
                                  "--max-resting-faces", "--robust-shift", "--robust-tilt-deg",
                                  "--robust-com-offset", "--robust-min-share", "--verify"};
    std::map<std::string, std::string> args;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "-h" || a == "--help") {
        std::cout << kUsage;
        return 0;
      }
      bool is_flag = false;
      for (const char* f : flags) is_flag |= a == f;
      if (is_flag) {
        args[a] = "";
        continue;
      }
      bool ok = false;
      for (const char* k : known) ok |= a == k;
      if (a.rfind("--", 0) == 0 && !ok) throw std::invalid_argument("unknown option " + a + " (see --help)");
      if (!ok || i + 1 >= argc)
        throw std::invalid_argument("unexpected argument '" + a + "' (see --help)");
      args[a] = argv[++i];
    }
    if (!args.count("--object") || !args.count("--area"))
      throw std::invalid_argument("--object and --area are required (see --help)");
    const auto integer = [&](const char* flag) {
      const double v = parseNum(flag, args[flag]);
      if (v != static_cast<int>(v)) throw std::invalid_argument(std::string(flag) + " expects an integer");
      return static_cast<int>(v);
    };
    PlannerConfig c;
    const bool auto_gravity = args.count("--gravity") && args["--gravity"] == "auto";
    if (args.count("--gravity") && !auto_gravity) c.gravity = parseVec("--gravity", args["--gravity"]);
    if (args.count("--approach")) c.approach = parseVec("--approach", args["--approach"]);
    if (args.count("--friction")) c.friction = parseNum("--friction", args["--friction"]);
    if (args.count("--spacing")) c.floor_point_spacing = parseNum("--spacing", args["--spacing"]);
    if (args.count("--max-rotations")) c.max_rotations = integer("--max-rotations");
    if (args.count("--orientation")) c.orientation = orientationModeFromString(args["--orientation"]);
    if (args.count("--max-resting-faces")) c.max_resting_faces = integer("--max-resting-faces");
    if (args.count("--robust-shift")) c.robust_shift = parseNum("--robust-shift", args["--robust-shift"]);
    if (args.count("--robust-tilt-deg"))
      c.robust_tilt_deg = parseNum("--robust-tilt-deg", args["--robust-tilt-deg"]);
    if (args.count("--robust-com-offset"))
      c.robust_com_offset = parseNum("--robust-com-offset", args["--robust-com-offset"]);
    if (args.count("--robust-min-share"))
      c.robust_min_share = parseNum("--robust-min-share", args["--robust-min-share"]);
    if (args.count("--no-robust-check")) c.robust_check = false;
    if (args.count("--budget-ms")) c.time_budget_ms = parseNum("--budget-ms", args["--budget-ms"]);
    if (args.count("--max-candidates")) c.max_candidates = integer("--max-candidates");
    if (args.count("--threads")) c.threads = integer("--threads");
    if (args.count("--backend")) {
      const std::string b = args["--backend"];
      if (b != "auto" && b != "cpu" && b != "cuda")
        throw std::invalid_argument("--backend expects auto, cpu or cuda (got '" + b + "')");
      c.backend = b == "cpu" ? BackendKind::kCpu : b == "cuda" ? BackendKind::kCuda : BackendKind::kAuto;
    }
    const int verify_k = args.count("--verify") ? integer("--verify") : 0;
    if (verify_k < 0) throw std::invalid_argument("--verify expects K >= 0");
#ifndef PLACE_PLANNER_HAVE_VALIDATION
    if (verify_k > 0) throw std::invalid_argument("--verify: built without Bullet (no validation library)");
#endif
    validate(c);
    const Mesh object = load(args["--object"]);
    const Mesh area = load(args["--area"]);
    if (auto_gravity) {
      // Against the normal of the area's largest flat region (area_up.h).
      const UpEstimate e = estimateUp(area, -c.gravity);
      c.gravity = -e.up;
      std::printf("gravity (auto): (%.3f, %.3f, %.3f), the largest flat region being %.0f %% of the area\n",
                  c.gravity.x(), c.gravity.y(), c.gravity.z(), 100 * e.share);
    }
    PlanResult r = Planner().plan(object, area, c);
    for (const auto& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    const auto& st = r.stats;
    std::printf("object %s (%zu triangles), area %s (%zu triangles), backend %s, orientation %s\n",
                args["--object"].c_str(), object.triangles.size(), args["--area"].c_str(),
                area.triangles.size(), st.backend.c_str(), toString(c.orientation).c_str());
    std::printf("floor points %d of %d, tree nodes %ld, planning %.1f ms, first stable %.1f ms\n",
                st.floor_points_done, st.floor_points_total, st.tree_nodes, st.total_ms,
                st.first_stable_ms);
    std::printf("steps [ms]: setup %.1f, floor points %.1f, distance %.1f, contacts %.1f, vertex/surface %.1f, "
                "edge/edge %.1f, stability %.1f, local optimisation %.1f, robustness %.1f\n",
                st.steps.setup, st.steps.floor_points, st.steps.first_contact, st.steps.contact_points,
                st.steps.tilt_vertex, st.steps.tilt_edge, st.steps.stability, st.steps.local_optimisation,
                st.robustness_ms);
#ifdef PLACE_PLANNER_HAVE_VALIDATION
    if (verify_k > 0) {
      // Within what is left of the plan's budget (none: no limit).
      const double budget = validation::remainingBudgetMs(c.time_budget_ms, st.total_ms);
      const validation::VerifyStats v =
          validation::verifyTopK(object, area, c, r, verify_k, budget, c.threads);
      std::printf("physics (Bullet): %d of %d checked, %d stayed, %d moved down the ranking; "
                  "%.1f ms (shapes %.1f ms, %.1f ms per candidate, %d threads)\n",
                  v.checked, v.selected, v.stayed, v.demoted, v.total_ms, v.shape_ms,
                  v.per_check_ms, v.threads);
    }
#endif
    std::printf("%4s %7s %6s %6s %7s %-14s %26s %32s %8s\n", "rank", "quality", "stable", "robust",
                "physics", "start", "position [m]", "orientation xyzw", "contacts");
    for (size_t i = 0; i < r.candidates.size(); ++i) {
      const auto& k = r.candidates[i];
      const Eigen::Quaterniond q(k.X_WO.linear());
      const Eigen::Vector3d p = k.X_WO.translation();
      std::printf("%4zu %7.3f %6s %6s %7s %-14s (%7.3f %7.3f %7.3f) (%6.3f %6.3f %6.3f %6.3f) %8zu\n",
                  i + 1, k.quality, k.stable ? "yes" : "no", robustnessCell(k.robustness).c_str(),
                  physicsCell(k.physics).c_str(), toString(k.start), p.x(), p.y(), p.z(), q.x(),
                  q.y(), q.z(), q.w(), k.contacts.size());
    }
    const PlanOutcome outcome = r.outcome();
    if (args.count("--json")) {
      std::ofstream o(args["--json"]);
      if (!o) throw std::runtime_error("cannot write " + args["--json"]);
      o.precision(9);
      o << "{\"object\": \"" << jsonEscaped(args["--object"]) << "\", \"area\": \""
        << jsonEscaped(args["--area"]) << "\", \"outcome\": \"" << toString(outcome)
        << "\", \"stable_candidates\": " << r.stableCount()
        << ", \"planning_ms\": " << st.total_ms << ", \"first_stable_ms\": " << st.first_stable_ms
        << ", \"floor_points\": " << st.floor_points_total
        << ", \"floor_points_done\": " << st.floor_points_done << ", \"gravity\": ";
      vecJson(o, c.gravity);
      o << ", \"warnings\": [";
      for (size_t i = 0; i < r.warnings.size(); ++i)
        o << (i ? ", " : "") << "\"" << jsonEscaped(r.warnings[i]) << "\"";
      o << "], \"candidates\": [";
      for (size_t i = 0; i < r.candidates.size(); ++i) {
        const auto& k = r.candidates[i];
        o << (i ? ", " : "") << "{\"position\": ";
        vecJson(o, k.X_WO.translation());
        o << ", \"orientation_xyzw\": ";
        quatJson(o, k.X_WO.linear());
        o << ", \"quality\": " << k.quality << ", \"stable\": " << (k.stable ? "true" : "false")
          << ", \"start\": \"" << toString(k.start) << "\", \"robustness\": {\"trials\": "
          << k.robustness.trials << ", \"held\": " << k.robustness.held
          << ", \"share\": " << k.robustness.share()
          << ", \"min_tipping_angle\": " << k.robustness.min_tipping_angle
          << "}, \"physics\": {\"checked\": " << (k.physics.checked ? "true" : "false")
          << ", \"stayed\": " << (k.physics.stayed ? "true" : "false")
          << ", \"moved_m\": " << k.physics.moved_m << ", \"turned_deg\": " << k.physics.turned_deg
          << "}, \"floor_point\": ";
        vecJson(o, k.floor_point_W);
        o << ", \"contacts\": [";
        for (size_t j = 0; j < k.contacts.size(); ++j) {
          o << (j ? ", " : "") << "{\"p\": ";
          vecJson(o, k.contacts[j].p_W);
          o << ", \"n\": ";
          vecJson(o, k.contacts[j].n_W);
          o << "}";
        }
        o << "], \"intermediate_poses\": [";
        for (size_t j = 0; j < k.intermediate_poses.size(); ++j) {
          o << (j ? ", " : "") << "{\"position\": ";
          vecJson(o, k.intermediate_poses[j].translation());
          o << ", \"orientation_xyzw\": ";
          quatJson(o, k.intermediate_poses[j].linear());
          o << "}";
        }
        o << "]}";
      }
      o << "]}\n";
    }
    // The answer in one line, always last on stdout (scripts read it with tail -1).
    const int n_stable = r.stableCount();
    switch (outcome) {
      case PlanOutcome::kStable:
        std::printf("outcome: stable (%d stable candidate%s)\n", n_stable, n_stable == 1 ? "" : "s");
        break;
      case PlanOutcome::kTimedOutWithStable:
        std::printf("partial answer: the time budget of %.1f ms ran out after %d of %d floor points\n",
                    c.time_budget_ms, st.floor_points_done, st.floor_points_total);
        std::printf("outcome: timed_out_partial (%d stable candidate%s so far)\n", n_stable,
                    n_stable == 1 ? "" : "s");
        break;
      case PlanOutcome::kNoStable:
        std::printf("outcome: no_stable_pose (%zu candidates, none stable, all %d floor points searched)\n",
                    r.candidates.size(), st.floor_points_total);
        break;
      case PlanOutcome::kTimedOutNone:
      case PlanOutcome::kCancelled:
        std::printf("outcome: %s (nothing stable in %d of %d floor points within %.1f ms)\n",
                    toString(outcome), st.floor_points_done, st.floor_points_total, c.time_budget_ms);
        break;
    }
    return exitCode(outcome);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "place_planner_cli: error: %s\n", e.what());
    std::printf("outcome: bad_input\n");
    return 2;
  }
}
