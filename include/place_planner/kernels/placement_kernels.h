// The four per-pose computations of the planner (Section VII-C: distance, vertex/surface
// rotation, edge/edge rotation, contact points), written once as __host__ __device__ code
// that the CPU backend (threads over poses) and the CUDA backend (GPU threads) both call.
// Frames: the object is posed by X_GO (object mesh frame O -> gravity-aligned planning frame G).
#pragma once
#include "place_planner/kernels/geometry.h"
#include "place_planner/kernels/scene_view.h"

namespace place_planner {

// Axis-aligned box of an O-frame box after the rigid transform (centre + |R| half extents).
PP_HD Aabb transformBox(const Rigid& X, const Aabb& b) {
  const V3 c = apply(X, 0.5 * (b.lo + b.hi));
  const V3 h = 0.5 * (b.hi - b.lo);
  const V3 e = v3(fabs(X.R[0]) * h.x + fabs(X.R[1]) * h.y + fabs(X.R[2]) * h.z,
                  fabs(X.R[3]) * h.x + fabs(X.R[4]) * h.y + fabs(X.R[5]) * h.z,
                  fabs(X.R[6]) * h.x + fabs(X.R[7]) * h.y + fabs(X.R[8]) * h.z);
  return Aabb{c - e, c + e};
}
// Inverse: a G-frame box expressed as an O-frame box.
PP_HD Aabb transformBoxInv(const Rigid& X, const Aabb& b) {
  const V3 c = applyInv(X, 0.5 * (b.lo + b.hi));
  const V3 h = 0.5 * (b.hi - b.lo);
  const V3 e = v3(fabs(X.R[0]) * h.x + fabs(X.R[3]) * h.y + fabs(X.R[6]) * h.z,
                  fabs(X.R[1]) * h.x + fabs(X.R[4]) * h.y + fabs(X.R[7]) * h.z,
                  fabs(X.R[2]) * h.x + fabs(X.R[5]) * h.y + fabs(X.R[8]) * h.z);
  return Aabb{c - e, c + e};
}
PP_HD Aabb sweepBox(Aabb b, V3 d, double t) {
  Aabb s = b;
  aabbAdd(s, b.lo + t * d);
  aabbAdd(s, b.hi + t * d);
  return s;
}

// ------------------------------------------------------------------ distance kernel (V-A)
// Smallest t in [0, tmax] such that the object translated by t d (d unit, frame G) touches the
// area: object vertices against area triangles, area vertices against object triangles, and
// object edges against area edges. kInf when nothing is hit within tmax.
PP_HD double firstContactDistance(const ObjectView& obj, const AreaView& area, const Rigid& X_GO,
                                  V3 d, double tmax) {
  double best = tmax;
  const MeshView& om = obj.mesh;
  const MeshView& am = area.mesh;
  const V3 d_O = rotateInv(X_GO, d);
  // Object vertices and edges, culled hierarchically: a node whose swept box meets no area
  // box cannot touch.
  {
    int stack[kBvhStack];
    int top = 0;
    if (om.vertex_bvh.num_nodes) stack[top++] = 0;
    while (top > 0) {
      const BvhNode& n = om.vertex_bvh.nodes[stack[--top]];
      const Aabb b = sweepBox(transformBox(X_GO, n.box), d, best);
      if (!bvhAnyOverlap(am.triangle_bvh, b)) continue;
      if (n.left >= 0) {
        stack[top++] = n.left;
        stack[top++] = n.right;
        continue;
      }
      for (int i = n.first; i < n.first + n.count; ++i) {
        const V3 v = apply(X_GO, om.vertices[om.vertex_bvh.order[i]]);
        best = bvhRay(am.triangle_bvh, v, d, best, [&](int t) {
          const int* tri = am.triangles + 3 * t;
          return rayTriangle(v, d, am.vertices[tri[0]], am.vertices[tri[1]], am.vertices[tri[2]]);
        });
      }
    }
  }
  {
    int stack[kBvhStack];
    int top = 0;
    if (om.edge_bvh.num_nodes) stack[top++] = 0;
    while (top > 0) {
      const BvhNode& n = om.edge_bvh.nodes[stack[--top]];
      const Aabb b = sweepBox(transformBox(X_GO, n.box), d, best);
      if (!bvhAnyOverlap(am.edge_bvh, b)) continue;
      if (n.left >= 0) {
        stack[top++] = n.left;
        stack[top++] = n.right;
        continue;
      }
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int* e = om.edges + 2 * om.edge_bvh.order[i];
        const V3 p0 = apply(X_GO, om.vertices[e[0]]), p1 = apply(X_GO, om.vertices[e[1]]);
        Aabb eb = aabbEmpty();
        aabbAdd(eb, p0);
        aabbAdd(eb, p1);
        bvhQuery(am.edge_bvh, sweepBox(eb, d, best), [&](int j) {
          const int* f = am.edges + 2 * j;
          const double t = edgeEdgeTranslation(p0, p1, am.vertices[f[0]], am.vertices[f[1]], d);
          if (t < best) best = t;
        });
      }
    }
  }
  // Area vertices moving by -d against the object's triangles (in O).
  {
    const Aabb swept = sweepBox(transformBox(X_GO, om.bounds), d, best);
    bvhQuery(am.vertex_bvh, swept, [&](int w) {
      const V3 w_O = applyInv(X_GO, am.vertices[w]);
      const V3 dir = -d_O;
      best = bvhRay(om.triangle_bvh, w_O, dir, best, [&](int t) {
        const int* tri = om.triangles + 3 * t;
        return rayTriangle(w_O, dir, om.vertices[tri[0]], om.vertices[tri[1]], om.vertices[tri[2]]);
      });
    });
  }
  return best < tmax ? best : kInf;
}

// ------------------------------------------------------------------ rotation kernels (V-C.2)
// Angle windows traced outward along the circles, like the paper's kd-restart tracing of
// D(v, A) (Fig. 3): a window's arcs are bounded by small boxes, so only patches the arcs can
// reach are tested; the search stops once the best angle lies inside the windows done.
constexpr int kNumAngleWindows = 8;
PP_HD double angleWindowEnd(int k) {
  // 2, 4, 8, 16, 32, 64, 128, 180 degrees
  const double deg[kNumAngleWindows] = {2, 4, 8, 16, 32, 64, 128, 180};
  return deg[k] * 0.017453292519943295;
}
PP_HD double angleWindowStart(int k) { return k == 0 ? 0.0 : angleWindowEnd(k - 1); }

struct TiltParams {
  double min_angle;  // angles at or below are the current contact, not a new one
  double tol;        // inside-patch tolerance, m
};

// Angle of an object-frame rotation sigma*theta (sigma = +1 ccw, -1 cw) from a ccw angle.
PP_HD double directed(double ccw, int sigma) { return sigma > 0 ? ccw : wrapAngle(kTwoPi - ccw); }

// Vertex/surface rotation: smallest angle theta in (min_angle, window limit] by which rotating
// the object sigma*theta about (s_A, d_A) brings an object vertex onto an area triangle or an
// area vertex onto an object triangle. kInf when none up to 180 degrees.
PP_HD double vertexSurfaceAngle(const ObjectView& obj, const AreaView& area, const Rigid& X_GO,
                                V3 s_A, V3 d_A, int sigma, const TiltParams& tp) {
  const MeshView& om = obj.mesh;
  const MeshView& am = area.mesh;
  double best = kInf;
  // The object's axis and direction expressed in O for the area-vertex test.
  const V3 s_O = applyInv(X_GO, s_A), d_O = rotateInv(X_GO, d_A);
  for (int k = 0; k < kNumAngleWindows && best > angleWindowStart(k); ++k) {
    const double a0 = sigma * angleWindowStart(k), a1 = sigma * angleWindowEnd(k);
    // v, n, a and the axis (s, dd) are in one frame: G for object vertices, O for area ones.
    auto accept = [&](double ccw, int sgn, V3 v, V3 n, V3 a, V3 s, V3 dd) {
      const double th = directed(ccw, sgn);
      if (th <= tp.min_angle || th >= best || th > angleWindowEnd(kNumAngleWindows - 1)) return;
      // Entering, not leaving: the vertex approaches the plane from the side it starts on.
      const double f0 = dot(v - a, n);
      if (fabs(f0) > tp.tol) {
        const V3 p = rotateAbout(v, s, dd, sgn * th);
        const double vel = dot(cross(dd, p - s), n) * sgn;
        if (vel * f0 > 0) return;
      }
      best = th;
    };
    // Object vertices against area triangles.
    int stack[kBvhStack];
    int top = 0;
    if (om.vertex_bvh.num_nodes) stack[top++] = 0;
    while (top > 0) {
      const BvhNode& n = om.vertex_bvh.nodes[stack[--top]];
      const Aabb nb = transformBox(X_GO, n.box);
      const V3 c = 0.5 * (nb.lo + nb.hi);
      const double r = 0.5 * norm(nb.hi - nb.lo);
      if (!bvhAnyOverlap(am.triangle_bvh, aabbInflate(arcBox(c, s_A, d_A, a0, a1), r))) continue;
      if (n.left >= 0) {
        stack[top++] = n.left;
        stack[top++] = n.right;
        continue;
      }
      for (int i = n.first; i < n.first + n.count; ++i) {
        const V3 v = apply(X_GO, om.vertices[om.vertex_bvh.order[i]]);
        bvhQuery(am.triangle_bvh, aabbInflate(arcBox(v, s_A, d_A, a0, a1), tp.tol), [&](int t) {
          const int* tri = am.triangles + 3 * t;
          const V3 A = am.vertices[tri[0]], B = am.vertices[tri[1]], C = am.vertices[tri[2]];
          double out[2];
          const int m = vertexTriangleAngles(v, s_A, d_A, A, B, C, tp.tol, out);
          for (int j = 0; j < m; ++j) accept(out[j], sigma, v, am.triangle_normals[t], A, s_A, d_A);
        });
      }
    }
    // Area vertices against object triangles: in O the area turns by -sigma*theta.
    top = 0;
    if (am.vertex_bvh.num_nodes) stack[top++] = 0;
    while (top > 0) {
      const BvhNode& n = am.vertex_bvh.nodes[stack[--top]];
      const Aabb nb_O = transformBoxInv(X_GO, n.box);
      const V3 c = 0.5 * (nb_O.lo + nb_O.hi);
      const double r = 0.5 * norm(nb_O.hi - nb_O.lo);
      if (!bvhAnyOverlap(om.triangle_bvh, aabbInflate(arcBox(c, s_O, d_O, -a0, -a1), r))) continue;
      if (n.left >= 0) {
        stack[top++] = n.left;
        stack[top++] = n.right;
        continue;
      }
      for (int i = n.first; i < n.first + n.count; ++i) {
        const V3 w = applyInv(X_GO, am.vertices[am.vertex_bvh.order[i]]);
        bvhQuery(om.triangle_bvh, aabbInflate(arcBox(w, s_O, d_O, -a0, -a1), tp.tol), [&](int t) {
          const int* tri = om.triangles + 3 * t;
          const V3 A = om.vertices[tri[0]], B = om.vertices[tri[1]], C = om.vertices[tri[2]];
          double out[2];
          const int m = vertexTriangleAngles(w, s_O, d_O, A, B, C, tp.tol, out);
          for (int j = 0; j < m; ++j) accept(out[j], -sigma, w, om.triangle_normals[t], A, s_O, d_O);
        });
      }
    }
  }
  return best;
}

// Edge/edge rotation: smallest angle by which rotating the object sigma*theta about (s_A, d_A)
// brings an object edge onto an area edge (surfaces of revolution, Table I). kInf when none.
PP_HD double edgeEdgeAngle(const ObjectView& obj, const AreaView& area, const Rigid& X_GO, V3 s_A,
                           V3 d_A, int sigma, const TiltParams& tp) {
  const MeshView& om = obj.mesh;
  const MeshView& am = area.mesh;
  double best = kInf;
  for (int k = 0; k < kNumAngleWindows && best > angleWindowStart(k); ++k) {
    const double a0 = sigma * angleWindowStart(k), a1 = sigma * angleWindowEnd(k);
    int stack[kBvhStack];
    int top = 0;
    if (om.edge_bvh.num_nodes) stack[top++] = 0;
    while (top > 0) {
      const BvhNode& n = om.edge_bvh.nodes[stack[--top]];
      const Aabb nb = transformBox(X_GO, n.box);
      const V3 c = 0.5 * (nb.lo + nb.hi);
      const double r = 0.5 * norm(nb.hi - nb.lo);
      if (!bvhAnyOverlap(am.edge_bvh, aabbInflate(arcBox(c, s_A, d_A, a0, a1), r))) continue;
      if (n.left >= 0) {
        stack[top++] = n.left;
        stack[top++] = n.right;
        continue;
      }
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int* e = om.edges + 2 * om.edge_bvh.order[i];
        const V3 p0 = apply(X_GO, om.vertices[e[0]]), p1 = apply(X_GO, om.vertices[e[1]]);
        // The swept segment lies in the convex hull of its end points' arcs.
        Aabb sb = arcBox(p0, s_A, d_A, a0, a1);
        aabbMerge(sb, arcBox(p1, s_A, d_A, a0, a1));
        bvhQuery(am.edge_bvh, aabbInflate(sb, tp.tol), [&](int j) {
          const int* f = am.edges + 2 * j;
          double out[4];
          const int m = edgeEdgeAngles(p0, p1, am.vertices[f[0]], am.vertices[f[1]], s_A, d_A, out);
          for (int q = 0; q < m; ++q) {
            const double th = directed(out[q], sigma);
            if (th > tp.min_angle && th < best && th <= angleWindowEnd(kNumAngleWindows - 1)) best = th;
          }
        });
      }
    }
  }
  return best;
}

// ------------------------------------------------------------------ contact kernel (V-B)
struct SphereContact {
  V3 p;       // p_c: mean of the colliding area spheres
  V3 n;       // contact normal, pointing at the object
  int valid;  // 0: no area sphere within the collision distance
};

// Contact of one object sphere (centre s_G, outward normal n_G, both posed) with the area via
// the height grid: early out on the cell's maximum height, else the arithmetic mean of the
// colliding area spheres. The normal blends the area's normals and the object's inward normal,
// each turned to point at the object's centre of mass (com_G): the paper's d_c = s - p_c is
// ill-defined when the two surfaces are coplanar, as in every face-on-face contact.
PP_HD SphereContact sphereContact(const AreaView& area, V3 s_G, V3 n_G, V3 com_G) {
  SphereContact out{v3(0, 0, 0), v3(0, 0, 1), 0};
  const GridView& g = area.grid;
  const int ix = static_cast<int>(floor((s_G.x - g.x0) / g.cell));
  const int iy = static_cast<int>(floor((s_G.y - g.y0) / g.cell));
  if (ix < 0 || iy < 0 || ix >= g.nx || iy >= g.ny) return out;
  const int cell = iy * g.nx + ix;
  if (s_G.z > g.max_z[cell]) return out;  // early out: above everything in this cell
  const double cd2 = g.collision_distance * g.collision_distance;
  V3 sum = v3(0, 0, 0), nsum = v3(0, 0, 0);
  int count = 0;
  for (int k = g.start[cell]; k < g.start[cell + 1]; ++k) {
    const int i = g.items[k];
    const V3 a = area.mesh.sphere_centres[i];
    if (norm2(a - s_G) >= cd2) continue;
    V3 na = area.mesh.sphere_normals[i];
    if (dot(na, com_G - a) < 0) na = -na;
    sum = sum + a;
    nsum = nsum + na;
    ++count;
  }
  if (count == 0) return out;
  out.p = (1.0 / count) * sum;
  V3 no = -n_G;
  if (dot(no, com_G - s_G) < 0) no = -no;
  V3 n = (1.0 / count) * nsum + no;
  if (norm2(n) < 1e-12) n = s_G - out.p;
  if (dot(n, com_G - out.p) < 0) n = -n;
  out.n = normalized(n);
  out.valid = 1;
  return out;
}

// Calls f(sphere index) for the object spheres whose BVH leaf, posed, comes within the
// collision distance of an area triangle box, in increasing index order within each leaf.
template <typename F>
PP_HD void forEachSphereNearArea(const ObjectView& obj, const AreaView& area, const Rigid& X_GO, F&& f) {
  const BvhView& b = obj.mesh.sphere_bvh;
  if (b.num_nodes == 0) return;
  const double cd = area.grid.collision_distance;
  int stack[kBvhStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = b.nodes[stack[--top]];
    if (!bvhAnyOverlap(area.mesh.triangle_bvh, aabbInflate(transformBox(X_GO, n.box), cd))) continue;
    if (n.left >= 0) {
      // Right pushed first so the left subtree (lower indices after sorting) comes first.
      stack[top++] = n.right;
      stack[top++] = n.left;
      continue;
    }
    for (int i = n.first; i < n.first + n.count; ++i) f(b.order[i]);
  }
}

}  // namespace place_planner
