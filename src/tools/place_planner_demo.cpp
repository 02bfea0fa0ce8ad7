// place_planner_demo: the planner on built-in scenes, no ROS and no data files needed.
// Prints the best placements of a mug on a stack of binders, a cube in a box, a plate on a table.
#include <cstdio>

#include "place_planner/planner.h"
#include "place_planner/infra/scenes.h"

int main() {
  using namespace place_planner;
  for (const auto& [object, area] : {std::pair<const char*, const char*>{"mug", "binder_stack"},
                                     {"cube", "open_box"},
                                     {"plate", "table"}}) {
    PlannerConfig config;
    config.max_candidates = 3;
    const PlanResult r = Planner().plan(scenes::byName(object), scenes::byName(area), config);
    std::printf("%s on %s: %d floor points, %ld poses evaluated, %.1f ms (first stable %.1f ms)\n",
                object, area, r.stats.floor_points_total, r.stats.tree_nodes, r.stats.total_ms,
                r.stats.first_stable_ms);
    for (const auto& c : r.candidates) {
      const Eigen::Vector3d p = c.X_WO.translation();
      const Eigen::Vector3d up = c.X_WO.linear().transpose() * Eigen::Vector3d::UnitZ();
      std::printf("  Q %.2f %-8s at (%.3f, %.3f, %.3f), object up = (%.2f, %.2f, %.2f), "
                  "%zu contacts, %zu intermediate poses\n",
                  c.quality, c.stable ? "stable" : "unstable", p.x(), p.y(), p.z(), up.x(), up.y(),
                  up.z(), c.contacts.size(), c.intermediate_poses.size());
    }
  }
  return 0;
}
