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

PP_HD double boxVolume(const Aabb& b) {
  const V3 e = b.hi - b.lo;
  return e.x * e.y * e.z;
}

// Simultaneous traversal of two BVHs: for every pair of leaves whose boxes overlap (A's node
// boxes first mapped by boxA: posed, swept along a translation or an arc), calls
// prep(primitive of A) -> data once per leaf of A and subtree of B it reaches, then
// leaf(data, primitive of A, primitive of B). Replaces one root-to-leaf query per primitive
// of A (the paper's kd-restart per ray) by one walk over both trees.
constexpr int kPairStack = 2 * kBvhStack;
struct AnyOrder {  // children visited in tree order
  PP_HD bool operator()(const Aabb&, const Aabb&) const { return false; }
};
// nearer(x, y): visit the pair with box x before the one with box y (both of A's mapped boxes
// or both of B's): a query whose reach shrinks with its hits (the translation to first
// contact) finds its nearest hit sooner and prunes more.
// reach(): how far the query still reaches (the best distance so far); a pair pushed when it
// reached farther gets its box mapped again when it comes off the stack, so pairs the hits
// found since have put out of reach are dropped.
struct FixedReach {
  PP_HD double operator()() const { return 0.0; }
};
template <typename BoxA, typename Prep, typename Leaf, typename NearerA = AnyOrder, typename NearerB = AnyOrder,
          typename Reach = FixedReach>
PP_HD void dualTraverse(const BvhView& A, const BvhView& B, BoxA&& boxA, Prep&& prep, Leaf&& leaf,
                        NearerA nearerA = {}, NearerB nearerB = {}, Reach reach = {}, int rootA = 0) {
  if (A.num_nodes == 0 || B.num_nodes == 0 || rootA < 0) return;
  // Each entry carries A's mapped box, so a node of A is mapped once per split, not once per
  // node of B it meets. Pairs are pushed only when their boxes overlap.
  struct Pair {
    int a, b;
    Aabb box;
    double reach;  // reach() when the box was mapped
  };
  constexpr bool kShrinks = !std::is_same<Reach, FixedReach>::value;
  Pair stack[kPairStack];
  int top = 0;
  {
    const Aabb root = boxA(A.nodes[rootA]);
    if (!aabbOverlap(root, B.nodes[0].box)) return;
    stack[top++] = Pair{rootA, 0, root, reach()};
  }
  while (top > 0) {
    Pair p = stack[--top];
    const BvhNode& na = A.nodes[p.a];
    const BvhNode& nb = B.nodes[p.b];
    if (kShrinks && reach() < p.reach) {
      p.box = boxA(na);
      p.reach = reach();
      if (!aabbOverlap(p.box, nb.box)) continue;
    }
    const bool la = na.left < 0, lb = nb.left < 0;
    if (la) {
      // A leaf of A: its primitives are prepared once and meet every leaf of B's subtree
      // under nb that overlaps the leaf's box (not once per leaf pair).
      using Data = decltype(prep(0));
      constexpr int kChunk = 8;
      for (int i0 = na.first; i0 < na.first + na.count; i0 += kChunk) {
        const int n = minv(kChunk, na.first + na.count - i0);
        Data data[kChunk];
        for (int k = 0; k < n; ++k) data[k] = prep(A.order[i0 + k]);
        int sub[kBvhStack];
        int st = 0;
        sub[st++] = p.b;
        while (st > 0) {
          const BvhNode& m = B.nodes[sub[--st]];
          if (m.left >= 0) {
            if (aabbOverlap(p.box, B.nodes[m.right].box)) sub[st++] = m.right;
            if (aabbOverlap(p.box, B.nodes[m.left].box)) sub[st++] = m.left;
            continue;
          }
          for (int j = m.first; j < m.first + m.count; ++j)
            for (int k = 0; k < n; ++k) leaf(data[k], A.order[i0 + k], B.order[j]);
        }
      }
      continue;
    }
    // Both trees are at most kBvhStack / 2 deep, so this stack cannot overflow.
    // The pair to visit first is pushed last.
    if (lb || boxVolume(p.box) >= boxVolume(nb.box)) {
      const Aabb cb[2] = {boxA(A.nodes[na.right]), boxA(A.nodes[na.left])};
      const int c[2] = {na.right, na.left};
      const int last = nearerA(cb[0], cb[1]) ? 0 : 1;
      const double r = reach();
      for (const int k : {1 - last, last})
        if (aabbOverlap(cb[k], nb.box)) stack[top++] = Pair{c[k], p.b, cb[k], r};
    } else {
      const bool swap = nearerB(B.nodes[nb.right].box, B.nodes[nb.left].box);
      for (const int c : {swap ? nb.left : nb.right, swap ? nb.right : nb.left})
        if (aabbOverlap(p.box, B.nodes[c].box)) stack[top++] = Pair{p.a, c, p.box, p.reach};
    }
  }
}

// One work item per part of a query (the GPU's threads, Section VII-C): part p of 2^levels
// walks the subtree of A reached from its root by p's bits, most significant first (0: left),
// so the parts cover A's primitives once. A leaf met early is walked by the part whose
// remaining bits are zero; the others get -1 (nothing). levels = 0: the whole tree.
PP_HD int subtreeRoot(const BvhView& b, int part, int levels) {
  if (b.num_nodes == 0) return -1;
  int node = 0;
  for (int l = levels - 1; l >= 0; --l) {
    const bool right = (part >> l) & 1;
    if (b.nodes[node].left < 0) return (part & ((1 << (l + 1)) - 1)) == 0 ? node : -1;
    node = right ? b.nodes[node].right : b.nodes[node].left;
  }
  return node;
}

// Where a subtree's primitives start in the tree's order (a subtree's leaves hold one range of
// it, left to right).
PP_HD int subtreeFirst(const BvhView& b, int node) {
  while (b.nodes[node].left >= 0) node = b.nodes[node].left;
  return b.nodes[node].first;
}

// *p = min(*p, v) for v >= 0, atomically: a query's parts (subtreeRoot) meet in one answer.
// Non-negative doubles order as their bit patterns do.
PP_HD void atomicMinNonNegative(double* p, double v) {
#ifdef __CUDA_ARCH__
  atomicMin(reinterpret_cast<unsigned long long*>(p), static_cast<unsigned long long>(__double_as_longlong(v)));
#else
  double cur;
  __atomic_load(p, &cur, __ATOMIC_RELAXED);
  while (v < cur && !__atomic_compare_exchange(p, &cur, &v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
  }
#endif
}

PP_HD Aabb segmentBox(V3 a, V3 b) {
  Aabb s = aabbEmpty();
  aabbAdd(s, a);
  aabbAdd(s, b);
  return s;
}

// ------------------------------------------------------------------ distance kernel (V-A)
// Smallest t in [0, tmax] such that the object translated by t d (d unit, frame G) touches the
// area: object vertices against area triangles, area vertices against object triangles, and
// object edges against area edges. kInf when nothing is hit within tmax.
PP_HD double firstContactDistance(const ObjectView& obj, const AreaView& area, const Rigid& X_GO,
                                  V3 d, double tmax, int part = 0, int levels = 0) {
  double best = tmax;
  const MeshView& om = obj.mesh;
  const MeshView& am = area.mesh;
  auto swept = [&](const BvhNode& n) { return sweepBox(transformBox(X_GO, n.box), d, best); };
  // Moving along u: the moving part foremost along u and the fixed part hindmost first.
  auto ahead = [](V3 u) { return [u](const Aabb& x, const Aabb& y) { return dot(x.lo + x.hi, u) > dot(y.lo + y.hi, u); }; };
  auto reach = [&] { return best; };
  // Object vertices along d against area triangles.
  auto posed = [&](int vi) { return apply(X_GO, om.vertices[vi]); };
  dualTraverse(om.vertex_bvh, am.triangle_bvh, swept, posed, [&](const V3& v, int, int t) {
    const int* tri = am.triangles + 3 * t;
    const double h = rayTriangle(v, d, am.vertices[tri[0]], am.vertices[tri[1]], am.vertices[tri[2]]);
    if (h < best) best = h;
  }, ahead(d), ahead(-d), reach, subtreeRoot(om.vertex_bvh, part, levels));
  // Object edges against area edges.
  auto posedEdge = [&](int ei) {
    const int* e = om.edges + 2 * ei;
    return Aabb{apply(X_GO, om.vertices[e[0]]), apply(X_GO, om.vertices[e[1]])};  // end points
  };
  dualTraverse(om.edge_bvh, am.edge_bvh, swept, posedEdge, [&](const Aabb& pe, int, int fj) {
    const int* f = am.edges + 2 * fj;
    const V3 p0 = pe.lo, p1 = pe.hi;
    const V3 q0 = am.vertices[f[0]], q1 = am.vertices[f[1]];
    if (!aabbOverlap(sweepBox(segmentBox(p0, p1), d, best), segmentBox(q0, q1))) return;
    const double h = edgeEdgeTranslation(p0, p1, q0, q1, d);
    if (h < best) best = h;
  }, ahead(d), ahead(-d), reach, subtreeRoot(om.edge_bvh, part, levels));
  // Area vertices moving by -d against the object's triangles, in O.
  const V3 dir_O = -rotateInv(X_GO, d);
  auto swept_area = [&](const BvhNode& n) {
    return sweepBox(transformBoxInv(X_GO, n.box), dir_O, best);
  };
  auto inObject = [&](int wi) { return applyInv(X_GO, am.vertices[wi]); };
  dualTraverse(am.vertex_bvh, om.triangle_bvh, swept_area, inObject, [&](const V3& w, int, int t) {
    const int* tri = om.triangles + 3 * t;
    const double h = rayTriangle(w, dir_O, om.vertices[tri[0]], om.vertices[tri[1]], om.vertices[tri[2]]);
    if (h < best) best = h;
  }, ahead(dir_O), ahead(-dir_O), reach, subtreeRoot(am.vertex_bvh, part, levels));
  return best < tmax ? best : kInf;
}

// ------------------------------------------------------------------ rotation kernels (V-C.2)
// Angle windows traced outward along the circles, like the paper's kd-restart tracing of
// D(v, A) (Fig. 3): a window's arcs are bounded by small boxes, so only patches the arcs can
// reach are tested; the search stops once the best angle lies inside the windows done.
// The windows cover the full tilt range up to a half turn: an object standing on its end tips
// over until it lies (90 degrees), nothing caps the search before a resting pose.
constexpr int kNumAngleWindows = 4;
PP_HD double angleWindowEnd(int k) {
  const double deg[kNumAngleWindows] = {15, 45, 100, 180};
  return deg[k] * 0.017453292519943295;
}
PP_HD double angleWindowStart(int k) { return k == 0 ? 0.0 : angleWindowEnd(k - 1); }

// The windows a tilt searches: all (window < 0) or one (a split answer searches them one launch
// at a time, so that a hit in an earlier one still ends it: batched_steps.h).
PP_HD int firstWindow(int window) { return window < 0 ? 0 : window; }
PP_HD int endWindow(int window) { return window < 0 ? kNumAngleWindows : window + 1; }

struct TiltParams {
  double min_angle;  // angles at or below are the current contact, not a new one
  double tol;        // inside-patch tolerance, m
};

// Angle of an object-frame rotation sigma*theta (sigma = +1 ccw, -1 cw) from a ccw angle.
PP_HD double directed(double ccw, int sigma) { return sigma > 0 ? ccw : wrapAngle(kTwoPi - ccw); }

// Box of everything a BVH node's box (in its mesh's frame; X maps it into the frame of the axis)
// sweeps over a window: the arc of its centre, inflated by its half diagonal. A rotation keeps
// every point of the box within that distance of the centre, so the centre is mapped and the
// box is not (its mapped axis-aligned box would be up to sqrt 3 wider).
template <bool kInverse>
PP_HD Aabb arcNodeBox(const Rigid& X, const Aabb& nb, V3 s, V3 d, const AngleWindow& w) {
  const V3 c = 0.5 * (nb.lo + nb.hi);
  return aabbInflate(arcBoxW(kInverse ? applyInv(X, c) : apply(X, c), s, d, w), 0.5 * norm(nb.hi - nb.lo));
}

struct VertexArc {
  V3 v;      // the vertex, in the frame of the axis
  Aabb box;  // its arc over the window, inflated by the tolerance
};
struct EdgeArc {
  V3 P0, P1;  // the edge in the axis frame
  Aabb box;   // its swept arc over the window
};

// Vertex/surface rotation: smallest angle theta in (min_angle, 180 deg] by which rotating the
// object sigma*theta about (s_A, d_A) brings an object vertex onto an area triangle or an
// area vertex onto an object triangle. kInf when none below `limit`.
PP_HD double vertexSurfaceAngle(const ObjectView& obj, const AreaView& area, const Rigid& X_GO,
                                V3 s_A, V3 d_A, int sigma, const TiltParams& tp,
                                double limit = kInf, int part = 0, int levels = 0, int window = -1) {
  const MeshView& om = obj.mesh;
  const MeshView& am = area.mesh;
  double best = limit;
  // The axis in O, for the area vertices (which turn the other way relative to the object).
  const V3 s_O = applyInv(X_GO, s_A), d_O = rotateInv(X_GO, d_A);
  const double max_angle = angleWindowEnd(kNumAngleWindows - 1);
  // v, n, a and the axis (s, dd) are in one frame: G for object vertices, O for area ones.
  auto accept = [&](double ccw, int sgn, V3 v, V3 n, V3 a, V3 s, V3 dd) {
    const double th = directed(ccw, sgn);
    if (th <= tp.min_angle || th >= best || th > max_angle) return;
    // Entering, not leaving: the vertex approaches the plane from the side it starts on.
    const double f0 = dot(v - a, n);
    if (fabs(f0) > tp.tol) {
      const V3 p = rotateAbout(v, s, dd, sgn * th);
      const double vel = dot(cross(dd, p - s), n) * sgn;
      if (vel * f0 > 0) return;
    }
    best = th;
  };
  for (int k = firstWindow(window); k < endWindow(window) && best > angleWindowStart(k); ++k) {
    // The window ends at the best angle so far: arcs past it cannot give a smaller one.
    // It also shrinks with every nearer hit, so the arcs of the nodes met after it are shorter.
    const double a0 = sigma * angleWindowStart(k);
    // The object's window, and the area's (area vertices turn the other way relative to it).
    auto window = [&](double dir) { return angleWindow(dir * a0, dir * sigma * minv(angleWindowEnd(k), best)); };
    AngleWindow win = window(1);
    dualTraverse(
        om.vertex_bvh, am.triangle_bvh,
        [&](const BvhNode& n) { return arcNodeBox<false>(X_GO, n.box, s_A, d_A, win); },
        [&](int vi) {
          const V3 v = apply(X_GO, om.vertices[vi]);
          return VertexArc{v, aabbInflate(arcBoxW(v, s_A, d_A, win), tp.tol)};
        },
        [&](const VertexArc& va, int, int t) {
          const V3 v = va.v;
          const int* tri = am.triangles + 3 * t;
          const V3 A = am.vertices[tri[0]], B = am.vertices[tri[1]], C = am.vertices[tri[2]];
          Aabb tb = segmentBox(A, B);
          aabbAdd(tb, C);
          if (!aabbOverlap(va.box, tb)) return;
          double out[2];
          const int m = vertexTriangleAngles(v, s_A, d_A, A, B, C, tp.tol, out);
          const double before = best;
          for (int j = 0; j < m; ++j) accept(out[j], sigma, v, am.triangle_normals[t], A, s_A, d_A);
          if (best < before) win = window(1);
        },
        AnyOrder{}, AnyOrder{}, FixedReach{}, subtreeRoot(om.vertex_bvh, part, levels));
    if (best <= angleWindowStart(k)) break;
    AngleWindow win_area = window(-1);
    dualTraverse(
        am.vertex_bvh, om.triangle_bvh,
        [&](const BvhNode& n) { return arcNodeBox<true>(X_GO, n.box, s_O, d_O, win_area); },
        [&](int wi) {
          const V3 w = applyInv(X_GO, am.vertices[wi]);
          return VertexArc{w, aabbInflate(arcBoxW(w, s_O, d_O, win_area), tp.tol)};
        },
        [&](const VertexArc& va, int, int t) {
          const V3 w = va.v;
          const int* tri = om.triangles + 3 * t;
          const V3 A = om.vertices[tri[0]], B = om.vertices[tri[1]], C = om.vertices[tri[2]];
          Aabb tb = segmentBox(A, B);
          aabbAdd(tb, C);
          if (!aabbOverlap(va.box, tb)) return;
          double out[2];
          const int m = vertexTriangleAngles(w, s_O, d_O, A, B, C, tp.tol, out);
          const double before = best;
          for (int j = 0; j < m; ++j) accept(out[j], -sigma, w, om.triangle_normals[t], A, s_O, d_O);
          if (best < before) win_area = window(-1);
        },
        AnyOrder{}, AnyOrder{}, FixedReach{}, subtreeRoot(am.vertex_bvh, part, levels));
  }
  return best < limit ? best : kInf;
}

// Edge/edge rotation: smallest angle by which rotating the object sigma*theta about (s_A, d_A)
// brings an object edge onto an area edge (surfaces of revolution, Table I). kInf when none
// below `limit`.
PP_HD double edgeEdgeAngle(const ObjectView& obj, const AreaView& area, const Rigid& X_GO, V3 s_A,
                           V3 d_A, int sigma, const TiltParams& tp, double limit = kInf, int part = 0,
                           int levels = 0, int window = -1) {
  const MeshView& om = obj.mesh;
  const MeshView& am = area.mesh;
  double best = limit;
  const AxisFrame frame = axisFrame(s_A, d_A);
  const double max_angle = angleWindowEnd(kNumAngleWindows - 1);
  for (int k = firstWindow(window); k < endWindow(window) && best > angleWindowStart(k); ++k) {
    // The window ends at the best angle so far, and shrinks with every nearer hit.
    auto window = [&] { return angleWindow(sigma * angleWindowStart(k), sigma * minv(angleWindowEnd(k), best)); };
    AngleWindow win = window();
    dualTraverse(
        om.edge_bvh, am.edge_bvh,
        [&](const BvhNode& n) { return arcNodeBox<false>(X_GO, n.box, s_A, d_A, win); },
        [&](int ei) {
          const int* e = om.edges + 2 * ei;
          const V3 p0 = apply(X_GO, om.vertices[e[0]]), p1 = apply(X_GO, om.vertices[e[1]]);
          // The swept segment lies in the convex hull of its end points' arcs.
          Aabb sb = arcBoxW(p0, s_A, d_A, win);
          aabbMerge(sb, arcBoxW(p1, s_A, d_A, win));
          return EdgeArc{toAxis(frame, p0), toAxis(frame, p1), aabbInflate(sb, tp.tol)};
        },
        [&](const EdgeArc& ea, int, int fj) {
          const int* f = am.edges + 2 * fj;
          const V3 q0 = am.vertices[f[0]], q1 = am.vertices[f[1]];
          if (!aabbOverlap(ea.box, segmentBox(q0, q1))) return;
          double out[4];
          const int m = edgeEdgeAnglesAxis(ea.P0, ea.P1, toAxis(frame, q0), toAxis(frame, q1), out);
          const double before = best;
          for (int q = 0; q < m; ++q) {
            const double th = directed(out[q], sigma);
            if (th > tp.min_angle && th < best && th <= max_angle) best = th;
          }
          if (best < before) win = window();
        },
        AnyOrder{}, AnyOrder{}, FixedReach{}, subtreeRoot(om.edge_bvh, part, levels));
  }
  return best < limit ? best : kInf;
}

// ------------------------------------------------------------------ contact kernel (V-B)
// An area normal and the object's inward normal agree when their cosine exceeds this (surfaces
// facing each other within about 72 degrees).
constexpr double kAgree = 0.3;
// The least weight of an area face in the area's own normal at a contact (sphereContact), for
// one at right angles to the object's surface there.
constexpr double kEdgeWeight = 0.05;

struct SphereContact {
  V3 p;       // p_c: mean of the colliding area spheres
  V3 n;       // contact normal, pointing at the object
  int valid;  // 0: no area sphere within the collision distance
  V3 na{0, 0, 0};  // the area's own normal there (its spheres' mean), pointing at the object; 0: unknown
};

// Contact of one object sphere (centre s_G, outward normal n_G, both posed) with the area via
// the height grid: early out on the cell's maximum height, else the arithmetic mean of the
// colliding area spheres. The normal blends the area's normals and the object's inward normal:
// the paper's d_c = s - p_c is ill-defined when the two surfaces are coplanar, as in every
// face-on-face contact. Each is turned to point at the object's centre of mass (com_G), except
// where an area normal faces the object's outward one (both meshes wound outward there) above
// the centre of mass, or on a wall (the area normal within kAgree of horizontal): a ring hanging
// on a peg has its centre of mass across the peg from the contact, and the peg pushes it up; a
// ring round a post has its centre of mass inside the post, and the post pushes it out.
PP_HD SphereContact sphereContact(const AreaView& area, V3 s_G, V3 n_G, V3 com_G) {
  SphereContact out{v3(0, 0, 0), v3(0, 0, 1), 0};
  const GridView& g = area.grid;
  const int ix = static_cast<int>(floor((s_G.x - g.x0) / g.cell));
  const int iy = static_cast<int>(floor((s_G.y - g.y0) / g.cell));
  if (ix < 0 || iy < 0 || ix >= g.nx || iy >= g.ny) return out;
  const int cell = iy * g.nx + ix;
  // Early out: above every height in this cell from which a contact can be made.
  if (s_G.z > g.max_contact_z[cell]) return out;
  const double cd2 = g.collision_distance * g.collision_distance;
  V3 sum = v3(0, 0, 0), nsum = v3(0, 0, 0), nfacing = v3(0, 0, 0);
  int count = 0;
  double gap = kInf;
  const double lateral2 = 2.25 * area.mesh.sphere_radius * area.mesh.sphere_radius;
  // A cell's spheres come highest first (buildHeightGrid): those higher than s_G by the collision
  // distance or more cannot collide, so the walk starts below them, found by bisection (a shelf
  // unit's column holds every board's spheres above the one the object rests on).
  int first = g.start[cell], last = g.start[cell + 1];
  const double reach_top = s_G.z + g.collision_distance;
  while (first < last) {
    const int mid = first + (last - first) / 2;
    if (area.mesh.sphere_centres[g.items[mid]].z >= reach_top) first = mid + 1;
    else last = mid;
  }
  for (int k = first; k < g.start[cell + 1]; ++k) {
    const int i = g.items[k];
    const V3 a = area.mesh.sphere_centres[i];
    // A cell's spheres come highest first (buildHeightGrid): below reach, so are the rest.
    if (a.z <= s_G.z - g.collision_distance) break;
    if (norm2(a - s_G) >= cd2) continue;
    V3 na = area.mesh.sphere_normals[i];
    const bool faces = (com_G.z < a.z || fabs(na.z) < kAgree) && dot(na, n_G) < -kAgree;
    if (!faces && dot(na, com_G - a) < 0) na = -na;
    sum = sum + a;
    nsum = nsum + na;
    // The area's own normal weighs each face by how squarely it faces the object's surface:
    // where a mug's side meets a board's lower edge, the board's underside (at right angles to
    // the side) does not push; the board's face does, sideways (a wall, not a floor).
    nfacing = nfacing + (fabs(dot(na, n_G)) + kEdgeWeight) * na;
    ++count;
    // Separation along the area's normal: zero for touching surfaces, whatever the lateral
    // offset of the two sphere lattices. Only where the object sphere lies over this sphere's
    // share of its patch (lateral offset within 1.5 r): a sphere on the side of a peg says
    // nothing about an object hovering above the peg's top.
    const V3 d = s_G - a;
    const double along = dot(d, na);
    if (norm2(d - along * na) <= lateral2) gap = minv(gap, fabs(along));
  }
  // Near misses (a gap up to the collision distance) are not contacts: the tree keeps
  // rotating until real contacts hold the object (the paper counts every colliding sphere).
  if (count == 0 || gap > g.contact_gap) return out;
  out.p = (1.0 / count) * sum;
  V3 no = -n_G;
  const V3 nmean = (1.0 / count) * nsum;
  const double nm = sqrt(norm2(nmean));
  const bool agree = (com_G.z < out.p.z || fabs(nmean.z) < kAgree * nm) && dot(nmean, no) > kAgree * nm;
  if (!agree && dot(no, com_G - s_G) < 0) no = -no;
  V3 n = nmean + no;
  if (norm2(nfacing) > 1e-12) out.na = normalized(nfacing);
  if (norm2(n) < 1e-12) n = s_G - out.p;
  if (!agree && dot(n, com_G - out.p) < 0) n = -n;
  out.n = normalized(n);
  out.valid = 1;
  return out;
}

// Can a sphere centre inside box b (frame G) make a contact (sphereContact)? Only when b
// reaches below the highest contact height (max_contact_z) of a grid cell under it. Boxes over
// more than 64 cells are not tested: their children are.
PP_HD bool gridMayCollide(const GridView& g, const Aabb& b) {
  const double fx0 = floor((b.lo.x - g.x0) / g.cell), fx1 = floor((b.hi.x - g.x0) / g.cell);
  const double fy0 = floor((b.lo.y - g.y0) / g.cell), fy1 = floor((b.hi.y - g.y0) / g.cell);
  // Off the grid: no area sphere there (tested in doubles, before any cast to int).
  if (fx1 < 0 || fy1 < 0 || fx0 > g.nx - 1 || fy0 > g.ny - 1) return false;
  const int ix0 = maxv(0.0, fx0), ix1 = minv(g.nx - 1.0, fx1);
  const int iy0 = maxv(0.0, fy0), iy1 = minv(g.ny - 1.0, fy1);
  if ((ix1 - ix0 + 1) * (iy1 - iy0 + 1) > 64) return true;
  for (int iy = iy0; iy <= iy1; ++iy)
    for (int ix = ix0; ix <= ix1; ++ix)
      if (b.lo.z <= g.max_contact_z[iy * g.nx + ix]) return true;
  return false;
}

// Calls f(sphere index) for the object spheres whose BVH leaf, posed, reaches below the height
// grid (gridMayCollide), in increasing index order within each leaf.
// `root`: the subtree walked (subtreeRoot; 0: the whole tree, -1: none).
template <typename F>
PP_HD void forEachSphereNearArea(const ObjectView& obj, const AreaView& area, const Rigid& X_GO, F&& f,
                                 int root = 0) {
  const BvhView& b = obj.mesh.sphere_bvh;
  if (b.num_nodes == 0 || root < 0) return;
  int stack[kBvhStack];
  int top = 0;
  stack[top++] = root;
  while (top > 0) {
    const BvhNode& n = b.nodes[stack[--top]];
    if (!gridMayCollide(area.grid, transformBox(X_GO, n.box))) continue;
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
