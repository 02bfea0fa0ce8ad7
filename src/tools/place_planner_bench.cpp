// Google Benchmark of the planner at the paper's workload (Section VII-C): about 140 floor
// points, max 5 rotations, the mug decimated to 200, 500 and 1000 triangles, on books_stack
// and dish_rack from ../shared/data; and planned on scans (../shared/data/scans: the mug seen from
// above on books_stack seen from the robot's head, 20,000 triangles), as a robot plans. Counters:
// time to the first stable candidate, floor points, tree nodes, stable candidates and time per
// batched step (ms). "cold" rebuilds the area's
// model every iteration; "warm" reuses it (a robot placing several objects on one area).
//
//   place_planner_bench --data ../shared/data [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>

#include "place_planner/infra/output_file.h"
#include "place_planner/infra/scenes.h"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/search/floor_points.h"
#include "place_planner/infra/mesh_io.h"
#include "place_planner/planner.h"
#include "place_planner/validation/mesh_variants.h"

using namespace place_planner;

namespace {

std::string g_data = "../shared/data";
constexpr int kTargetFloorPoints = 140;

const Mesh* mesh(const std::string& key) {
  static std::map<std::string, std::unique_ptr<Mesh>> cache;
  auto it = cache.find(key);
  if (it != cache.end()) return it->second.get();
  std::unique_ptr<Mesh> m;
  try {
    const auto at = key.find('@');
    if (at == std::string::npos) {
      m = std::make_unique<Mesh>(loadMesh(g_data + "/" + key));
    } else {  // "tris@file": the file decimated to about tris triangles
      const Mesh full = loadMesh(g_data + "/" + key.substr(at + 1));
      m = std::make_unique<Mesh>(validation::decimateByClustering(full, std::stoi(key.substr(0, at))));
    }
  } catch (const std::exception&) {
    return nullptr;
  }
  return (cache[key] = std::move(m)).get();
}

// Spacing that gives about kTargetFloorPoints rays on the area (the paper's 140).
double spacingFor(const Mesh& area) {
  const AreaModel am = buildAreaModel(area, {0, 0, -1}, 0.003, 0.006, 0.006);
  double lo = 0.005, hi = 0.2;
  for (int i = 0; i < 30; ++i) {
    const double mid = std::sqrt(lo * hi);
    FloorPointParams p;
    p.d_vis = v3(0, 0, -1);
    p.spacing = mid;
    p.min_points = 1;
    const int n = static_cast<int>(floorPoints(am, p).points.size());
    (n > kTargetFloorPoints ? lo : hi) = mid;
  }
  return hi;
}

void runPlan(benchmark::State& state, const std::string& area_file, bool cold,
             OrientationMode mode = OrientationMode::kAuto, BackendKind backend = BackendKind::kCpu,
             const std::string& object_file = "") {
  std::string why;
  if (backend == BackendKind::kCuda && !cuda::available(&why)) {
    state.SkipWithError(("no usable GPU: " + why).c_str());
    return;
  }
  const int tris = static_cast<int>(state.range(0));
  const Mesh* object = !object_file.empty() ? mesh(object_file)
                       : tris >= 1000      ? mesh("objects/mug_ycb025_1k.ply")
                                           : mesh(std::to_string(tris) + "@objects/mug_ycb025.ply");
  const Mesh* area = mesh(area_file);
  if (!object || !area) {
    state.SkipWithError(("../shared/data not found at " + g_data).c_str());
    return;
  }
  PlannerConfig cfg;
  cfg.floor_point_spacing = spacingFor(*area);
  cfg.threads = 2;
  cfg.max_rotations = 5;
  cfg.orientation = mode;
  cfg.backend = backend;
  static const Planner planner;  // keeps the area's model between iterations (warm runs)
  PlanResult r;
  StepTimes sum;
  double first = 0, robust = 0;
  for (auto _ : state) {
    if (cold) planner.clearAreaCache();
    r = planner.plan(*object, *area, cfg);
    const StepTimes& s = r.stats.steps;
    robust += r.stats.robustness_ms;
    sum.setup += s.setup;
    sum.first_contact += s.first_contact;
    sum.contact_points += s.contact_points;
    sum.tilt_vertex += s.tilt_vertex;
    sum.tilt_edge += s.tilt_edge;
    sum.stability += s.stability;
    first += r.stats.first_stable_ms;
  }
  const double n = static_cast<double>(state.iterations());
  int stable = 0;
  for (const auto& c : r.candidates) stable += c.stable;
  state.counters["area_tris"] = static_cast<double>(area->triangles.size());
  state.counters["object_tris"] = static_cast<double>(object->triangles.size());
  state.counters["floor_points"] = r.stats.floor_points_total;
  state.counters["tree_nodes"] = static_cast<double>(r.stats.tree_nodes);
  state.counters["stable"] = stable;
  state.counters["first_stable_ms"] = first / n;
  state.counters["setup_ms"] = sum.setup / n;
  state.counters["distance_ms"] = sum.first_contact / n;
  state.counters["contacts_ms"] = sum.contact_points / n;
  state.counters["vertex_rot_ms"] = sum.tilt_vertex / n;
  state.counters["edge_rot_ms"] = sum.tilt_edge / n;
  state.counters["stability_ms"] = sum.stability / n;
  state.counters["robustness_ms"] = robust / n;
  state.counters["roots"] = r.stats.roots_total;
}

void BM_BooksStackWarm(benchmark::State& s) { runPlan(s, "areas/books_stack.ply", false); }
void BM_BooksStackCold(benchmark::State& s) { runPlan(s, "areas/books_stack.ply", true); }
// The paper's workload on scans (its input is a scan): the mug's scan from above (bottom never
// seen) on the scan of books_stack from the robot's head, checked on the true meshes by
// place_planner_suite --scans. Cold: the area's model each time; warm: kept.
void BM_BooksStackScanCold(benchmark::State& s) {
  runPlan(s, "scans/areas/books_stack_scan.ply", true, OrientationMode::kAuto, BackendKind::kCpu,
          "scans/objects/mug_ycb025_upper_scan.ply");
}
void BM_BooksStackScanWarm(benchmark::State& s) {
  runPlan(s, "scans/areas/books_stack_scan.ply", false, OrientationMode::kAuto, BackendKind::kCpu,
          "scans/objects/mug_ycb025_upper_scan.ply");
}
void BM_BooksStackPrincipalAxis(benchmark::State& s) {
  runPlan(s, "areas/books_stack.ply", true, OrientationMode::kPrincipalAxis);
}
// The same workloads on the GPU (per-kernel times in the counters, as for the CPU).
void BM_BooksStackCudaCold(benchmark::State& s) {
  runPlan(s, "areas/books_stack.ply", true, OrientationMode::kAuto, BackendKind::kCuda);
}
void BM_BooksStackCudaPrincipalAxis(benchmark::State& s) {
  runPlan(s, "areas/books_stack.ply", true, OrientationMode::kPrincipalAxis, BackendKind::kCuda);
}
// An area approached from the side: the built-in shelf unit (scenes::shelfUnit, 15k triangles,
// 2.4 m tall, open to -y), the 1k mug along d_vis = +y, about 200 floor points, cold.
void shelfFromSide(benchmark::State& state, BackendKind backend) {
  std::string why;
  if (backend == BackendKind::kCuda && !cuda::available(&why)) {
    state.SkipWithError(("no usable GPU: " + why).c_str());
    return;
  }
  const Mesh* object = mesh("objects/mug_ycb025_1k.ply");
  if (!object) {
    state.SkipWithError(("../shared/data not found at " + g_data).c_str());
    return;
  }
  static const Mesh shelf = scenes::shelfUnit();
  PlannerConfig cfg;
  cfg.approach = Eigen::Vector3d(0, 1, 0);
  cfg.floor_point_spacing = 0.11;
  cfg.threads = 2;
  cfg.backend = backend;
  static const Planner planner;
  PlanResult r;
  double contacts = 0, setup = 0;
  for (auto _ : state) {
    planner.clearAreaCache();
    r = planner.plan(*object, shelf, cfg);
    contacts += r.stats.steps.contact_points;
    setup += r.stats.steps.setup;
  }
  const double n = static_cast<double>(state.iterations());
  int stable = 0;
  for (const auto& c : r.candidates) stable += c.stable;
  state.counters["area_tris"] = static_cast<double>(shelf.triangles.size());
  state.counters["floor_points"] = r.stats.floor_points_total;
  state.counters["stable"] = stable;
  state.counters["first_stable_ms"] = r.stats.first_stable_ms;
  state.counters["setup_ms"] = setup / n;
  state.counters["contacts_ms"] = contacts / n;
}
void BM_ShelfFromSideCold(benchmark::State& s) { shelfFromSide(s, BackendKind::kCpu); }
void BM_ShelfFromSideCudaCold(benchmark::State& s) { shelfFromSide(s, BackendKind::kCuda); }
void BM_DishRackWarm(benchmark::State& s) { runPlan(s, "areas/dish_rack.ply", false); }
void BM_DishRackCold(benchmark::State& s) { runPlan(s, "areas/dish_rack.ply", true); }

}  // namespace

BENCHMARK(BM_BooksStackWarm)->Arg(200)->Arg(500)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BooksStackCold)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BooksStackScanCold)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BooksStackScanWarm)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BooksStackPrincipalAxis)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BooksStackCudaCold)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BooksStackCudaPrincipalAxis)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DishRackWarm)->Arg(200)->Arg(500)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DishRackCold)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShelfFromSideCold)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShelfFromSideCudaCold)->Unit(benchmark::kMillisecond)->UseRealTime();

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "--data") && i + 1 < argc) g_data = argv[++i];
  // --benchmark_out=FILE follows the project's output-file rules (infra/output_file.h): Google
  // Benchmark writes a temporary file beside it, which then replaces it (or is copied into a
  // device or FIFO).
  int out_arg = -1;
  for (int i = 1; i < argc; ++i)
    if (!std::strncmp(argv[i], "--benchmark_out=", 16)) out_arg = i;
  try {
    if (out_arg < 0) {
      benchmark::Initialize(&argc, argv);
      benchmark::RunSpecifiedBenchmarks();
    } else {
      place_planner::produceOutputFile(argv[out_arg] + 16, [&](const std::string& temp) {
        std::string arg = "--benchmark_out=" + temp;
        argv[out_arg] = arg.data();
        benchmark::Initialize(&argc, argv);
        benchmark::RunSpecifiedBenchmarks();
      });
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "place_planner_bench: %s\n", e.what());
    return 4;
  }
  benchmark::Shutdown();
  return 0;
}
