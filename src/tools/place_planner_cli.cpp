// Placeholder until the planner lands: loads the built-in demo scene and prints mesh statistics.
#include <cstdio>

#include "place_planner/scenes.h"

int main() {
  using namespace place_planner;
  for (const auto& name : {"binder_stack", "mug"}) {
    const Mesh m = scenes::byName(name);
    const auto& p = m.properties;
    std::printf("%-14s %4zu patches %4zu triangles  area %.4f m^2  com (%.3f %.3f %.3f)\n", name,
                m.patches.size(), m.triangles.size(), p.surface_area, p.center_of_mass.x(),
                p.center_of_mass.y(), p.center_of_mass.z());
  }
  return 0;
}
