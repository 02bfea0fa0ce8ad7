// Shared-data lookup for the validation tests (same convention as test/core/test_helpers.h).
#pragma once
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>

#include "place_planner/infra/mesh_io.h"

namespace place_planner {
namespace validation_test {

inline std::string sharedData() { return PP_SHARED_DATA_DIR; }
// A mesh of ../shared/data by its path there ("objects/bowl_ycb024_1k.ply").
inline Mesh sharedMesh(const std::string& path) { return loadMesh(sharedData() + "/" + path); }
inline bool haveSharedData() {
  struct stat st;
  return stat((sharedData() + "/MANIFEST.tsv").c_str(), &st) == 0;
}
#define PP_VALIDATION_REQUIRE_SHARED_DATA()                                                   \
  if (!::place_planner::validation_test::haveSharedData())                                    \
  GTEST_SKIP() << "../shared/data not found at "                                              \
               << ::place_planner::validation_test::sharedData()                              \
               << ": the real-mesh tests need it beside the repository"

}  // namespace validation_test
}  // namespace place_planner
