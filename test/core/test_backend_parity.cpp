// nvblox style: the CUDA backend gives the CPU backend's answers, kernel by kernel
// and plan by plan. The query sets are checked on the CPU first (they must hit), so the parity
// tests cannot pass on queries that find nothing. Without a GPU they skip and say why.
#include <Eigen/Geometry>
#include <algorithm>
#include <tuple>

#include "place_planner/infra/backend.h"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/infra/mesh_io.h"
#include "place_planner/kernels/batched_steps.h"
#include "place_planner/planner.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {

struct Scene {
  std::string name;
  Mesh object, area;
};

std::vector<Scene> scenesToCompare() {
  std::vector<Scene> s = {{"mug on binders", scenes::mug(), scenes::binderStack()},
                          {"pen in dish rack", scenes::pen(), scenes::dishRack()}};
  if (test::haveSharedData()) {
    const std::string d = test::sharedData();
    const Mesh mug = loadMesh(d + "/objects/mug_ycb025_1k.ply");
    s.push_back({"ycb mug on books_stack", mug, loadMesh(d + "/areas/books_stack.ply")});
    s.push_back({"ycb mug in bin", mug, loadMesh(d + "/areas/bin.ply")});
  }
  return s;
}

// The models every comparison builds from a scene, and the tilt parameters.
struct Models {
  explicit Models(const Scene& s)
      : om(buildObjectModel(s.object, 0.0015)), am(buildAreaModel(s.area, {0, 0, -1}, 0.002, 0.0035, 0.0035)) {}
  ObjectModel om;
  AreaModel am;
  TiltParams tp{0.002, 1e-6};
};

// Queries around the area's top: poses above it (distance), just touching (contacts) and
// tilting about axes through points on it (rotations), in many orientations.
struct Queries {
  std::vector<TranslationQuery> t;
  std::vector<RotationQuery> r;
  std::vector<Rigid> contact;
};

Queries queriesFor(const ObjectModel& om, const AreaModel& am, Backend& cpu) {
  Queries q;
  const Aabb b = am.bounds;
  for (int i = 0; i < 48; ++i) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = Eigen::AngleAxisd(0.37 * i, Eigen::Vector3d(1, 2 + i % 3, 3).normalized()).toRotationMatrix();
    const double u = (i % 8 + 0.5) / 8.0, v = (i / 8 + 0.5) / 6.0;
    X.translation() = Eigen::Vector3d(b.lo.x + u * (b.hi.x - b.lo.x), b.lo.y + v * (b.hi.y - b.lo.y), b.hi.z + 0.3);
    q.t.push_back({toRigid(X), v3(0, 0, -1), 1.0});
  }
  // Each pose dropped to its first contact: the contact and rotation queries.
  std::vector<double> t;
  cpu.distance(q.t, t);
  for (size_t i = 0; i < t.size(); ++i) {
    if (t[i] >= kInf) continue;
    Rigid X = q.t[i].X_GO;
    X.t = X.t + t[i] * v3(0, 0, -1);
    q.contact.push_back(X);
    const V3 c = apply(X, om.com);
    for (const V3& axis : {v3(1, 0, 0), v3(0, 1, 0), normalized(v3(1, 1, 0))})
      q.r.push_back({X, v3(c.x, c.y, c.z - om.bounding_radius * 0.5), axis});
  }
  return q;
}

using ContactKey = std::tuple<long, long, long>;
std::vector<std::pair<ContactKey, SphereContact>> sorted(const std::vector<SphereContact>& c) {
  std::vector<std::pair<ContactKey, SphereContact>> out;
  for (const auto& s : c)
    out.push_back({ContactKey{std::lround(s.p.x * 1e7), std::lround(s.p.y * 1e7), std::lround(s.p.z * 1e7)}, s});
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

double capped(double v) { return std::min(v, 1e3); }

struct Host {  // the host models, as the CPU backend reads them
  template <typename T>
  const T* operator()(const std::vector<T>& v) const {
    return v.empty() ? nullptr : v.data();
  }
};

}  // namespace

TEST(BackendParity, QueriesHitOnTheCpu) {
  for (const Scene& s : scenesToCompare()) {
    SCOPED_TRACE(s.name);
    const Models m(s);
    const ObjectModel& om = m.om;
    const AreaModel& am = m.am;
    auto cpu = makeCpuBackend(om, am, m.tp, 2);
    const Queries q = queriesFor(om, am, *cpu);
    EXPECT_GE(q.contact.size(), q.t.size() * 3 / 4) << "distance queries missed the area";
    std::vector<std::vector<SphereContact>> c;
    cpu->contactPoints(q.contact, c);
    size_t touching = 0;
    for (const auto& v : c) touching += !v.empty();
    EXPECT_GE(touching, q.contact.size() * 3 / 4) << "dropped poses without contacts";
    std::vector<AnglePair> a, e;
    cpu->vertexSurfaceRotation(q.r, a);
    cpu->edgeEdgeRotation(q.r, e);
    size_t finite = 0;
    for (size_t i = 0; i < a.size(); ++i) finite += a[i].ccw < kInf || a[i].cw < kInf || e[i].ccw < kInf || e[i].cw < kInf;
    EXPECT_GE(finite, a.size() / 2) << "rotations found no contact";
  }
}

// The GPU splits each distance and tilt answer into 2^levels work items over subtrees of its
// BVHs, met by an atomic minimum, the tilts one angle window per launch (batched_steps.h). Run
// here on the host, item by item, the split answers are the whole ones, value by value, for
// every split the GPU may use.
TEST(BackendParity, SplitWorkItemsGiveTheWholeAnswers) {
  for (const Scene& s : scenesToCompare()) {
    SCOPED_TRACE(s.name);
    const Models m(s);
    const TiltParams& tp = m.tp;
    const Queries q = queriesFor(m.om, m.am, *makeCpuBackend(m.om, m.am, tp, 2));
    const ObjectView o = makeObjectView(m.om, Host{});
    const AreaView a = makeAreaView(m.am, Host{});
    auto run = [](size_t n, int levels, double* out, const auto& item) {
      for (size_t i = 0; i < n; ++i) FillItem{out, kInf}(i);
      for (size_t k = 0; k < (n << levels); ++k) item(k);
    };
    // As the launcher runs a split tilt: one angle window after the other.
    auto tilts = [&](size_t n, int levels, double* out, auto item) {
      for (size_t i = 0; i < n; ++i) FillItem{out, kInf}(i);
      for (int w = 0; w < kNumAngleWindows; ++w) {
        item.window = w;
        for (size_t k = 0; k < (n << levels); ++k) item(k);
      }
    };
    std::vector<double> t0(q.t.size()), v0(2 * q.r.size()), e0(2 * q.r.size());
    run(t0.size(), 0, t0.data(), DistanceItem{o, a, q.t.data(), t0.data(), 0});
    run(v0.size(), 0, v0.data(), RotationItem<true>{o, a, q.r.data(), v0.data(), tp, 0});
    run(e0.size(), 0, e0.data(), RotationItem<false>{o, a, q.r.data(), e0.data(), tp, 0});
    ASSERT_GT(std::count_if(t0.begin(), t0.end(), [](double x) { return x < kInf; }), 0);
    for (const int levels : {1, 3, 5, 8}) {
      SCOPED_TRACE("levels " + std::to_string(levels));
      std::vector<double> t(t0.size()), v(v0.size()), e(e0.size());
      run(t.size(), levels, t.data(), DistanceItem{o, a, q.t.data(), t.data(), levels});
      tilts(v.size(), levels, v.data(), RotationItem<true>{o, a, q.r.data(), v.data(), tp, levels});
      tilts(e.size(), levels, e.data(), RotationItem<false>{o, a, q.r.data(), e.data(), tp, levels});
      for (size_t i = 0; i < t.size(); ++i) EXPECT_EQ(t[i], std::max(t0[i], 0.0)) << "distance " << i;
      for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], v0[i]) << "vertex/surface tilt " << i;
      for (size_t i = 0; i < e.size(); ++i) EXPECT_EQ(e[i], e0[i]) << "edge/edge tilt " << i;
      // Contacts: each pose's, part after part, are the whole walk's, in the same order.
      const int cap = o.mesh.num_spheres;
      const size_t items = q.contact.size() << levels;
      std::vector<SphereContact> c0(q.contact.size() * cap), c(q.contact.size() * cap);
      std::vector<int> n0(q.contact.size()), n(items), first(items);
      const ContactItem whole{o, a, q.contact.data(), c0.data(), n0.data(), cap};
      const ContactItem split{o, a, q.contact.data(), c.data(), n.data(), cap, levels, first.data()};
      for (size_t i = 0; i < q.contact.size(); ++i) whole(i);
      for (size_t k = 0; k < items; ++k) split(k);
      size_t total = 0;
      for (size_t i = 0; i < q.contact.size(); ++i) {
        std::vector<V3> got;
        for (size_t k = i << levels; k < (i + 1) << levels; ++k)
          for (int m = 0; m < n[k]; ++m) got.push_back(c[i * cap + first[k] + m].p);
        ASSERT_EQ(got.size(), static_cast<size_t>(n0[i])) << "contacts of pose " << i;
        for (int m = 0; m < n0[i]; ++m) EXPECT_EQ(norm(got[m] - c0[i * cap + m].p), 0.0) << "pose " << i;
        total += got.size();
      }
      EXPECT_GT(total, 0u);
    }
  }
}

TEST(BackendParity, KernelsMatchValueByValue) {
  std::string why;
  if (!cuda::available(&why)) GTEST_SKIP() << "no usable GPU (" << why << "): the CUDA kernels cannot run here";
  for (const Scene& s : scenesToCompare()) {
    SCOPED_TRACE(s.name);
    const Models m(s);
    const ObjectModel& om = m.om;
    const AreaModel& am = m.am;
    const TiltParams& tp = m.tp;
    auto cpu = makeCpuBackend(om, am, tp, 2);
    auto gpu = makeCudaBackend(om, am, tp);
    const Queries q = queriesFor(om, am, *cpu);
    ASSERT_FALSE(q.contact.empty());
    // Same per-element code on both: equal up to the GPU's fused multiply-adds.
    constexpr double kTol = 1e-9;
    std::vector<double> tc, tg;
    cpu->distance(q.t, tc);
    gpu->distance(q.t, tg);
    for (size_t i = 0; i < tc.size(); ++i) EXPECT_NEAR(capped(tc[i]), capped(tg[i]), kTol) << "distance " << i;
    std::vector<AnglePair> vc, vg, ec, eg;
    cpu->vertexSurfaceRotation(q.r, vc);
    gpu->vertexSurfaceRotation(q.r, vg);
    cpu->edgeEdgeRotation(q.r, ec);
    gpu->edgeEdgeRotation(q.r, eg);
    for (size_t i = 0; i < q.r.size(); ++i) {
      EXPECT_NEAR(capped(vc[i].ccw), capped(vg[i].ccw), kTol) << "vertex ccw " << i;
      EXPECT_NEAR(capped(vc[i].cw), capped(vg[i].cw), kTol) << "vertex cw " << i;
      EXPECT_NEAR(capped(ec[i].ccw), capped(eg[i].ccw), kTol) << "edge ccw " << i;
      EXPECT_NEAR(capped(ec[i].cw), capped(eg[i].cw), kTol) << "edge cw " << i;
    }
    std::vector<std::vector<SphereContact>> cc, cg;
    cpu->contactPoints(q.contact, cc);
    gpu->contactPoints(q.contact, cg);
    for (size_t i = 0; i < cc.size(); ++i) {
      const auto a = sorted(cc[i]), b = sorted(cg[i]);
      ASSERT_EQ(a.size(), b.size()) << "pose " << i;
      for (size_t k = 0; k < a.size(); ++k) {
        EXPECT_NEAR(norm(a[k].second.p - b[k].second.p), 0.0, kTol);
        EXPECT_NEAR(norm(a[k].second.n - b[k].second.n), 0.0, 1e-7);
      }
    }
  }
}

TEST(BackendParity, PlansMatch) {
  std::string why;
  if (!cuda::available(&why)) GTEST_SKIP() << "no usable GPU (" << why << "): the CUDA backend cannot run here";
  for (const Scene& s : scenesToCompare()) {
    SCOPED_TRACE(s.name);
    PlannerConfig c;
    c.threads = 2;
    c.backend = BackendKind::kCpu;
    const PlanResult rc = Planner().plan(s.object, s.area, c);
    c.backend = BackendKind::kCuda;
    const PlanResult rg = Planner().plan(s.object, s.area, c);
    EXPECT_EQ(rg.stats.backend, "cuda");
    ASSERT_FALSE(rc.candidates.empty());
    ASSERT_EQ(rc.candidates.size(), rg.candidates.size());
    for (size_t i = 0; i < rc.candidates.size(); ++i) {
      const Candidate &a = rc.candidates[i], &b = rg.candidates[i];
      EXPECT_LT((a.X_WO.translation() - b.X_WO.translation()).norm(), 1e-4) << "candidate " << i;
      EXPECT_LT(Eigen::AngleAxisd(a.X_WO.linear().transpose() * b.X_WO.linear()).angle(), 1e-3) << "candidate " << i;
      EXPECT_EQ(a.stable, b.stable) << "candidate " << i;
    }
  }
}

TEST(BackendParity, DeviceFaultSendsAutoToTheCpuUntilReset) {
  cuda::markUnusable("test: simulated illegal address");
  std::string why;
  EXPECT_FALSE(cuda::available(&why));
#ifdef PLACE_PLANNER_HAVE_CUDA
  EXPECT_NE(why.find("simulated illegal address"), std::string::npos) << why;
  // auto plans on the CPU meanwhile; cuda asked for explicitly fails with the reason.
  PlannerConfig c;
  c.threads = 2;
  EXPECT_EQ(Planner().plan(scenes::mug(), scenes::table(), c).stats.backend, "cpu");
  c.backend = BackendKind::kCuda;
  try {
    Planner().plan(scenes::mug(), scenes::table(), c);
    ADD_FAILURE() << "backend cuda planned on a device marked unusable";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("simulated illegal address"), std::string::npos) << e.what();
  }
#endif
  cuda::resetDevice();
  why.clear();  // available() writes the reason only when it answers false
  cuda::available(&why);
  EXPECT_EQ(why.find("simulated illegal address"), std::string::npos) << "reset did not clear the fault: " << why;
}

// cudaDeviceReset frees every device allocation and limit: a planner whose area model was
// uploaded before the reset must upload it again, not read the freed copy.
TEST(BackendParity, PlansOnACachedAreaAfterAReset) {
  std::string why;
  if (!cuda::available(&why)) GTEST_SKIP() << "no usable GPU (" << why << "): the CUDA backend cannot run here";
  Planner planner;  // one planner: its host cache keeps the area model (and its id) across the reset
  PlannerConfig c;
  c.threads = 2;
  c.backend = BackendKind::kCuda;
  const PlanResult before = planner.plan(scenes::mug(), scenes::table(), c);
  ASSERT_FALSE(before.candidates.empty());
  cuda::resetDevice();
  PlanResult after;
  ASSERT_NO_THROW(after = planner.plan(scenes::mug(), scenes::table(), c));
  EXPECT_EQ(after.stats.backend, "cuda");
  ASSERT_EQ(before.candidates.size(), after.candidates.size());
  for (size_t i = 0; i < before.candidates.size(); ++i)
    EXPECT_LT((before.candidates[i].X_WO.translation() - after.candidates[i].X_WO.translation()).norm(), 1e-9)
        << "candidate " << i;
  EXPECT_TRUE(cuda::available(&why)) << why;
}
