// Plans one object/area pair and checks each candidate in Bullet; optionally drops the object
// from the pre-placement pose above the floor points (the paper's baseline).
//
//   place_planner_validate --object SRC --area SRC [--friction MU] [--all] [--drops N]
//                          [--holes FRACTION] [--threads N]
// SRC: a mesh file or builtin:<name> (table, dish_rack, open_box, binder_stack, mug, plate, pen,
// cube). Exit status 0 when every validated candidate was confirmed, 1 otherwise, 2 on misuse.
#include <cstdio>
#include <cstdlib>
#include <string>

#include <Eigen/Geometry>

#include "place_planner/validation/suite.h"

using namespace place_planner;
using namespace place_planner::validation;

int main(int argc, char** argv) {
  std::string object, area;
  SuiteConfig cfg;
  cfg.max_drops = 0;
  bool all = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has = i + 1 < argc;
    if (a == "--object" && has) object = argv[++i];
    else if (a == "--area" && has) area = argv[++i];
    else if (a == "--friction" && has) cfg.planner.friction = std::atof(argv[++i]);
    else if (a == "--drops" && has) cfg.max_drops = std::atoi(argv[++i]);
    else if (a == "--holes" && has) cfg.hole_fraction = std::atof(argv[++i]);
    else if (a == "--threads" && has) cfg.planner.threads = std::atoi(argv[++i]);
    else if (a == "--all") all = true;
    else {
      std::fprintf(stderr,
                   "usage: place_planner_validate --object SRC --area SRC [--friction MU] [--all]"
                   " [--drops N] [--holes F] [--threads N]\n");
      return 2;
    }
  }
  if (object.empty() || area.empty()) {
    std::fprintf(stderr, "--object and --area are required\n");
    return 2;
  }
  if (all) cfg.max_validated = 1000;
  const SceneResult r = runScene({object + "@" + area, object, area}, cfg);
  if (!r.error.empty()) {
    std::fprintf(stderr, "error: %s\n", r.error.c_str());
    return 2;
  }
  const ValidatorConfig& v = cfg.validator;
  std::printf("planner: %.1f ms (first stable %.1f ms), %d floor points, %d candidates, %d stable\n",
              r.stats.total_ms, r.stats.first_stable_ms, r.stats.floor_points_total, r.candidates,
              r.stable);
  std::printf("bullet: %.0f s at 1/%.0f s, %d iterations, mu %.2f; confirmed = moved < %.0f mm and"
              " turned < %.0f deg\n",
              v.settle_time, 1.0 / v.time_step, v.solver_iterations, cfg.planner.friction,
              v.max_translation * 1000, v.max_rotation_deg);
  std::printf("%4s %7s %9s %9s %10s  %s\n", "rank", "quality", "moved mm", "turned", "result",
              "goal position (m)");
  for (const auto& c : r.checks) {
    const Eigen::Vector3d t = c.X_WO.translation();
    std::printf("%4d %7.3f %9.2f %9.2f %10s  (%.3f, %.3f, %.3f)\n", c.rank, c.quality,
                c.check.moved_m * 1000, c.check.turned_deg,
                c.check.confirmed ? "confirmed" : "REJECTED", t.x(), t.y(), t.z());
  }
  std::printf("precision: %d / %d\n", r.confirmed, r.validated);
  if (!r.drops.empty())
    std::printf("drops: %d at rest, %d fell off, of %zu; %.1f ms mean (%.1f median) per drop;"
                " planner %.2f ms per floor point; speed-up %.1fx\n",
                r.drops_at_rest, r.drops_fell, r.drops.size(), r.drop_ms_mean, r.drop_ms_median,
                r.planner_ms_per_floor_point, r.speedup());
  return r.confirmed == r.validated ? 0 : 1;
}
