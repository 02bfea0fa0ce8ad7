// One Planner shared by several threads (planner.h: plan() is const, the area-model cache is
// guarded): four threads plan at once on one Planner, on the same area and on different areas,
// and each answer is the one a single thread gets. Run under ThreadSanitizer by
// scripts/sanitizer_tests, which makes any data race a failure.
#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "place_planner/infra/scenes.h"
#include "place_planner/planner.h"

using namespace place_planner;

namespace {

struct Job {
  Mesh object, area;
};

void expectSame(const PlanResult& a, const PlanResult& b, const std::string& what) {
  ASSERT_EQ(a.candidates.size(), b.candidates.size()) << what;
  ASSERT_GT(a.candidates.size(), 0u) << what << ": nothing planned";
  EXPECT_GT(a.stableCount(), 0) << what << ": nothing stable";
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_TRUE(a.candidates[i].X_WO.isApprox(b.candidates[i].X_WO, 1e-12)) << what << " #" << i;
    EXPECT_EQ(a.candidates[i].stable, b.candidates[i].stable) << what << " #" << i;
    EXPECT_EQ(a.candidates[i].quality, b.candidates[i].quality) << what << " #" << i;
  }
  EXPECT_EQ(a.stats.tree_nodes, b.stats.tree_nodes) << what;
}

// Plans every job on four threads sharing `shared`, each thread taking job (thread % jobs).
void planConcurrently(const std::vector<Job>& jobs, const PlannerConfig& cfg) {
  std::vector<PlanResult> alone;
  for (const Job& j : jobs) alone.push_back(Planner().plan(j.object, j.area, cfg));
  const Planner shared;
  constexpr int kThreads = 4;
  std::vector<PlanResult> together(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      const Job& j = jobs[static_cast<size_t>(t) % jobs.size()];
      together[static_cast<size_t>(t)] = shared.plan(j.object, j.area, cfg);
    });
  }
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t)
    expectSame(together[static_cast<size_t>(t)], alone[static_cast<size_t>(t) % jobs.size()],
               "thread " + std::to_string(t));
}

PlannerConfig smallConfig() {
  PlannerConfig cfg;
  cfg.floor_point_spacing = 0.1;  // a few floor points: the test is about sharing, not search
  cfg.threads = 2;                // each plan also uses the worker pool (busy: runs serially)
  return cfg;
}

}  // namespace

TEST(Threads, OnePlannerFourThreadsSameArea) {
  planConcurrently({{scenes::mug(), scenes::table()}}, smallConfig());
}

TEST(Threads, OnePlannerFourThreadsDifferentAreas) {
  planConcurrently({{scenes::mug(), scenes::table()},
                    {scenes::byName("cube"), scenes::binderStack()},
                    {scenes::mug(), scenes::binderStack()},
                    {scenes::byName("cube"), scenes::table()}},
                   smallConfig());
}
