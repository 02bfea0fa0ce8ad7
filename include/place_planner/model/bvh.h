// Bounding-volume hierarchy over boxes (triangles, edges or points), flat arrays so the same
// traversal runs on the host and in CUDA kernels. Plays the role of the paper's kd-tree
// (Section V-A: "kd-restart"): it selects the patches a ray, a sweep or an arc can reach.
#pragma once
#include <vector>

#include "place_planner/kernels/geometry.h"

namespace place_planner {

struct BvhNode {
  Aabb box;
  int left;   // child index, -1 for a leaf
  int right;
  int first;  // leaf: range [first, first + count) of Bvh::order
  int count;
};

struct Bvh {
  std::vector<BvhNode> nodes;  // nodes[0] is the root (empty tree: no nodes)
  std::vector<int> order;      // primitive indices in leaf order
};

// Builds over the primitive boxes: median split along the longest axis of the centroids,
// leaves of at most `leaf_size` primitives.
Bvh buildBvh(const std::vector<Aabb>& boxes, int leaf_size = 1);

// Flat view for traversal (host or device pointers).
struct BvhView {
  const BvhNode* nodes;
  const int* order;
  int num_nodes;
};

inline BvhView view(const Bvh& b) {
  return BvhView{b.nodes.data(), b.order.data(), static_cast<int>(b.nodes.size())};
}

constexpr int kBvhStack = 64;

// Visits the leaves whose boxes overlap `query`, depth first; leaf(node) returns true to stop
// the walk. Returns true when a leaf stopped it.
template <typename Leaf>
PP_HD bool bvhVisitLeaves(const BvhView& bvh, const Aabb& query, Leaf&& leaf) {
  if (bvh.num_nodes == 0) return false;
  int stack[kBvhStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = bvh.nodes[stack[--top]];
    if (!aabbOverlap(n.box, query)) continue;
    if (n.left < 0) {
      if (leaf(n)) return true;
    } else if (top + 2 <= kBvhStack) {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return false;
}

// Calls f(primitive) for every primitive whose leaf box overlaps `query`.
template <typename F>
PP_HD void bvhQuery(const BvhView& bvh, const Aabb& query, F&& f) {
  bvhVisitLeaves(bvh, query, [&](const BvhNode& n) {
    for (int i = n.first; i < n.first + n.count; ++i) f(bvh.order[i]);
    return false;
  });
}

// True when some leaf box overlaps `query` (early exit).
PP_HD bool bvhAnyOverlap(const BvhView& bvh, const Aabb& query) {
  return bvhVisitLeaves(bvh, query, [](const BvhNode&) { return true; });
}

// Ray slab test: does o + t d, t in [0, tmax], meet the box?
PP_HD bool rayBox(V3 o, V3 d, double tmax, const Aabb& b) {
  double t0 = 0, t1 = tmax;
  const double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
  const double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
  for (int k = 0; k < 3; ++k) {
    if (fabs(dd[k]) < 1e-300) {
      if (oo[k] < lo[k] || oo[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - oo[k]) / dd[k], tb = (hi[k] - oo[k]) / dd[k];
    if (ta > tb) {
      const double t = ta;
      ta = tb;
      tb = t;
    }
    t0 = maxv(t0, ta);
    t1 = minv(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// Calls f(primitive) for primitives whose leaf boxes the ray segment may reach; f returns the
// new tmax (distance of the closest hit so far) so farther subtrees are culled.
template <typename F>
PP_HD double bvhRay(const BvhView& bvh, V3 o, V3 d, double tmax, F&& f) {
  if (bvh.num_nodes == 0) return tmax;
  int stack[kBvhStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = bvh.nodes[stack[--top]];
    if (!rayBox(o, d, tmax, n.box)) continue;
    if (n.left < 0) {
      for (int i = n.first; i < n.first + n.count; ++i) tmax = minv(tmax, f(bvh.order[i]));
    } else if (top + 2 <= kBvhStack) {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return tmax;
}

}  // namespace place_planner
