// The search over roots (Sections IV-A, IV-B): floor point x start orientation, in an anytime
// order, each root a pose above its floor point from which a tree starts. Frame G.
#pragma once
#include <Eigen/Core>
#include <vector>

#include "place_planner/model/mesh.h"
#include "place_planner/model/scene.h"
#include "place_planner/search/hanging_starts.h"
#include "place_planner/search/opening_points.h"
#include "place_planner/search/start_orientations.h"

namespace place_planner {

// Anytime order of floor points: amid a wide flat neighbourhood first (more neighbours at the
// same height), then central ones; such points rarely let the object hang over an edge, so
// good poses come early. The set is the paper's; only the order changes.
std::vector<V3> orderFloorPoints(const std::vector<V3>& points, double spacing);

class RootSearch {
 public:
  // The hanging starts first (few, each a peg the object is threaded on), then roots
  // H + f * |orientations| + o: for each floor point (in order), every orientation (likeliest
  // first), so the first trees cover the likeliest orientations.
  RootSearch(const std::vector<V3>& floor_points_G, const std::vector<StartOrientation>& orientations,
             const MeshProperties& object, const AreaModel& area, const V3& d_vis_G,
             std::vector<HangingStart> hanging = {});
  // The first floor points are the middles of openings (opening_points.h): their roots' start
  // orientations are turned about the vertical to fit the opening, their footprints' middles over
  // its middle (fitIntoOpening), each when its root is first posed (a search cut short fits only
  // the roots it ran). `area` and `surface_O` must outlive the search.
  void fitOpenings(int opening_points, const AreaModel& area, const std::vector<V3>& surface_O);
  int size() const { return hangingCount() + static_cast<int>(floor_points_.size() * orientations_.size()); }
  int hangingCount() const { return static_cast<int>(hanging_.size()); }
  // The root's hanging start, null for a root over a floor point.
  const HangingStart* hanging(int root) const { return root < hangingCount() ? &hanging_[root] : nullptr; }
  // Index into the floor points (roots over a floor point only).
  int floorPoint(int root) const { return (root - hangingCount()) / static_cast<int>(orientations_.size()); }
  // Where the root's tree starts on the area: its floor point, or the point of its peg.
  V3 floorPointG(int root) const;
  StartKind kind(int root) const;
  // The root's pose: centre of mass above the floor point along -d_vis, clear of everything
  // (V-A, first step), or threaded on its peg; and the translation to do, along direction().
  // Not thread-safe: it fits an opening's root on first use.
  Rigid pose(int root) const;
  double tmax(int root) const;
  V3 direction(int root) const { return hanging(root) ? v3(0, 0, -1) : d_vis_; }
  double clearance(int root) const;
  const V3& d_vis() const { return d_vis_; }

 private:
  std::vector<HangingStart> hanging_;
  std::vector<V3> floor_points_;
  std::vector<StartOrientation> orientations_;
  Eigen::Vector3d com_O_;
  double radius_;
  V3 d_vis_;
  double hmax_ = 0, hmin_ = 0;  // the area's extent along -d_vis
  // fitOpenings: per opening floor point and orientation, fitted on first use (pose).
  mutable std::vector<OpeningFit> fit_;
  mutable std::vector<char> fitted_;
  const HeightGrid* grid_ = nullptr;
  const std::vector<V3>* surface_O_ = nullptr;
};

}  // namespace place_planner

#include <functional>

#include "place_planner/search/tree_stepper.h"

namespace place_planner {

// Streams the roots into the stepper (anytime): whenever trees end, new roots take their
// places, so a pose that settles in a few steps is not held up by a long tree. The batch starts
// at first_batch and doubles every other step up to `batch`. Each tree depends on its root
// only: the leaves are the same whatever the batch. `after_step(leaves)` is called after every
// batched step with the open roots counted; false stops the search. When every root has ended
// and no hanging leaf is stable, the hanging roots whose leaves after_step marked inside the
// area run once more, their swings checked by all the object's probes (PegLine::probe_swing).
void streamRoots(const RootSearch& roots, TreeStepper& stepper, const V3& com_O, int batch,
                 std::vector<TreeLeaf>& leaves,
                 const std::function<bool(int roots_started, int roots_open)>& after_step);

}  // namespace place_planner
