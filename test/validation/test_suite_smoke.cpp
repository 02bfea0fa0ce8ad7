// Smoke version of the benchmark suite: a few scenes, planner and Bullet in
// this process; fails when the planner's stable poses stop being confirmed by physics.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "place_planner/validation/suite.h"
#include "validation_test_helpers.h"

namespace place_planner {
namespace validation {
namespace {

// confirmed-stable precision >= 0.95 on the smoke scenes (measured 1.0: 35 of 35 with
// the robustness check; the full suite's figures are in doc/validation.md).
constexpr double kMinSmokePrecision = 0.95;

SuiteConfig smokeConfig() {
  SuiteConfig c;
  c.max_validated = 5;
  c.max_drops = 2;
  return c;
}

void report(const SceneResult& r) {
  std::printf("[smoke] %-36s %-8s plan %.1f ms, %d stable, confirmed %d/%d, drops at rest %d/%zu\n",
              r.pair.name.c_str(), r.variant.c_str(), r.stats.total_ms, r.stable, r.confirmed,
              r.validated, r.drops_at_rest, r.drops.size());
  for (const auto& c : r.checks)
    if (!c.check.confirmed)
      std::printf("[smoke]   rank %d rejected: moved %.1f mm, turned %.1f deg\n", c.rank,
                  c.check.moved_m * 1000, c.check.turned_deg);
}

// The top-3 tally on seen surface counts only the checks the planner did not flag as resting on
// unseen surface, among the first three (a flagged pose that falls is reported apart).
TEST(SuiteSmoke, TopThreeOnSeenSurfaceLeavesOutFlaggedPoses) {
  SceneResult r;
  const SupportKind kinds[] = {SupportKind::kSeen, SupportKind::kCompleted, SupportKind::kSeen, SupportKind::kSeen};
  const bool confirmed[] = {true, false, false, true};
  for (int k = 0; k < 4; ++k) {
    CandidateCheck c;
    c.rank = k;
    c.support = kinds[k];
    c.check.confirmed = confirmed[k];
    r.checks.push_back(c);
  }
  int all = 0, seen = 0;
  EXPECT_EQ(r.confirmedOfTop(3, &all), 1);
  EXPECT_EQ(all, 3);
  EXPECT_EQ(r.confirmedSeenOfTop(3, &seen), 1);  // the fourth, seen and confirmed, is not in the top 3
  EXPECT_EQ(seen, 2);
}

TEST(SuiteSmoke, BuiltInScenesAreConfirmed) {
  std::vector<SceneResult> rs;
  for (const auto& p : std::vector<ScenePair>{
           {"builtin_cube@table", "builtin:cube", "builtin:table"},
           {"builtin_mug@table", "builtin:mug", "builtin:table"},
           {"builtin_mug@binder_stack", "builtin:mug", "builtin:binder_stack"}}) {
    rs.push_back(runScene(p, smokeConfig()));
    report(rs.back());
    ASSERT_TRUE(rs.back().error.empty()) << rs.back().error;
  }
  const SuiteSummary s = summarize(rs);
  EXPECT_GE(s.validated, 3) << "the planner returned too few stable poses to judge";
  EXPECT_GE(s.precision, kMinSmokePrecision) << s.confirmed << " / " << s.validated;
  // The cube dropped on the table comes to rest.
  EXPECT_GT(rs[0].drops_at_rest, 0);
}

TEST(SuiteSmoke, SharedDataScenesAreConfirmed) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const std::string d = validation_test::sharedData();
  std::vector<SceneResult> rs;
  for (const auto& p : std::vector<ScenePair>{
           {"mug_ycb025_1k@table", d + "/objects/mug_ycb025_1k.ply", d + "/areas/table.ply"},
           {"sugar_box_ycb004_1k@books_stack", d + "/objects/sugar_box_ycb004_1k.ply",
            d + "/areas/books_stack.ply"},
           {"bowl_ycb024_1k@bin", d + "/objects/bowl_ycb024_1k.ply", d + "/areas/bin.ply"}}) {
    rs.push_back(runScene(p, smokeConfig()));
    report(rs.back());
    ASSERT_TRUE(rs.back().error.empty()) << rs.back().error;
  }
  const SuiteSummary s = summarize(rs);
  EXPECT_GE(s.validated, 3);
  EXPECT_GE(s.precision, kMinSmokePrecision) << s.confirmed << " / " << s.validated;
}

TEST(SuiteSmoke, TenPercentHolesStillConfirmedOnTheFullMesh) {
  PP_VALIDATION_REQUIRE_SHARED_DATA();
  const std::string d = validation_test::sharedData();
  SuiteConfig c = smokeConfig();
  c.hole_fraction = 0.10;
  c.max_drops = 0;
  const SceneResult r =
      runScene({"mug_ycb025_1k@table", d + "/objects/mug_ycb025_1k.ply", d + "/areas/table.ply"}, c);
  report(r);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.variant, "holes_10");
  EXPECT_GE(r.validated, 1);
  EXPECT_GE(r.precision(), kMinSmokePrecision) << r.confirmed << " / " << r.validated;
}

}  // namespace
}  // namespace validation
}  // namespace place_planner
