#include "place_planner/validation/suite.h"

#include "place_planner/infra/output_file.h"
#include "place_planner/validation/mujoco_validator.h"

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "place_planner/model/area_up.h"
#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/validation/mesh_variants.h"

namespace place_planner {
namespace validation {
namespace {

using Clock = std::chrono::steady_clock;

bool exists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Height (along up) the object must clear above floor point p_W: the highest area vertex within
// the object's bounding radius horizontally, or p_W itself.
double clearanceAt(const Mesh& area, const Eigen::Vector3d& p_W, const Eigen::Vector3d& up,
                   double radius) {
  double h = up.dot(p_W);
  for (const auto& v : area.vertices) {
    const Eigen::Vector3d d = v - p_W;
    if ((d - up.dot(d) * up).norm() <= radius) h = std::max(h, up.dot(v));
  }
  return h;
}

double lowestPoint(const Mesh& object, const Eigen::Isometry3d& X_WO, const Eigen::Vector3d& up) {
  double lo = std::numeric_limits<double>::infinity();
  for (const auto& v : object.vertices) lo = std::min(lo, up.dot(X_WO * v));
  return lo;
}

// The drop start above floor point i: the planner's pre-placement pose when a candidate started
// there, else the best candidate's pre-placement orientation moved over the floor point, else the
// object as given. Its height: lowest point 1 cm above the highest area vertex near the floor
// point (drops from the planner's approach height, 10-30 cm, bounced off and tunnelled through
// thin areas).
Eigen::Isometry3d dropStart(const PlanResult& plan, int i, const Mesh& object, const Mesh& area,
                            const Eigen::Vector3d& up) {
  const Eigen::Vector3d fp = plan.floor_points_W[i];
  const Candidate* ref = nullptr;
  for (const auto& c : plan.candidates) {
    if (c.intermediate_poses.empty()) continue;
    if ((c.floor_point_W - fp).norm() < 1e-6) {
      ref = &c;
      break;
    }
    if (!ref) ref = &c;
  }
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  if (ref) {
    X = Eigen::Translation3d(fp - ref->floor_point_W) * ref->intermediate_poses.front();
  } else {
    X.translation() = fp - object.properties.center_of_mass;
  }
  const double clear = clearanceAt(area, fp, up, object.properties.bounding_radius) + 0.01;
  const double low = lowestPoint(object, X, up);
  X.translation() += (clear - low) * up;
  return X;
}

std::string fmt(double v, int prec) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(prec) << v;
  return os.str();
}

void poseCsv(std::ostream& os, const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  os << std::setprecision(6) << X.translation().x() << ',' << X.translation().y() << ','
     << X.translation().z() << ',' << q.w() << ',' << q.x() << ',' << q.y() << ',' << q.z();
}

}  // namespace

Mesh loadSceneMesh(const std::string& source) {
  const std::string prefix = "builtin:";
  if (source.compare(0, prefix.size(), prefix) == 0) return scenes::byName(source.substr(prefix.size()));
  return loadMesh(source);
}

std::vector<ScenePair> defaultPairs(const std::string& data_dir) {
  std::vector<ScenePair> pairs;
  if (!data_dir.empty() && exists(data_dir + "/MANIFEST.tsv")) {
    const std::vector<std::string> objects = {
        "mug_ycb025_1k",         "bowl_ycb024_1k",      "plate_ycb029_1k",
        "mustard_ycb006_1k",     "cracker_box_ycb003_1k", "sugar_box_ycb004_1k",
        "pudding_box_ycb008_1k", "marker_ycb040_1k",    "mug_lowpoly"};
    const std::vector<std::string> areas = {"table",        "books_stack",        "bin",
                                            "dish_rack",    "divided_tray",       "pen_cup_ycb065j_1k",
                                            "tissuebox_scan_scene"};
    for (const auto& a : areas)
      for (const auto& o : objects)
        pairs.push_back({o + "@" + a, data_dir + "/objects/" + o + ".ply", data_dir + "/areas/" + a + ".ply"});
  }
  for (const auto& a : scenes::areaNames())
    for (const auto& o : scenes::objectNames())
      pairs.push_back({"builtin_" + o + "@" + a, "builtin:" + o, "builtin:" + a});
  return pairs;
}

std::vector<ScenePair> scanPairs(const std::string& data_dir, const std::vector<std::string>& areas) {
  std::vector<ScenePair> pairs;
  std::ifstream in(data_dir + "/scans/MANIFEST.tsv");
  if (!in) return pairs;
  struct Row {
    std::string file, source, kind, mode;
  };
  std::vector<Row> rows;
  std::string line;
  std::getline(in, line);  // header: file source kind mode ...
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    Row r;
    std::getline(ls, r.file, '\t');
    std::getline(ls, r.source, '\t');
    std::getline(ls, r.kind, '\t');
    std::getline(ls, r.mode, '\t');
    if (!r.file.empty()) rows.push_back(r);
  }
  auto stem = [](const std::string& path) {
    const size_t a = path.rfind('/') == std::string::npos ? 0 : path.rfind('/') + 1;
    return path.substr(a, path.rfind('.') - a);
  };
  for (const std::string& area : areas) {
    const Row* area_scan = nullptr;
    for (const Row& r : rows)
      if (r.kind == "area" && stem(r.source) == area) area_scan = &r;
    if (!area_scan) continue;
    for (const Row& r : rows) {
      if (r.kind != "object") continue;
      ScenePair p;
      p.name = stem(r.file) + "@" + stem(area_scan->file);
      p.object = data_dir + "/" + r.source;
      p.area = data_dir + "/" + area_scan->source;
      p.object_plan = data_dir + "/scans/" + r.file;
      p.area_plan = data_dir + "/scans/" + area_scan->file;
      p.mode = r.mode;
      pairs.push_back(p);
    }
  }
  return pairs;
}

std::vector<ScenePair> hangingPairs(const std::string& data_dir) {
  struct Obj {
    std::string name, object, plan, mode;
  };
  std::vector<Obj> objects;
  const bool data = !data_dir.empty() && std::ifstream(data_dir + "/objects/mug_ycb025_1k.ply").good();
  if (data) {
    objects.push_back({"mug_ycb025_1k", data_dir + "/objects/mug_ycb025_1k.ply", "", "mesh"});
    objects.push_back({"mug_lowpoly", data_dir + "/objects/mug_lowpoly.ply", "", "mesh"});
    for (const char* mode : {"allaround", "upper", "inhand"}) {
      const std::string scan = data_dir + "/scans/objects/mug_ycb025_" + mode + "_scan.ply";
      if (!std::ifstream(scan).good()) continue;
      const std::string m = mode;
      objects.push_back({"mug_ycb025_" + m + "_scan", data_dir + "/objects/mug_ycb025.ply", scan,
                         m == "allaround" ? "all_around" : m == "inhand" ? "in_hand" : m});
    }
  }
  objects.push_back({"ring", "builtin:ring", "", "mesh"});
  objects.push_back({"loop_mug", "builtin:loop_mug", "", "mesh"});
  objects.push_back({"tape_roll", "builtin:tape_roll", "", "mesh"});
  std::vector<ScenePair> pairs;
  for (const char* area : {"peg_wall", "peg_wall_rising", "mug_tree", "mug_rack", "cup_hooks"})
    for (const Obj& o : objects) {
      ScenePair p;
      p.name = o.name + "@" + area;
      p.object = o.object;
      p.area = std::string("builtin:") + area;
      p.object_plan = o.plan;
      p.mode = o.mode;
      pairs.push_back(p);
    }
  return pairs;
}

SceneResult runScene(const ScenePair& pair, const SuiteConfig& config) {
  try {
    if (!pair.object_plan.empty() || !pair.area_plan.empty())
      return runScene(pair, loadSceneMesh(pair.object), loadSceneMesh(pair.area),
                      loadSceneMesh(pair.object_plan.empty() ? pair.object : pair.object_plan),
                      loadSceneMesh(pair.area_plan.empty() ? pair.area : pair.area_plan), config);
    return runScene(pair, loadSceneMesh(pair.object), loadSceneMesh(pair.area), config);
  } catch (const std::exception& e) {
    SceneResult r;
    r.pair = pair;
    r.error = e.what();
    return r;
  }
}

SceneResult runScene(const ScenePair& pair, const Mesh& object_full, const Mesh& area,
                     const SuiteConfig& config) {
  if (config.hole_fraction > 0) {
    SceneResult r = runScene(pair, object_full, area, punchHoles(object_full, config.hole_fraction, config.hole_seed),
                             area, config);
    r.variant = "holes_" + std::to_string(static_cast<int>(std::lround(config.hole_fraction * 100)));
    return r;
  }
  return runScene(pair, object_full, area, object_full, area, config);
}

SceneResult runScene(const ScenePair& pair, const Mesh& object_full, const Mesh& area_true,
                     const Mesh& object, const Mesh& area, const SuiteConfig& config) {
  SceneResult r;
  r.pair = pair;
  r.area_triangles = static_cast<int>(area.triangles.size());
  if (!pair.mode.empty()) r.variant = "scan_" + pair.mode;
  try {
    r.object_triangles = static_cast<int>(object.triangles.size());

    // Planner.
    PlannerConfig pc = config.planner;
    const Eigen::Vector3d g0 = pc.gravity.norm() > 1e-9 ? Eigen::Vector3d(pc.gravity) : -Eigen::Vector3d::UnitZ();
    if (config.auto_gravity && upFacingShare(area, -g0) < 0.05) pc.gravity = -estimateUp(area, -g0).up;
    const PlanResult plan = Planner().plan(object, area, pc);
    r.stats = plan.stats;
    r.candidates = static_cast<int>(plan.candidates.size());
    for (const auto& c : plan.candidates) r.stable += c.stable ? 1 : 0;
    if (plan.stats.floor_points_total > 0)
      r.planner_ms_per_floor_point = plan.stats.total_ms / plan.stats.floor_points_total;

    // Physics check of the best-ranked stable candidates, on the full object mesh.
    ValidatorConfig vc = config.validator;
    vc.friction = config.planner.friction;
    if (pc.gravity.norm() > 1e-9) vc.gravity = 9.81 * pc.gravity.normalized();
    const PhysicsValidator validator(object_full, area_true, vc);
    std::unique_ptr<MujocoValidator> mujoco;
    if (config.mujoco) mujoco = std::make_unique<MujocoValidator>(object_full, area_true, vc);
    const auto t0 = Clock::now();
    for (size_t k = 0; k < plan.candidates.size() && r.validated < config.max_validated; ++k) {
      const Candidate& c = plan.candidates[k];
      if (!c.stable) continue;
      CandidateCheck cc;
      cc.rank = static_cast<int>(k);
      cc.quality = c.quality;
      cc.X_WO = c.X_WO;
      cc.support = c.support;
      cc.check = validator.check(c.X_WO);
      if (c.hanging) cc.check.confirmed = stillHanging(cc.check, c.X_WO, object_full.properties.center_of_mass, vc);
      if (mujoco) {
        cc.mujoco_checked = true;
        cc.mujoco = mujoco->check(c.X_WO);
        if (c.hanging) cc.mujoco.confirmed = stillHanging(cc.mujoco, c.X_WO, object_full.properties.center_of_mass, vc);
        r.confirmed_mujoco += cc.mujoco.confirmed ? 1 : 0;
        r.confirmed_both += cc.bothConfirmed() ? 1 : 0;
      }
      ++r.validated;
      r.confirmed += cc.check.confirmed ? 1 : 0;
      r.checks.push_back(cc);
    }
    r.validate_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();

    // Baseline: drop from the pre-placement pose above (a spread of) the same floor points.
    const int nfp = static_cast<int>(plan.floor_points_W.size());
    const int ndrop = std::min(nfp, std::max(0, config.max_drops));
    const Eigen::Vector3d up = -vc.gravity.normalized();
    std::vector<double> ms;
    for (int j = 0; j < ndrop; ++j) {
      const int i = static_cast<int>((static_cast<long>(j) * nfp) / ndrop);
      DropRecord d;
      d.floor_point = i;
      d.X_WO_start = dropStart(plan, i, object_full, area_true, up);
      d.result = validator.drop(d.X_WO_start);
      r.drops_at_rest += d.result.at_rest ? 1 : 0;
      r.drops_fell += d.result.fell_off ? 1 : 0;
      ms.push_back(d.result.wall_ms);
      r.drops.push_back(d);
    }
    if (!ms.empty()) {
      double s = 0;
      for (double m : ms) s += m;
      r.drop_ms_mean = s / ms.size();
      r.drop_ms_median = median(ms);
    }
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  return r;
}

SuiteSummary summarize(const std::vector<SceneResult>& results) {
  SuiteSummary s;
  std::vector<double> first, total;
  for (const auto& r : results) {
    ++s.scenes;
    if (!r.error.empty()) {
      ++s.errors;
      continue;
    }
    s.validated += r.validated;
    s.confirmed += r.confirmed;
    if (r.plannerConfirmed()) ++s.planner_scenes_confirmed;
    if (r.bulletRests()) {
      ++s.bullet_rest_scenes;
      if (r.plannerConfirmed()) ++s.covered_scenes;
    }
    s.floor_points += r.stats.floor_points_total;
    s.planner_ms_total += r.stats.total_ms;
    s.drops += static_cast<int>(r.drops.size());
    s.drop_ms_total += r.drop_ms_mean * r.drops.size();
    total.push_back(r.stats.total_ms);
    if (r.stats.first_stable_ms >= 0) first.push_back(r.stats.first_stable_ms);
  }
  s.precision = s.validated ? double(s.confirmed) / s.validated : 0.0;
  s.coverage = s.bullet_rest_scenes ? double(s.covered_scenes) / s.bullet_rest_scenes : 0.0;
  s.planner_ms_per_floor_point = s.floor_points ? s.planner_ms_total / s.floor_points : 0.0;
  s.drop_ms_per_drop = s.drops ? s.drop_ms_total / s.drops : 0.0;
  s.speedup = s.planner_ms_per_floor_point > 0 && s.drops
                  ? s.drop_ms_per_drop / s.planner_ms_per_floor_point : 0.0;
  s.median_first_stable_ms = first.empty() ? -1.0 : median(first);
  s.median_total_ms = median(total);
  return s;
}

void writeScenesCsv(const std::vector<SceneResult>& results, const std::string& path) {
  // Written whole by the output-file rules (infra/output_file.h): never half a file, never a
  // device replaced.
  std::ostringstream os;
  os << "scene,variant,object_triangles,area_triangles,floor_points,total_ms,first_stable_ms,"
        "ms_setup,ms_floor_points,ms_first_contact,ms_contact_points,ms_tilt_vertex,ms_tilt_edge,"
        "ms_stability,ms_local_optimisation,candidates,stable,validated,confirmed,precision,"
        "drops,drops_at_rest,drops_fell,drop_ms_mean,drop_ms_median,planner_ms_per_floor_point,"
        "speedup,error\n";
  for (const auto& r : results) {
    const StepTimes& st = r.stats.steps;
    os << r.pair.name << ',' << r.variant << ',' << r.object_triangles << ',' << r.area_triangles
       << ',' << r.stats.floor_points_total << ',' << r.stats.total_ms << ','
       << r.stats.first_stable_ms << ',' << st.setup << ',' << st.floor_points << ',' << st.first_contact << ','
       << st.contact_points << ',' << st.tilt_vertex << ',' << st.tilt_edge << ',' << st.stability
       << ',' << st.local_optimisation << ',' << r.candidates << ',' << r.stable << ','
       << r.validated << ',' << r.confirmed << ',' << r.precision() << ',' << r.drops.size() << ','
       << r.drops_at_rest << ',' << r.drops_fell << ',' << r.drop_ms_mean << ','
       << r.drop_ms_median << ',' << r.planner_ms_per_floor_point << ',' << r.speedup() << ",\""
       << r.error << "\"\n";
  }
  writeOutputFile(path, os.str());
}

void writeChecksCsv(const std::vector<SceneResult>& results, const std::string& path) {
  // Written whole by the output-file rules (infra/output_file.h): never half a file, never a
  // device replaced.
  std::ostringstream os;
  os << "scene,variant,rank,quality,confirmed,moved_m,turned_deg,aborted,"
        "goal_x,goal_y,goal_z,goal_qw,goal_qx,goal_qy,goal_qz,"
        "final_x,final_y,final_z,final_qw,final_qx,final_qy,final_qz,"
        "mujoco_checked,mujoco_confirmed,mujoco_moved_m,mujoco_turned_deg,support\n";
  for (const auto& r : results)
    for (const auto& c : r.checks) {
      os << r.pair.name << ',' << r.variant << ',' << c.rank << ',' << c.quality << ','
         << c.check.confirmed << ',' << c.check.moved_m << ',' << c.check.turned_deg << ','
         << c.check.aborted << ',';
      poseCsv(os, c.X_WO);
      os << ',';
      poseCsv(os, c.check.X_WO_final);
      os << ',' << c.mujoco_checked << ',' << c.mujoco.confirmed << ',' << c.mujoco.moved_m << ','
         << c.mujoco.turned_deg << ',' << toString(c.support) << '\n';
    }
  writeOutputFile(path, os.str());
}

void writeDropsCsv(const std::vector<SceneResult>& results, const std::string& path) {
  // Written whole by the output-file rules (infra/output_file.h): never half a file, never a
  // device replaced.
  std::ostringstream os;
  os << "scene,variant,floor_point,at_rest,fell_off,steps,sim_s,wall_ms,"
        "start_x,start_y,start_z,start_qw,start_qx,start_qy,start_qz,"
        "rest_x,rest_y,rest_z,rest_qw,rest_qx,rest_qy,rest_qz\n";
  for (const auto& r : results)
    for (const auto& d : r.drops) {
      os << r.pair.name << ',' << r.variant << ',' << d.floor_point << ',' << d.result.at_rest << ','
         << d.result.fell_off << ',' << d.result.steps << ',' << d.result.sim_time << ','
         << d.result.wall_ms << ',';
      poseCsv(os, d.X_WO_start);
      os << ',';
      poseCsv(os, d.result.X_WO_rest);
      os << '\n';
    }
  writeOutputFile(path, os.str());
}

std::string markdownTable(const std::vector<SceneResult>& results) {
  std::ostringstream os;
  os << "| scene | variant | tris | floor pts | plan ms | first stable ms | cand. | stable | "
        "confirmed / validated | drops at rest | drop ms (mean) | planner ms / floor pt | "
        "speed-up |\n"
     << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& r : results) {
    if (!r.error.empty()) {
      os << "| " << r.pair.name << " | " << r.variant << " | error: " << r.error
         << " |||||||||||\n";
      continue;
    }
    os << "| " << r.pair.name << " | " << r.variant << " | " << r.object_triangles << " | "
       << r.stats.floor_points_total << " | " << fmt(r.stats.total_ms, 1) << " | "
       << (r.stats.first_stable_ms >= 0 ? fmt(r.stats.first_stable_ms, 1) : std::string("-"))
       << " | " << r.candidates << " | " << r.stable << " | " << r.confirmed << " / "
       << r.validated << " | ";
    if (r.drops.empty())
      os << "- | - | " << fmt(r.planner_ms_per_floor_point, 2) << " | - |\n";
    else
      os << r.drops_at_rest << " / " << r.drops.size() << " | " << fmt(r.drop_ms_mean, 1) << " | "
         << fmt(r.planner_ms_per_floor_point, 2) << " | " << fmt(r.speedup(), 1) << "x |\n";
  }
  return os.str();
}

std::string markdownSummary(const SuiteSummary& s, const std::string& label) {
  std::ostringstream os;
  os << "| " << label << " | " << s.scenes - s.errors << " | " << s.confirmed << " / "
     << s.validated << " = **" << fmt(s.precision, 3) << "** | " << s.covered_scenes << " / "
     << s.bullet_rest_scenes << " = **" << fmt(s.coverage, 3) << "** | "
     << fmt(s.median_total_ms, 1) << " | "
     << (s.median_first_stable_ms >= 0 ? fmt(s.median_first_stable_ms, 1) : std::string("-"))
     << " | ";
  if (s.drops)
    os << fmt(s.planner_ms_per_floor_point, 2) << " | " << fmt(s.drop_ms_per_drop, 1) << " | **"
       << fmt(s.speedup, 1) << "x** |";
  else
    os << fmt(s.planner_ms_per_floor_point, 2) << " | - | - |";
  return os.str();
}

}  // namespace validation
}  // namespace place_planner
