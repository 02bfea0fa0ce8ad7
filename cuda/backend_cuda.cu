// CUDA launcher of the four batched kernels (Section VII-C). The per-pose bodies are the
// __host__ __device__ functions of kernels/placement_kernels.h that the CPU backend runs;
// here the scene is uploaded once and each GPU thread takes one (pose, direction) pair for the
// rotation and distance kernels and one (pose, sphere) pair for the contact kernel.
#include <memory>
#include <vector>

#include "cuda_common.cuh"
#include "place_planner/backend.h"
#include "place_planner/cuda_backend.h"

namespace place_planner {
namespace {

template <typename T>
struct Dev {
  std::unique_ptr<cuda::DeviceBuffer<T>> buf;
  const T* upload(const std::vector<T>& h) {
    buf = std::make_unique<cuda::DeviceBuffer<T>>(h.size());
    buf->upload(h.data());
    return h.empty() ? nullptr : buf->get();
  }
};

struct DevBvh {
  Dev<BvhNode> nodes;
  Dev<int> order;
  BvhView upload(const Bvh& b) {
    return BvhView{nodes.upload(b.nodes), order.upload(b.order), static_cast<int>(b.nodes.size())};
  }
};

struct DevMesh {
  Dev<V3> vertices, normals, centres, snormals;
  Dev<int> tris, edges;
  DevBvh tb, eb, vb, sb;
  MeshView upload(const MeshModel& m) {
    MeshView v;
    v.vertices = vertices.upload(m.vertices);
    std::vector<int> t(m.triangles.size() * 3), e(m.edges.size() * 2);
    for (size_t i = 0; i < m.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) t[3 * i + k] = m.triangles[i][k];
    for (size_t i = 0; i < m.edges.size(); ++i)
      for (int k = 0; k < 2; ++k) e[2 * i + k] = m.edges[i][k];
    v.triangles = tris.upload(t);
    v.edges = edges.upload(e);
    v.triangle_normals = normals.upload(m.triangle_normals);
    v.num_vertices = static_cast<int>(m.vertices.size());
    v.num_triangles = static_cast<int>(m.triangles.size());
    v.num_edges = static_cast<int>(m.edges.size());
    v.triangle_bvh = tb.upload(m.triangle_bvh);
    v.edge_bvh = eb.upload(m.edge_bvh);
    v.vertex_bvh = vb.upload(m.vertex_bvh);
    v.sphere_centres = centres.upload(m.spheres.centres);
    v.sphere_normals = snormals.upload(m.spheres.normals);
    v.num_spheres = static_cast<int>(m.spheres.centres.size());
    v.sphere_radius = m.spheres.radius;
    v.sphere_bvh = sb.upload(m.spheres.bvh);
    v.bounds = m.bounds;
    return v;
  }
};

__global__ void distanceKernel(ObjectView o, AreaView a, const TranslationQuery* q, double* t, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) t[i] = firstContactDistance(o, a, q[i].X_GO, q[i].d, q[i].tmax);
}

__global__ void vertexSurfaceKernel(ObjectView o, AreaView a, const RotationQuery* q, double* out,
                                    int n, TiltParams tp) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= 2 * n) return;
  const int i = k / 2, sigma = k % 2 ? -1 : 1;
  out[k] = vertexSurfaceAngle(o, a, q[i].X_GO, q[i].s_A, q[i].d_A, sigma, tp,
                              sigma > 0 ? q[i].limit_ccw : q[i].limit_cw);
}

__global__ void edgeEdgeKernel(ObjectView o, AreaView a, const RotationQuery* q, double* out, int n,
                               TiltParams tp) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= 2 * n) return;
  const int i = k / 2, sigma = k % 2 ? -1 : 1;
  out[k] = edgeEdgeAngle(o, a, q[i].X_GO, q[i].s_A, q[i].d_A, sigma, tp,
                         sigma > 0 ? q[i].limit_ccw : q[i].limit_cw);
}

__global__ void contactKernel(ObjectView o, AreaView a, const Rigid* X, SphereContact* c, int poses) {
  const long k = blockIdx.x * static_cast<long>(blockDim.x) + threadIdx.x;
  const int ns = o.mesh.num_spheres;
  if (k >= static_cast<long>(poses) * ns) return;
  const int i = static_cast<int>(k / ns), s = static_cast<int>(k % ns);
  c[k] = sphereContact(a, apply(X[i], o.mesh.sphere_centres[s]),
                       rotate(X[i], o.mesh.sphere_normals[s]), apply(X[i], o.com));
}

class CudaBackend : public Backend {
 public:
  CudaBackend(const ObjectModel& o, const AreaModel& a, const TiltParams& tp) : tp_(tp) {
    obj_ = ObjectView{om_.upload(o), o.com, o.bounding_radius};
    const HeightGrid& g = a.grid;
    area_ = AreaView{am_.upload(a), GridView{g.x0, g.y0, g.cell, g.nx, g.ny, g.collision_distance, g.contact_gap,
                                             start_.upload(g.start), items_.upload(g.items),
                                             maxz_.upload(g.max_z)}};
    // Deep per-thread traversal stacks: raise the stack size for the rotation kernels.
    PP_CUDA_CHECK(cudaDeviceSetLimit(cudaLimitStackSize, 16384));
  }
  std::string name() const override { return "cuda"; }

  void distance(const std::vector<TranslationQuery>& q, std::vector<double>& t) override {
    t.assign(q.size(), kInf);
    if (q.empty()) return;
    cuda::DeviceBuffer<TranslationQuery> dq(q.size());
    cuda::DeviceBuffer<double> dt(q.size());
    dq.upload(q.data());
    distanceKernel<<<cuda::blocksFor(q.size(), 64), 64>>>(obj_, area_, dq.get(), dt.get(),
                                                          static_cast<int>(q.size()));
    finish();
    dt.download(t.data());
  }
  void vertexSurfaceRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) override {
    rotation(q, a, true);
  }
  void edgeEdgeRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) override {
    rotation(q, a, false);
  }
  void contactPoints(const std::vector<Rigid>& X,
                     std::vector<std::vector<SphereContact>>& out) override {
    const size_t ns = static_cast<size_t>(obj_.mesh.num_spheres);
    const size_t n = X.size() * ns;
    out.assign(X.size(), {});
    if (n == 0) return;
    std::vector<SphereContact> c(n);
    cuda::DeviceBuffer<Rigid> dx(X.size());
    cuda::DeviceBuffer<SphereContact> dc(n);
    dx.upload(X.data());
    contactKernel<<<cuda::blocksFor(n), 256>>>(obj_, area_, dx.get(), dc.get(), static_cast<int>(X.size()));
    finish();
    dc.download(c.data());
    // Compact per pose; reduceContacts() does not depend on the order.
    for (size_t i = 0; i < X.size(); ++i)
      for (size_t s = 0; s < ns; ++s)
        if (c[i * ns + s].valid) out[i].push_back(c[i * ns + s]);
  }

 private:
  void rotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a, bool vertex) {
    a.assign(q.size(), AnglePair{});
    if (q.empty()) return;
    cuda::DeviceBuffer<RotationQuery> dq(q.size());
    cuda::DeviceBuffer<double> out(2 * q.size());
    dq.upload(q.data());
    const int n = static_cast<int>(q.size());
    if (vertex)
      vertexSurfaceKernel<<<cuda::blocksFor(2 * q.size(), 64), 64>>>(obj_, area_, dq.get(), out.get(), n, tp_);
    else
      edgeEdgeKernel<<<cuda::blocksFor(2 * q.size(), 64), 64>>>(obj_, area_, dq.get(), out.get(), n, tp_);
    finish();
    std::vector<double> h(2 * q.size());
    out.download(h.data());
    for (size_t i = 0; i < q.size(); ++i) a[i] = AnglePair{h[2 * i], h[2 * i + 1]};
  }
  static void finish() {
    PP_CUDA_CHECK(cudaGetLastError());
    PP_CUDA_CHECK(cudaDeviceSynchronize());
  }

  TiltParams tp_;
  DevMesh om_, am_;
  Dev<int> start_, items_;
  Dev<double> maxz_;
  ObjectView obj_;
  AreaView area_;
};

}  // namespace

std::unique_ptr<Backend> makeCudaBackend(const ObjectModel& object, const AreaModel& area,
                                         const TiltParams& tilt) {
  std::string why;
  if (!cuda::available(&why)) throw std::runtime_error("CUDA backend unavailable: " + why);
  return std::make_unique<CudaBackend>(object, area, tilt);
}

}  // namespace place_planner
