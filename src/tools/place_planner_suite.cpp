// The benchmark suite (scripts/bench runs it): every object x area pair, planner and
// Bullet in this one process. Writes scenes.csv, checks.csv, drops.csv, fig6.csv, results.md
// and the PNG plots.
//
//   place_planner_suite --data ../shared/data --out DIR [--plots DIR] [--pairs SUBSTR,...]
//       [--holes 0.05,0.1,0.2 | --holes none] [--no-fig6] [--max-validated 5] [--max-drops 16]
//       [--threads 1] [--friction 0.2] [--auto-gravity]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/output_file.h"
#include "place_planner/validation/mesh_variants.h"
#include "place_planner/validation/plot.h"
#include "place_planner/validation/suite.h"

using namespace place_planner;
using namespace place_planner::validation;

namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

[[noreturn]] void usage(const char* msg) {
  std::fprintf(stderr,
               "%s\nusage: place_planner_suite --data DIR --out DIR [--plots DIR] [--pairs S,...]\n"
               "  [--holes 0.05,0.1,0.2|none] [--no-fig6] [--max-validated N] [--max-drops N]\n"
               "  [--threads N] [--friction MU] [--auto-gravity] [--orientation MODE]\n"
               "  [--robust-shift M] [--robust-tilt-deg D] [--robust-com-offset F] [--robust-min-share S]\n"
               "  [--robust-min-share-hanging S]\n"
               "  [--no-robust-check] [--no-robust-recheck-caught] [--no-rock-settle] [--closed-scan|--exact-mesh]\n"
               "  [--scans AREA,...]  the scan suite instead: object scans on the areas' robot-head\n"
               "  scans (DATA/scans), validated on the true meshes; writes OUT/scans.{md,csv}\n"
               "  [--hanging]  the hanging suite instead: looped objects on built-in peg walls and a\n"
               "  mug tree, placement hanging; writes OUT/hanging.{md,csv}\n"
               "  [--mujoco]  also check each validated pose in MuJoCo, the second engine, and count\n"
               "  the poses both engines keep\n"
               "  --auto-gravity: areas with under 5 %% of their surface facing up are planned and\n"
               "  validated with gravity against their largest flat region (area_up.h)\n",
               msg);
  std::exit(2);
}

struct Fig6Row {
  int triangles = 0;
  StepTimes steps;
  double total_ms = 0, per_floor_point_ms = 0;
};

// Time per planner step against object triangles (the paper's Fig. 6): the 16k YCB mug reduced
// by vertex clustering to 200..1000 triangles, planned on the books stack, median of 3 runs.
std::vector<Fig6Row> fig6(const std::string& data, const SuiteConfig& cfg) {
  const Mesh full = loadMesh(data + "/objects/mug_ycb025.ply");
  const Mesh area = loadMesh(data + "/areas/books_stack.ply");
  std::vector<Fig6Row> rows;
  for (int target = 200; target <= 1000; target += 100) {
    const Mesh m = decimateByClustering(full, target);
    std::vector<PlanStats> runs;
    for (int k = 0; k < 3; ++k) runs.push_back(Planner().plan(m, area, cfg.planner).stats);
    auto med = [&](auto get) {
      std::vector<double> v;
      for (const auto& s : runs) v.push_back(get(s));
      return median(v);
    };
    Fig6Row r;
    r.triangles = static_cast<int>(m.triangles.size());
    r.steps.setup = med([](const PlanStats& s) { return s.steps.setup; });
    r.steps.floor_points = med([](const PlanStats& s) { return s.steps.floor_points; });
    r.steps.first_contact = med([](const PlanStats& s) { return s.steps.first_contact; });
    r.steps.contact_points = med([](const PlanStats& s) { return s.steps.contact_points; });
    r.steps.tilt_vertex = med([](const PlanStats& s) { return s.steps.tilt_vertex; });
    r.steps.tilt_edge = med([](const PlanStats& s) { return s.steps.tilt_edge; });
    r.steps.stability = med([](const PlanStats& s) { return s.steps.stability; });
    r.steps.local_optimisation = med([](const PlanStats& s) { return s.steps.local_optimisation; });
    r.total_ms = med([](const PlanStats& s) { return s.total_ms; });
    r.per_floor_point_ms = med([](const PlanStats& s) {
      return s.floor_points_total ? s.total_ms / s.floor_points_total : 0.0;
    });
    std::fprintf(stderr, "[fig6] %4d triangles: %.1f ms total\n", r.triangles, r.total_ms);
    rows.push_back(r);
  }
  return rows;
}

// A suite checked by its best stable poses (the scan suite, the hanging suite): by mode (the
// object scan's, or "mesh") and by area, scenes whose best stable pose Bullet confirms and the
// precision of the top-3 stable poses. Writes OUT/<stem>.md, <stem>.csv, <stem>_checks.csv.
int runBestPoseSuite(const std::vector<ScenePair>& all_pairs, const std::vector<std::string>& filters,
                     const std::string& out, const std::string& stem, const std::string& intro, SuiteConfig cfg) {
  cfg.max_drops = 0;
  std::vector<ScenePair> pairs;
  for (const auto& p : all_pairs) {
    bool keep = filters.empty();
    for (const auto& f : filters) keep = keep || p.name.find(f) != std::string::npos;
    if (keep) pairs.push_back(p);
  }
  if (pairs.empty()) {
    std::fprintf(stderr, "no scene pairs for the %s suite\n", stem.c_str());
    return 2;
  }
  struct Tally {
    int scenes = 0, best = 0, top3_validated = 0, top3_confirmed = 0, none_stable = 0;
    int top3_seen_validated = 0, top3_seen_confirmed = 0;  // those flagged as on seen surface
    int best_both = 0, top3_both = 0;  // confirmed in Bullet and MuJoCo (--mujoco)
    double plan_ms = 0;
  };
  std::map<std::string, Tally> by_mode, by_area;
  Tally total;
  std::vector<SceneResult> results;
  std::ostringstream rows;
  for (const auto& p : pairs) {
    SceneResult r = runScene(p, cfg);
    int v3 = 0;
    const int c3 = r.confirmedOfTop(3, &v3);
    int v3_seen = 0;
    const int c3_seen = r.confirmedSeenOfTop(3, &v3_seen);
    const std::string area = p.name.substr(p.name.find('@') + 1);
    for (Tally* t : {&by_mode[p.mode], &by_area[area], &total}) {
      ++t->scenes;
      t->best += r.bestConfirmed() ? 1 : 0;
      t->best_both += r.bestConfirmedBoth() ? 1 : 0;
      t->top3_both += r.confirmedBothOfTop(3);
      t->top3_validated += v3;
      t->top3_confirmed += c3;
      t->top3_seen_validated += v3_seen;
      t->top3_seen_confirmed += c3_seen;
      t->none_stable += r.stable == 0 ? 1 : 0;
      t->plan_ms += r.stats.total_ms;
    }
    std::string both;
    if (cfg.mujoco)
      both = std::string("  both engines: best ") + (r.checks.empty() ? "-" : r.bestConfirmedBoth() ? "yes" : "no") +
             " top-3 " + std::to_string(r.confirmedBothOfTop(3)) + "/" + std::to_string(v3);
    std::fprintf(stderr, "%-55s plan %7.1f ms  stable %2d  best %s  top-3 %d/%d%s  %s\n", p.name.c_str(),
                 r.stats.total_ms, r.stable, r.checks.empty() ? "-  " : r.bestConfirmed() ? "yes" : "no ", c3, v3,
                 both.c_str(), r.error.c_str());
    char line[512];
    std::snprintf(line, sizeof line, "| %s | %s | %d | %s | %d/%d | %.0f |\n", p.name.c_str(), p.mode.c_str(),
                  r.stable, r.checks.empty() ? "-" : r.bestConfirmed() ? "yes" : "no", c3, v3, r.stats.total_ms);
    rows << line;
    results.push_back(std::move(r));
  }
  std::ostringstream md;
  md << intro << "\n\n"
     << "| group | scenes | best confirmed | top-3 precision | top-3 on seen surface | nothing stable | mean plan ms |"
     << (cfg.mujoco ? " best, both engines | top-3, both engines |\n" : "\n")
     << "|---|---:|---:|---:|---:|---:|---:|" << (cfg.mujoco ? "---:|---:|\n" : "\n");
  auto line = [&](const std::string& name, const Tally& t) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "| %s | %d | %d/%d = %.2f | %d/%d = %.2f | %d/%d = %.2f | %d | %.0f |", name.c_str(),
                  t.scenes, t.best, t.scenes, t.scenes ? double(t.best) / t.scenes : 0.0, t.top3_confirmed,
                  t.top3_validated, t.top3_validated ? double(t.top3_confirmed) / t.top3_validated : 0.0,
                  t.top3_seen_confirmed, t.top3_seen_validated,
                  t.top3_seen_validated ? double(t.top3_seen_confirmed) / t.top3_seen_validated : 0.0, t.none_stable,
                  t.scenes ? t.plan_ms / t.scenes : 0.0);
    md << buf;
    if (cfg.mujoco) {
      std::snprintf(buf, sizeof buf, " %d/%d = %.2f | %d/%d = %.2f |", t.best_both, t.scenes,
                    t.scenes ? double(t.best_both) / t.scenes : 0.0, t.top3_both, t.top3_validated,
                    t.top3_validated ? double(t.top3_both) / t.top3_validated : 0.0);
      md << buf;
    }
    md << "\n";
  };
  for (const auto& [mode, t] : by_mode) line("mode " + mode, t);
  for (const auto& [area, t] : by_area) line("area " + area, t);
  line("all", total);
  md << "\n| scene | mode | stable | best | top-3 | plan ms |\n|---|---|---:|---|---:|---:|\n" << rows.str();
  writeScenesCsv(results, out + "/" + stem + ".csv");
  writeChecksCsv(results, out + "/" + stem + "_checks.csv");
  place_planner::writeOutputFile(out + "/" + stem + ".md", md.str());
  std::cout << md.str().substr(0, md.str().find("\n| scene")) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data, out, plots;
  std::vector<std::string> filters;
  std::vector<double> holes = {0.05, 0.10, 0.20};
  bool do_fig6 = true;
  std::vector<std::string> scan_areas;
  bool hanging = false;
  SuiteConfig cfg;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) usage(("missing value after " + a).c_str());
      return argv[++i];
    };
    if (a == "--data") data = next();
    else if (a == "--out") out = next();
    else if (a == "--plots") plots = next();
    else if (a == "--pairs") filters = split(next());
    else if (a == "--holes") {
      const std::string v = next();
      holes.clear();
      if (v != "none")
        for (const auto& s : split(v)) holes.push_back(std::stod(s));
    } else if (a == "--no-fig6") do_fig6 = false;
    else if (a == "--max-validated") cfg.max_validated = std::stoi(next());
    else if (a == "--max-drops") cfg.max_drops = std::stoi(next());
    else if (a == "--threads") cfg.planner.threads = std::stoi(next());
    else if (a == "--friction") cfg.planner.friction = std::stod(next());
    else if (a == "--auto-gravity") cfg.auto_gravity = true;
    else if (a == "--scans") scan_areas = split(next());
    else if (a == "--hanging") hanging = true;
    else if (a == "--mujoco") cfg.mujoco = true;
    // Planner options, to measure their effect on precision and coverage.
    else if (a == "--orientation") cfg.planner.orientation = orientationModeFromString(next());
    else if (a == "--robust-shift") cfg.planner.robust_shift = std::stod(next());
    else if (a == "--robust-tilt-deg") cfg.planner.robust_tilt_deg = std::stod(next());
    else if (a == "--robust-com-offset") cfg.planner.robust_com_offset = std::stod(next());
    else if (a == "--robust-min-share") cfg.planner.robust_min_share = std::stod(next());
    else if (a == "--robust-min-share-hanging") cfg.planner.robust_min_share_hanging = std::stod(next());
    else if (a == "--no-robust-check") cfg.planner.robust_check = false;
    else if (a == "--robust-recheck-caught") cfg.planner.robust_recheck_caught = true;
    else if (a == "--no-robust-recheck-caught") cfg.planner.robust_recheck_caught = false;
    else if (a == "--rock-settle") cfg.planner.rock_settle = true;
    else if (a == "--no-rock-settle") cfg.planner.rock_settle = false;
    else if (a == "--closed-scan") cfg.planner.closed_scan = true;
    else if (a == "--exact-mesh") cfg.planner.closed_scan = false;
    else usage(("unknown argument " + a).c_str());
  }
  if (out.empty()) usage("--out is required");
  if (plots.empty()) plots = out;
  // Made before the long run, so that a path that cannot be written fails now, not at the end.
  for (const std::string& dir : {out, plots}) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) usage(("cannot create the directory " + dir + ": " + ec.message()).c_str());
  }

  if (!scan_areas.empty())
    return runBestPoseSuite(scanPairs(data, scan_areas), filters, out, "scans",
                            "Planned on the scans (DATA/scans), checked in Bullet on the true meshes; best = the "
                            "best stable pose stays put (released 2 mm above: moved < 1 cm, turned < 5 deg); "
                            "top-3 = the three best stable poses.",
                            cfg);
  if (hanging) {
    // Hanging poses only; a pendulum settles with light damping (air, the joint).
    cfg.planner.placement = PlacementKind::kHanging;
    cfg.validator = forHanging(cfg.validator);
    return runBestPoseSuite(hangingPairs(data), filters, out, "hanging",
                            "Planned with placement hanging (scans planned on, checked on the true mug), "
                            "checked in Bullet (damping 0.3, 3 s); best = the best stable pose still hangs "
                            "(released 2 mm above: centre of mass moved < 1 cm, dropped < 5 mm, any turn); "
                            "top-3 = the three best stable poses.",
                            cfg);
  }

  std::vector<ScenePair> pairs;
  for (const auto& p : defaultPairs(data)) {
    bool keep = filters.empty();
    for (const auto& f : filters) keep = keep || p.name.find(f) != std::string::npos;
    if (keep) pairs.push_back(p);
  }
  if (data.empty() || pairs.empty()) std::fprintf(stderr, "note: no shared data, built-in scenes only\n");
  std::fprintf(stderr, "%zu pairs, holes variants: %zu\n", pairs.size(), holes.size());

  // Full meshes: planner + validation + drops.
  std::vector<SceneResult> full;
  for (const auto& p : pairs) {
    SceneResult r = runScene(p, cfg);
    const std::string both = cfg.mujoco ? "  MuJoCo " + std::to_string(r.confirmed_mujoco) + "/" +
                                              std::to_string(r.validated) + " both " + std::to_string(r.confirmed_both)
                                        : std::string();
    std::fprintf(stderr, "%-40s plan %7.1f ms  fp %3d  stable %2d  confirmed %d/%d%s  drops rest %d/%zu"
                 " (%.1f ms)  %s\n", p.name.c_str(), r.stats.total_ms, r.stats.floor_points_total,
                 r.stable, r.confirmed, r.validated, both.c_str(), r.drops_at_rest, r.drops.size(), r.drop_ms_mean,
                 r.error.c_str());
    full.push_back(std::move(r));
  }
  // Holes: plan on the holey mesh, validate on the full one; no drops.
  std::vector<std::vector<SceneResult>> holey;
  for (double f : holes) {
    SuiteConfig hc = cfg;
    hc.hole_fraction = f;
    hc.max_drops = 0;
    std::vector<SceneResult> rs;
    for (const auto& p : pairs) {
      SceneResult r = runScene(p, hc);
      std::fprintf(stderr, "%-40s %s confirmed %d/%d %s\n", p.name.c_str(), r.variant.c_str(),
                   r.confirmed, r.validated, r.error.c_str());
      rs.push_back(std::move(r));
    }
    holey.push_back(std::move(rs));
  }
  std::vector<SceneResult> all = full;
  for (const auto& rs : holey) all.insert(all.end(), rs.begin(), rs.end());
  writeScenesCsv(all, out + "/scenes.csv");
  writeChecksCsv(all, out + "/checks.csv");
  writeDropsCsv(all, out + "/drops.csv");

  std::ostringstream md;
  md << "| suite | scenes | confirmed-stable precision | coverage | median plan ms | "
        "median first stable ms | planner ms / floor pt | Bullet ms / drop | speed-up |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const SuiteSummary sf = summarize(full);
  md << markdownSummary(sf, "full meshes") << "\n";
  for (size_t k = 0; k < holes.size(); ++k)
    md << markdownSummary(summarize(holey[k]),
                          std::to_string(static_cast<int>(std::lround(holes[k] * 100))) +
                              "% holes (plan holey, validate full)")
       << "\n";
  md << "\n";

  // Precision per scene (full and each holes variant).
  {
    std::vector<std::string> labels;
    std::vector<Series> ser(1 + holes.size());
    ser[0].name = "full mesh";
    for (size_t k = 0; k < holes.size(); ++k)
      ser[k + 1].name = std::to_string(static_cast<int>(std::lround(holes[k] * 100))) + "% holes";
    for (size_t i = 0; i < full.size(); ++i) {
      labels.push_back(full[i].pair.name);
      auto val = [](const SceneResult& r) {
        return r.validated ? r.precision() : std::numeric_limits<double>::quiet_NaN();
      };
      ser[0].y.push_back(val(full[i]));
      for (size_t k = 0; k < holes.size(); ++k) ser[k + 1].y.push_back(val(holey[k][i]));
    }
    plotBars(plots + "/precision_per_scene.png",
             "Confirmed-stable precision per scene (Bullet, 2 s, <1 cm, <5 deg)",
             "confirmed / validated", labels, ser, 0.0, 1.0, 0.97);
  }

  if (do_fig6 && !data.empty()) {
    const std::vector<Fig6Row> rows = fig6(data, cfg);
    std::ostringstream csv;  // written whole below (infra/output_file.h)
    csv << "triangles,setup,floor_points,first_contact,contact_points,tilt_vertex,tilt_edge,stability,"
           "local_optimisation,total_ms,per_floor_point_ms\n";
    md << "Time per planner step (ms, median of 3) against object triangles, YCB mug decimated by "
          "vertex clustering, on books_stack:\n\n"
       << "| triangles | setup | floor points | first contact | contact points | tilt vertex | tilt edge |"
          " stability | local opt. | total | per floor pt |\n"
       << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    std::vector<double> x;
    std::vector<Series> ser = {{"setup", {}}, {"floor points", {}},  {"first contact", {}}, {"contact points", {}},
                               {"tilt (vertex)", {}}, {"tilt (edge)", {}},   {"stability", {}},
                               {"local optimisation", {}}, {"total", {}}};
    for (const auto& r : rows) {
      const StepTimes& s = r.steps;
      csv << r.triangles << ',' << s.setup << ',' << s.floor_points << ',' << s.first_contact << ','
          << s.contact_points << ',' << s.tilt_vertex << ',' << s.tilt_edge << ',' << s.stability
          << ',' << s.local_optimisation << ',' << r.total_ms << ',' << r.per_floor_point_ms << '\n';
      char line[512];
      std::snprintf(line, sizeof line,
                    "| %d | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.1f | %.2f |\n",
                    r.triangles, s.setup, s.floor_points, s.first_contact, s.contact_points, s.tilt_vertex,
                    s.tilt_edge, s.stability, s.local_optimisation, r.total_ms,
                    r.per_floor_point_ms);
      md << line;
      x.push_back(r.triangles);
      const double v[] = {s.setup, s.floor_points, s.first_contact, s.contact_points, s.tilt_vertex,
                          s.tilt_edge,    s.stability,     s.local_optimisation, r.total_ms};
      for (size_t k = 0; k < ser.size(); ++k) ser[k].y.push_back(v[k]);
    }
    md << "\n";
    place_planner::writeOutputFile(out + "/fig6.csv", csv.str());
    plotLines(plots + "/fig6_step_times.png",
              "Planner time per step vs object triangles (mug on books_stack)",
              "object triangles (vertex clustering of the 16k YCB mug)", "ms (median of 3)", x, ser);
  }

  md << "Per scene (full meshes):\n\n" << markdownTable(full) << "\n";
  for (size_t k = 0; k < holes.size(); ++k)
    md << "Per scene, " << static_cast<int>(std::lround(holes[k] * 100)) << "% holes:\n\n"
       << markdownTable(holey[k]) << "\n";
  place_planner::writeOutputFile(out + "/results.md", md.str());
  std::cout << md.str().substr(0, md.str().find("\n\n")) << "\n";
  return sf.errors == sf.scenes ? 1 : 0;
}
