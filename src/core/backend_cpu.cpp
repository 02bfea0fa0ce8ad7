// CPU launcher of the four batched kernels: threads over poses, each pose computed by exactly
// the per-pose code the CUDA kernels run.
#include "place_planner/backend.h"
#include "place_planner/parallel_for.h"

namespace place_planner {

namespace {
MeshView meshView(const MeshModel& m) {
  MeshView v;
  v.vertices = m.vertices.data();
  v.triangles = m.triangles.empty() ? nullptr : m.triangles[0].data();
  v.edges = m.edges.empty() ? nullptr : m.edges[0].data();
  v.triangle_normals = m.triangle_normals.data();
  v.num_vertices = static_cast<int>(m.vertices.size());
  v.num_triangles = static_cast<int>(m.triangles.size());
  v.num_edges = static_cast<int>(m.edges.size());
  v.triangle_bvh = view(m.triangle_bvh);
  v.edge_bvh = view(m.edge_bvh);
  v.vertex_bvh = view(m.vertex_bvh);
  v.sphere_centres = m.spheres.centres.data();
  v.sphere_normals = m.spheres.normals.data();
  v.num_spheres = static_cast<int>(m.spheres.centres.size());
  v.sphere_radius = m.spheres.radius;
  v.sphere_bvh = view(m.spheres.bvh);
  v.bounds = m.bounds;
  return v;
}

class CpuBackend : public Backend {
 public:
  CpuBackend(const ObjectModel& o, const AreaModel& a, const TiltParams& tp, int threads)
      : obj_(view(o)), area_(view(a)), tp_(tp), threads_(threads) {}
  std::string name() const override { return "cpu"; }

  void distance(const std::vector<TranslationQuery>& q, std::vector<double>& t) override {
    t.assign(q.size(), kInf);
    parallelFor(q.size(), threads_, [&](size_t i) {
      t[i] = firstContactDistance(obj_, area_, q[i].X_GO, q[i].d, q[i].tmax);
    });
  }
  void vertexSurfaceRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) override {
    rotation(q, a, [](auto&&... args) { return vertexSurfaceAngle(args...); });
  }
  void edgeEdgeRotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a) override {
    rotation(q, a, [](auto&&... args) { return edgeEdgeAngle(args...); });
  }
  void contactPoints(const std::vector<Rigid>& X,
                     std::vector<std::vector<SphereContact>>& c) override {
    c.assign(X.size(), {});
    parallelFor(X.size(), threads_, [&](size_t i) {
      // Only spheres whose BVH node comes within the collision distance of an area triangle can
      // collide: the others would find no area sphere in reach (same result as testing all).
      forEachSphereNearArea(obj_, area_, X[i], [&](int s) {
        const SphereContact sc =
            sphereContact(area_, apply(X[i], obj_.mesh.sphere_centres[s]),
                          rotate(X[i], obj_.mesh.sphere_normals[s]), apply(X[i], obj_.com));
        if (sc.valid) c[i].push_back(sc);
      });
    });
  }

 private:
  // One work item per pose and direction (sigma = +1: ccw, -1: cw).
  template <typename Kernel>
  void rotation(const std::vector<RotationQuery>& q, std::vector<AnglePair>& a, Kernel kernel) {
    a.assign(q.size(), AnglePair{});
    parallelFor(2 * q.size(), threads_, [&](size_t k) {
      const size_t i = k / 2;
      const int sigma = k % 2 ? -1 : 1;
      const double th = kernel(obj_, area_, q[i].X_GO, q[i].s_A, q[i].d_A, sigma, tp_,
                               sigma > 0 ? q[i].limit_ccw : q[i].limit_cw);
      (sigma > 0 ? a[i].ccw : a[i].cw) = th;
    });
  }

  ObjectView obj_;
  AreaView area_;
  TiltParams tp_;
  int threads_;
};
}  // namespace

ObjectView view(const ObjectModel& o) {
  return ObjectView{meshView(o), o.com, o.bounding_radius};
}

AreaView view(const AreaModel& a) {
  const HeightGrid& g = a.grid;
  return AreaView{meshView(a), GridView{g.x0, g.y0, g.cell, g.nx, g.ny, g.collision_distance, g.contact_gap,
                                        g.start.data(), g.items.data(), g.max_z.data()}};
}

std::unique_ptr<Backend> makeCpuBackend(const ObjectModel& object, const AreaModel& area,
                                        const TiltParams& tilt, int threads) {
  return std::make_unique<CpuBackend>(object, area, tilt, threads);
}

}  // namespace place_planner
