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

using namespace place_planner;

namespace {

const char* kUsage =
    "usage: place_planner_cli --object O.ply --area P.ply [--gravity x,y,z|auto] [--approach x,y,z]\n"
    "       [--friction F] [--spacing M] [--max-rotations N] [--orientation MODE]\n"
    "       [--budget-ms T] [--max-candidates K] [--threads N] [--json OUT]\n"
    "  O and P are .ply/.obj/.stl files or builtin:NAME (table, dish_rack, open_box,\n"
    "  binder_stack, mug, plate, pen, cube). MODE: principal_axis | keep | all_axes.\n"
    "  --gravity auto: against the normal of the area's largest flat region (a scan in its\n"
    "  camera frame).\n";

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

}  // namespace

int main(int argc, char** argv) {
  try {
    std::map<std::string, std::string> args;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "-h" || a == "--help") {
        std::cout << kUsage;
        return 0;
      }
      if (a.rfind("--", 0) != 0 || i + 1 >= argc)
        throw std::invalid_argument("unexpected argument '" + a + "' (see --help)");
      args[a] = argv[++i];
    }
    static const char* known[] = {"--object", "--area", "--gravity", "--approach", "--friction",
                                  "--spacing", "--max-rotations", "--orientation", "--budget-ms",
                                  "--max-candidates", "--threads", "--json", "--backend"};
    for (const auto& kv : args) {
      bool ok = false;
      for (const char* k : known) ok |= kv.first == k;
      if (!ok) throw std::invalid_argument("unknown option " + kv.first + " (see --help)");
    }
    if (!args.count("--object") || !args.count("--area"))
      throw std::invalid_argument("--object and --area are required (see --help)");
    PlannerConfig c;
    const bool auto_gravity = args.count("--gravity") && args["--gravity"] == "auto";
    if (args.count("--gravity") && !auto_gravity) c.gravity = parseVec("--gravity", args["--gravity"]);
    if (args.count("--approach")) c.approach = parseVec("--approach", args["--approach"]);
    if (args.count("--friction")) c.friction = parseNum("--friction", args["--friction"]);
    if (args.count("--spacing")) c.floor_point_spacing = parseNum("--spacing", args["--spacing"]);
    if (args.count("--max-rotations"))
      c.max_rotations = static_cast<int>(parseNum("--max-rotations", args["--max-rotations"]));
    if (args.count("--orientation")) c.orientation = orientationModeFromString(args["--orientation"]);
    if (args.count("--budget-ms")) c.time_budget_ms = parseNum("--budget-ms", args["--budget-ms"]);
    if (args.count("--max-candidates"))
      c.max_candidates = static_cast<int>(parseNum("--max-candidates", args["--max-candidates"]));
    if (args.count("--threads")) c.threads = static_cast<int>(parseNum("--threads", args["--threads"]));
    if (args.count("--backend")) {
      const std::string b = args["--backend"];
      c.backend = b == "cpu" ? BackendKind::kCpu : b == "cuda" ? BackendKind::kCuda : BackendKind::kAuto;
    }
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
    const PlanResult r = Planner().plan(object, area, c);
    for (const auto& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    const auto& st = r.stats;
    std::printf("object %s (%zu triangles), area %s (%zu triangles), backend %s\n",
                args["--object"].c_str(), object.triangles.size(), args["--area"].c_str(),
                area.triangles.size(), st.backend.c_str());
    std::printf("floor points %d, tree nodes %ld, planning %.1f ms, first stable %.1f ms\n",
                st.floor_points_total, st.tree_nodes, st.total_ms, st.first_stable_ms);
    std::printf("steps [ms]: setup %.1f, floor points %.1f, distance %.1f, contacts %.1f, vertex/surface %.1f, "
                "edge/edge %.1f, stability %.1f, local optimisation %.1f\n",
                st.steps.setup, st.steps.floor_points, st.steps.first_contact, st.steps.contact_points,
                st.steps.tilt_vertex, st.steps.tilt_edge, st.steps.stability, st.steps.local_optimisation);
    std::printf("%4s %7s %6s %26s %32s %8s\n", "rank", "quality", "stable", "position [m]",
                "orientation xyzw", "contacts");
    for (size_t i = 0; i < r.candidates.size(); ++i) {
      const auto& k = r.candidates[i];
      const Eigen::Quaterniond q(k.X_WO.linear());
      const Eigen::Vector3d p = k.X_WO.translation();
      std::printf("%4zu %7.3f %6s (%7.3f %7.3f %7.3f) (%6.3f %6.3f %6.3f %6.3f) %8zu\n", i + 1,
                  k.quality, k.stable ? "yes" : "no", p.x(), p.y(), p.z(), q.x(), q.y(), q.z(),
                  q.w(), k.contacts.size());
    }
    if (args.count("--json")) {
      std::ofstream o(args["--json"]);
      if (!o) throw std::runtime_error("cannot write " + args["--json"]);
      o.precision(9);
      o << "{\"object\": \"" << args["--object"] << "\", \"area\": \"" << args["--area"]
        << "\", \"planning_ms\": " << st.total_ms << ", \"first_stable_ms\": " << st.first_stable_ms
        << ", \"floor_points\": " << st.floor_points_total << ", \"gravity\": ";
      vecJson(o, c.gravity);
      o << ", \"warnings\": [";
      for (size_t i = 0; i < r.warnings.size(); ++i) o << (i ? ", " : "") << "\"" << r.warnings[i] << "\"";
      o << "], \"candidates\": [";
      for (size_t i = 0; i < r.candidates.size(); ++i) {
        const auto& k = r.candidates[i];
        o << (i ? ", " : "") << "{\"position\": ";
        vecJson(o, k.X_WO.translation());
        o << ", \"orientation_xyzw\": ";
        quatJson(o, k.X_WO.linear());
        o << ", \"quality\": " << k.quality << ", \"stable\": " << (k.stable ? "true" : "false")
          << ", \"floor_point\": ";
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
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "place_planner_cli: error: %s\n", e.what());
    return 2;
  }
}
