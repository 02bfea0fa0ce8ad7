#include "place_planner/model/bvh.h"

#include <algorithm>

namespace place_planner {
namespace {

struct Builder {
  const std::vector<Aabb>& boxes;
  std::vector<V3> centres;
  Bvh bvh;
  int leaf_size;

  int build(int first, int count, int depth) {
    const int id = static_cast<int>(bvh.nodes.size());
    bvh.nodes.push_back(BvhNode{aabbEmpty(), -1, -1, first, count});
    Aabb box = aabbEmpty(), cbox = aabbEmpty();
    for (int i = first; i < first + count; ++i) {
      aabbMerge(box, boxes[bvh.order[i]]);
      aabbAdd(cbox, centres[bvh.order[i]]);
    }
    bvh.nodes[id].box = box;
    // Depth is bounded so the fixed traversal stack (kBvhStack) never overflows.
    if (count <= leaf_size || depth >= kBvhStack / 2 - 2) return id;
    const V3 ext = cbox.hi - cbox.lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    auto key = [&](int i) { return axis == 0 ? centres[i].x : axis == 1 ? centres[i].y : centres[i].z; };
    const int mid = first + count / 2;
    // Ties broken by index: the tree (and every result) is deterministic.
    std::nth_element(bvh.order.begin() + first, bvh.order.begin() + mid,
                     bvh.order.begin() + first + count, [&](int a, int b) {
                       const double ka = key(a), kb = key(b);
                       return ka < kb || (ka == kb && a < b);
                     });
    const int l = build(first, mid - first, depth + 1);
    const int r = build(mid, first + count - mid, depth + 1);
    bvh.nodes[id].left = l;
    bvh.nodes[id].right = r;
    return id;
  }
};

}  // namespace

Bvh buildBvh(const std::vector<Aabb>& boxes, int leaf_size) {
  Builder b{boxes, {}, {}, std::max(1, leaf_size)};
  if (boxes.empty()) return b.bvh;
  b.centres.resize(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) b.centres[i] = 0.5 * (boxes[i].lo + boxes[i].hi);
  b.bvh.order.resize(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) b.bvh.order[i] = static_cast<int>(i);
  b.bvh.nodes.reserve(2 * boxes.size() / b.leaf_size + 2);
  b.build(0, static_cast<int>(boxes.size()), 0);
  return b.bvh;
}

}  // namespace place_planner
