// Analytic meshes and helpers shared by the core tests.
#pragma once
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <sys/stat.h>

#include "place_planner/model/mesh.h"
#include "place_planner/infra/scenes.h"

namespace place_planner {
namespace test {

inline std::string sharedData() { return PP_SHARED_DATA_DIR; }
inline bool haveSharedData() {
  struct stat st;
  return stat((sharedData() + "/MANIFEST.tsv").c_str(), &st) == 0;
}
#define PP_REQUIRE_SHARED_DATA()                                                            \
  if (!::place_planner::test::haveSharedData())                                             \
  GTEST_SKIP() << "../shared/data not found at " << ::place_planner::test::sharedData()     \
               << ": the real-mesh tests need it beside the repository"

}  // namespace test
}  // namespace place_planner
