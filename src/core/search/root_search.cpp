// The search over roots (root_search.h).
#include "place_planner/search/root_search.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace place_planner {

std::vector<V3> orderFloorPoints(const std::vector<V3>& points, double spacing) {
  if (points.empty()) return points;
  V3 c = v3(0, 0, 0);
  for (const V3& p : points) c = c + p;
  c = (1.0 / points.size()) * c;
  std::vector<std::pair<int, double>> key(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    int flat = 0;
    for (const V3& q : points) {
      const V3 d = q - points[i];
      flat += d.x * d.x + d.y * d.y < 2.5 * spacing * spacing && std::abs(d.z) < 0.005;
    }
    const V3 dc = points[i] - c;
    key[i] = {-flat, dc.x * dc.x + dc.y * dc.y};
  }
  std::vector<size_t> idx(points.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return key[a] < key[b]; });
  std::vector<V3> sorted;
  for (size_t i : idx) sorted.push_back(points[i]);
  return sorted;
}

RootSearch::RootSearch(const std::vector<V3>& floor_points_G, const std::vector<StartOrientation>& orientations,
                       const MeshProperties& object, const AreaModel& area, const V3& d_vis_G,
                       std::vector<HangingStart> hanging)
    : hanging_(std::move(hanging)), floor_points_(floor_points_G), orientations_(orientations), com_O_(object.center_of_mass),
      radius_(object.bounding_radius), d_vis_(d_vis_G) {
  hmax_ = -kInf;
  hmin_ = kInf;
  for (const V3& v : area.vertices) {
    hmax_ = std::max(hmax_, -dot(v, d_vis_));
    hmin_ = std::min(hmin_, -dot(v, d_vis_));
  }
}

double RootSearch::clearance(int root) const {
  return hmax_ + dot(floor_points_[floorPoint(root)], d_vis_) + radius_ + 0.01;
}

V3 RootSearch::floorPointG(int root) const {
  if (const HangingStart* h = hanging(root)) return toV3(h->peg_point);
  return floor_points_[floorPoint(root)];
}

StartKind RootSearch::kind(int root) const {
  if (hanging(root)) return StartKind::kLoopOnPeg;
  return orientations_[(root - hangingCount()) % orientations_.size()].kind;
}

void RootSearch::fitOpenings(int opening_points, const AreaModel& area, const std::vector<V3>& surface_O) {
  const int n = std::min(opening_points, static_cast<int>(floor_points_.size()));
  fit_.assign(static_cast<size_t>(n) * orientations_.size(), OpeningFit{});
  fitted_.assign(fit_.size(), 0);
  grid_ = &area.grid;
  surface_O_ = &surface_O;
}

Rigid RootSearch::pose(int root) const {
  if (const HangingStart* h = hanging(root)) return h->X_GO;
  const size_t o = (root - hangingCount()) % orientations_.size();
  const size_t i = static_cast<size_t>(floorPoint(root)) * orientations_.size() + o;
  if (i < fit_.size() && !fitted_[i]) {
    fit_[i] = fitIntoOpening(*grid_, floor_points_[floorPoint(root)], orientations_[o].R_GO, *surface_O_, toV3(com_O_));
    fitted_[i] = 1;
  }
  const OpeningFit fit = i < fit_.size() ? fit_[i] : OpeningFit{};
  const Eigen::Matrix3d R = Eigen::AngleAxisd(fit.yaw, Eigen::Vector3d::UnitZ()) * orientations_[o].R_GO;
  const Eigen::Vector3d com_G = toEigen(floor_points_[floorPoint(root)]) - clearance(root) * toEigen(d_vis_) +
                                Eigen::Vector3d(fit.shift.x(), fit.shift.y(), 0);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R;
  X.translation() = com_G - R * com_O_;
  return toRigid(X);
}

double RootSearch::tmax(int root) const {
  if (const HangingStart* h = hanging(root)) return h->drop;
  return clearance(root) + radius_ + (hmax_ - hmin_) + 0.01;
}

}  // namespace place_planner

namespace place_planner {

void streamRoots(const RootSearch& roots, TreeStepper& stepper, const V3& com_O, int batch,
                 std::vector<TreeLeaf>& leaves,
                 const std::function<bool(int, int)>& after_step) {
  int next = 0;
  const int first_batch = std::max(4, batch / 6);
  // Where no hanging pose is stable, the hanging trees whose rests the result's guard found
  // inside the area run once more with each swing move checked by all the object's probes
  // (PegLine::probe_swing): a basket's box passed a 12 mm arm between its corner vertices. Only
  // then: a mug swung by its vertices past a round post ends where Bullet keeps it, and stopped
  // at the post by the probes it rested tilted against it, where Bullet turned it off.
  auto pegOf = [&](int k, bool probe_swing) {
    const HangingStart* h = roots.hanging(k);
    PegLine peg = h ? PegLine{h->peg_point, -h->approach, h->turned, h->room} : PegLine{};
    peg.probe_swing = probe_swing;
    return peg;
  };
  std::vector<char> again(static_cast<size_t>(roots.size()), 0);  // 1: to run again, 2: run again
  bool hangs = false;
  size_t seen = leaves.size();
  for (int step = 0, target = first_batch;; ++step) {
    if (step > 0 && step % 2 == 0) target = std::min(batch, 2 * target);
    while (static_cast<int>(stepper.active()) < target && next < roots.size()) {
      stepper.addRoot(roots.pose(next), next, com_O, roots.direction(next), roots.tmax(next), pegOf(next, false));
      ++next;
    }
    if (stepper.empty() && next >= roots.size() && !hangs)
      for (int k = 0; k < roots.size(); ++k)
        if (again[static_cast<size_t>(k)] == 1) {
          again[static_cast<size_t>(k)] = 2;
          stepper.addRoot(roots.pose(k), k, com_O, roots.direction(k), roots.tmax(k), pegOf(k, true));
        }
    if (stepper.empty()) break;
    stepper.step(leaves);
    if (!after_step(next, static_cast<int>(stepper.openRoots().size()))) break;
    for (; seen < leaves.size(); ++seen) {
      const TreeLeaf& l = leaves[seen];
      hangs = hangs || (l.stable && l.hanging);
      if (l.inside && roots.hanging(l.root) && !l.peg.probe_swing && !again[static_cast<size_t>(l.root)])
        again[static_cast<size_t>(l.root)] = 1;
    }
  }
}

}  // namespace place_planner
