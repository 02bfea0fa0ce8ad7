// One kernel body, one launcher (Open3D style): the four batched steps of Section VII-C as
// work items (__host__ __device__ functors over the per-element code of placement_kernels.h),
// and the one Backend that runs them on a Device. A Device (CpuDevice in backend_cpu.cpp,
// CudaDevice in cuda/backend_cuda.cu) provides:
//   template <class F> void parallelFor(size_t n, const F& f);   // f(i) for i in [0, n)
//   template <class T> T* scratch(int slot, size_t n);           // reusable buffer (its memory)
//   template <class T> const T* upload(int slot, const std::vector<T>& host);
//   template <class T> void download(const T* dev, size_t n, T* host);
//   size_t preferredBatch(size_t spheres_per_pose) const;
//   int splitLevels() const;                                     // work items per answer: 2^levels
//   int contactSplitLevels() const;                              // the same for contact points
//   ObjectView object() const; AreaView area() const;           // views in its memory
//   void finish();                                               // waits, throws on a fault
// Frames: poses X_GO (object O into the area's gravity frame G), as in backend.h.
#pragma once
#include <string>
#include <vector>

#include "place_planner/infra/backend.h"

namespace place_planner {

// ------------------------------------------------------------------ views of the models
// One makeView for both memories: `up(vector)` returns the array's pointer where the kernels
// read it (the host vector's data, or a device copy).
template <typename Up>
MeshView makeMeshView(const MeshModel& m, Up&& up) {
  MeshView v;
  v.vertices = up(m.vertices);
  v.triangles = reinterpret_cast<const int*>(up(m.triangles));  // std::array<int, 3>: 3 ints each
  v.edges = reinterpret_cast<const int*>(up(m.edges));
  v.triangle_normals = up(m.triangle_normals);
  v.num_vertices = static_cast<int>(m.vertices.size());
  v.num_triangles = static_cast<int>(m.triangles.size());
  v.num_edges = static_cast<int>(m.edges.size());
  auto bvh = [&](const Bvh& b) { return BvhView{up(b.nodes), up(b.order), static_cast<int>(b.nodes.size())}; };
  v.triangle_bvh = bvh(m.triangle_bvh);
  v.edge_bvh = bvh(m.edge_bvh);
  v.vertex_bvh = bvh(m.vertex_bvh);
  v.sphere_centres = up(m.spheres.centres);
  v.sphere_normals = up(m.spheres.normals);
  v.num_spheres = static_cast<int>(m.spheres.centres.size());
  v.sphere_radius = m.spheres.radius;
  v.sphere_bvh = bvh(m.spheres.bvh);
  v.bounds = m.bounds;
  return v;
}

template <typename Up>
ObjectView makeObjectView(const ObjectModel& o, Up&& up) {
  return ObjectView{makeMeshView(o, up), o.com, o.bounding_radius};
}

template <typename Up>
AreaView makeAreaView(const AreaModel& a, Up&& up) {
  const HeightGrid& g = a.grid;
  return AreaView{makeMeshView(a, up), GridView{g.x0, g.y0, g.cell, g.nx, g.ny, g.collision_distance, g.contact_gap,
                                                up(g.start), up(g.items), up(g.max_contact_z)}};
}

// ------------------------------------------------------------------ work items
// With `levels` > 0 each answer is split into 2^levels parts (subtreeRoot), one work item each,
// item k = (answer << levels) | part, met by an atomic minimum in an answer filled with kInf
// first (FillItem): a GPU runs a few hundred poses per step, too few threads alone. 0: one item
// per answer (the CPU's workers are few; a whole tree prunes best).
PP_HD int partOf(size_t k, int levels) { return static_cast<int>(k & ((size_t{1} << levels) - 1)); }
// An answer, or one part's of it: stored, or met by the atomic minimum (a pose already
// touching, a distance under 0, as 0).
PP_HD void meet(double* answer, double v, int levels) {
  if (levels == 0) *answer = v;
  else if (v < kInf) atomicMinNonNegative(answer, maxv(v, 0.0));
}

struct DistanceItem {  // V-A: one translation query
  ObjectView o;
  AreaView a;
  const TranslationQuery* q;
  double* t;
  int levels = 0;
  PP_HD void operator()(size_t k) const {
    const size_t i = k >> levels;
    meet(t + i, firstContactDistance(o, a, q[i].X_GO, q[i].d, q[i].tmax, partOf(k, levels), levels), levels);
  }
};

// V-C.2: one (pose, direction) pair, j = 2 i (ccw) or 2 i + 1 (cw); split as DistanceItem, and
// then one angle window per launch (`window`), skipped where an earlier one found the contact:
// the whole tree stops at the first window with a hit, and a part alone would search them all.
template <bool kVertex>
struct RotationItem {
  ObjectView o;
  AreaView a;
  const RotationQuery* q;
  double* out;
  TiltParams tp;
  int levels = 0;
  int window = -1;  // -1: every window
  PP_HD void operator()(size_t k) const {
    const size_t j = k >> levels, i = j / 2;
    const int part = partOf(k, levels);
    if (window > 0 && out[j] <= angleWindowStart(window)) return;
    const int sigma = j % 2 ? -1 : 1;
    const double limit = sigma > 0 ? q[i].limit_ccw : q[i].limit_cw;
    const double th = kVertex ? vertexSurfaceAngle(o, a, q[i].X_GO, q[i].s_A, q[i].d_A, sigma, tp, limit, part, levels, window)
                              : edgeEdgeAngle(o, a, q[i].X_GO, q[i].s_A, q[i].d_A, sigma, tp, limit, part, levels, window);
    meet(out + j, th, levels);
  }
};

struct FillItem {  // the answers an atomic minimum meets in
  double* t;
  double value;
  PP_HD void operator()(size_t i) const { t[i] = value; }
};

// V-B: one pose; its object spheres culled through the height grid (forEachSphereNearArea),
// the contacts in sphere order into the pose's slots c[i * capacity ...], their number in n[i].
// Split (levels > 0): item k = (i << levels) | part walks one subtree of the sphere tree and
// writes from the slot where the subtree's spheres start (first[k]); n[k] counts its contacts.
struct ContactItem {
  ObjectView o;
  AreaView a;
  const Rigid* X;
  SphereContact* c;
  int* n;
  int capacity;
  int levels = 0;
  int* first = nullptr;  // per item: its first slot (levels > 0)
  PP_HD void operator()(size_t k) const {
    const size_t i = k >> levels;
    const int root = subtreeRoot(o.mesh.sphere_bvh, partOf(k, levels), levels);
    const int start = levels > 0 && root >= 0 ? subtreeFirst(o.mesh.sphere_bvh, root) : 0;
    if (levels > 0) first[k] = start;
    const Rigid T = X[i];
    const V3 com = apply(T, o.com);
    int count = 0;
    SphereContact* out = c + i * static_cast<size_t>(capacity) + start;
    forEachSphereNearArea(o, a, T, [&](int s) {
      const SphereContact sc = sphereContact(a, apply(T, o.mesh.sphere_centres[s]), rotate(T, o.mesh.sphere_normals[s]), com);
      if (sc.valid && start + count < capacity) out[count++] = sc;
    }, root);
    n[k] = count;
  }
};

// Packs the items' contacts (n[k] of them from slot first[k] of their pose's `capacity`) at
// offsets off[k].
struct CompactItem {
  const SphereContact* c;
  const int* n;
  const size_t* off;
  SphereContact* packed;
  int capacity;
  int levels = 0;
  const int* first = nullptr;
  PP_HD void operator()(size_t k) const {
    const SphereContact* from = c + (k >> levels) * static_cast<size_t>(capacity) + (levels > 0 ? first[k] : 0);
    for (int m = 0; m < n[k]; ++m) packed[off[k] + m] = from[m];
  }
};

// ------------------------------------------------------------------ the one launcher
template <typename Device>
class BatchedBackend : public Backend {
 public:
  template <typename... Args>
  explicit BatchedBackend(const TiltParams& tp, Args&&... device_args)
      : tp_(tp), dev_(std::forward<Args>(device_args)...) {}

  std::string name() const override { return dev_.name(); }
  size_t preferredBatch() const override {
    return dev_.preferredBatch(static_cast<size_t>(dev_.object().mesh.num_spheres));
  }

  void distance(const std::vector<TranslationQuery>& q, std::vector<double>& t) override {
    t.assign(q.size(), kInf);
    if (q.empty()) return;
    double* dt = dev_.template scratch<double>(kOut, q.size());
    const int levels = dev_.splitLevels();
    if (levels > 0) dev_.parallelFor(q.size(), FillItem{dt, kInf});
    dev_.parallelFor(q.size() << levels, DistanceItem{dev_.object(), dev_.area(), dev_.upload(kQueries, q), dt, levels});
    dev_.finish();
    dev_.download(dt, q.size(), t.data());
  }
  void vertexSurfaceRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) override {
    rotation<true>(q, a);
  }
  void edgeEdgeRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) override {
    rotation<false>(q, a);
  }
  void contactPoints(const std::vector<Rigid>& X, std::vector<std::vector<SphereContact>>& out) override {
    out.assign(X.size(), {});
    const int cap = dev_.object().mesh.num_spheres;
    if (X.empty() || cap == 0) return;
    const int levels = dev_.contactSplitLevels();
    const size_t items = X.size() << levels;
    SphereContact* dc = dev_.template scratch<SphereContact>(kContacts, X.size() * cap);
    int* dn = dev_.template scratch<int>(kCounts, items);
    int* dfirst = levels > 0 ? dev_.template scratch<int>(kFirsts, items) : nullptr;
    dev_.parallelFor(items, ContactItem{dev_.object(), dev_.area(), dev_.upload(kQueries, X), dc, dn, cap, levels, dfirst});
    dev_.finish();
    std::vector<int> n(items);
    dev_.download(dn, items, n.data());
    // One download: the contacts packed item after item (a pose's parts in sphere order).
    std::vector<size_t> off(items + 1, 0);
    for (size_t k = 0; k < items; ++k) off[k + 1] = off[k] + n[k];
    if (off.back() == 0) return;
    SphereContact* packed = dev_.template scratch<SphereContact>(kPacked, off.back());
    dev_.parallelFor(items, CompactItem{dc, dn, dev_.upload(kOffsets, off), packed, cap, levels, dfirst});
    dev_.finish();
    std::vector<SphereContact> all(off.back());
    dev_.download(packed, all.size(), all.data());
    for (size_t i = 0; i < X.size(); ++i)
      out[i].assign(all.begin() + off[i << levels], all.begin() + off[(i + 1) << levels]);
  }

 private:
  enum Slot { kQueries, kOut, kContacts, kCounts, kPacked, kOffsets, kFirsts };
  template <bool kVertex>
  void rotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) {
    a.assign(q.size(), AnglePair{});
    if (q.empty()) return;
    double* out = dev_.template scratch<double>(kOut, 2 * q.size());
    const int levels = dev_.splitLevels();
    const RotationQuery* dq = dev_.upload(kQueries, q);
    if (levels == 0) {
      dev_.parallelFor(2 * q.size(), RotationItem<kVertex>{dev_.object(), dev_.area(), dq, out, tp_});
    } else {
      dev_.parallelFor(2 * q.size(), FillItem{out, kInf});
      for (int w = 0; w < kNumAngleWindows; ++w)
        dev_.parallelFor((2 * q.size()) << levels, RotationItem<kVertex>{dev_.object(), dev_.area(), dq, out, tp_, levels, w});
    }
    dev_.finish();
    std::vector<double> h(2 * q.size());
    dev_.download(out, h.size(), h.data());
    for (size_t i = 0; i < q.size(); ++i) a[i] = AnglePair{h[2 * i], h[2 * i + 1]};
  }

  TiltParams tp_;
  Device dev_;
};

}  // namespace place_planner
