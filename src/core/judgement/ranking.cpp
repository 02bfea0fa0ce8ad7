// Candidate ranking (ranking.h).
#include "place_planner/judgement/ranking.h"

#include <algorithm>
#include <cmath>

#include "place_planner/judgement/contact_forces.h"
#include "place_planner/search/contact_points.h"
#include "place_planner/manipulation/placeability.h"
#include "place_planner/infra/parallel_for.h"
#include "place_planner/infra/stable_sort.h"

namespace place_planner {
namespace {

// The push a pose resists (contact_forces.h), mean over 8 directions in weights, adds to the
// score with this weight: on a flat area every wide pose resists about mu and Q decides; a pose
// the area holds (a plate between pegs, a box in a slot, a pen in a cup) resists pushes that
// would slide the same pose off a flat top. See doc/method.md ("Push resistance").
constexpr double kPushWeight = 0.25;
// Each release of the robustness check that fails costs the score this much per share (a
// hanging pose may be stable with some failed: robust_min_share_hanging): one of 12 costs
// 0.083, about what separates a pose hanging free from one propped on the wall (Q). Measured on
// the hanging suite (scripts/bench --hanging): 0.5: 27/32 best, top-3 75/80; 1: 27/32, 77/80;
// 2: 27/32, 76/80; a larger share always first: 26/32, 76/80. Standing poses are stable only
// with every release held (robust_min_share 1), so for them it changes nothing. Among poses
// that are not stable the share is a tie-break (kUnstableShareWeight): they rank by Q.
constexpr double kShareWeight = 1.0;
constexpr double kUnstableShareWeight = 0.05;
// How far the object can be tilted before it tips or slips off (the smallest over the releases
// that held, Robustness::min_tipping_angle) adds to the score up to kTipFull, a little more than
// the releases' own tilt (3 degrees): a pose that a 2-3 degree nudge sends off ranks behind one
// that takes 5. Beyond that more margin buys nothing (the validator's turn limit is 5 degrees).
// A hanging pose's margin is negative where a wall below lowers its contacts' centre past the
// centre of mass (tipping_angle, stability.cpp): it counts as none.
// Measured: a scanned mug on a peg with 2.5 degrees to spare, ranked first on Q, swung off its
// peg in Bullet (hanging suite, best 36/40 -> 37/40, top-3 105 -> 106/111); a 10 degree cap
// also reorders lying bottles whose margins differ at 3-10 degrees (scan suite top-3 145 -> 144).
constexpr double kTipWeight = 0.05, kTipFull = 5.0 * M_PI / 180.0;
// A stable pose's distance to a drop-off of the area (RankingInput::drop_margin, 0 to 1) adds
// to the score with this weight: a mug on a tray divider's 6 mm top (margin about 0.5) ranks
// behind the same mug on the compartment's floor (1), whose Q is the same to 0.01.
constexpr double kDropWeight = 0.1;
// Leaves whose down directions (in O) lie within this rest on the same face (ranking's
// robustness order).
constexpr double kSameFaceDeg = 15.0;
// Intermediate poses closer than this to the one before are merged into it (m, rad).
constexpr double kPathStep = 0.002, kPathTurn = 2.0 * M_PI / 180.0;

struct Item {
  size_t leaf;
  bool stable;
  double quality, reorientation;
  Robustness robustness;
  bool checked = false;
  long preference = 0;  // config.rank_order's key, lower first
  Placement placement;
  SupportKind support = SupportKind::kSeen;  // on unseen surface: after the seen ones
  PushResistance push;
  bool pushed = false;  // push computed
  double drop_margin = 1.0;
  double score() const {
    const double share = checked ? robustness.share() : 1.0;
    const double w = stable ? kShareWeight : kUnstableShareWeight;
    const double tip = checked ? std::clamp(robustness.min_tipping_angle / kTipFull, 0.0, 1.0) : 1.0;
    return quality - 0.05 * reorientation / M_PI - w * (1.0 - share) + kPushWeight * push.mean + kTipWeight * tip -
           kDropWeight * (1.0 - drop_margin);
  }
};

// Scores equal to 1e-3 are ties (the same placement seen through another frame differs only
// by rounding); ties go to the pose nearer the frame's vertical axis, then by position on a 1 mm
// lattice: an order that depends on the geometry, not on the order roots were tried in.
long quantised(double v, double step) { return std::lround(v / step); }

void sortItems(std::vector<Item>& items, const std::vector<TreeLeaf>& leaves) {
  stableSortAligned(items, [&](const Item& a, const Item& b) {
    if (a.stable != b.stable) return a.stable;
    // Unseen is not empty: a pose on seen surface first, where one exists (completion.h).
    const bool ua = a.support != SupportKind::kSeen, ub = b.support != SupportKind::kSeen;
    if (a.stable && ua != ub) return !ua;
    if (a.preference != b.preference) return a.preference < b.preference;
    const long sa = quantised(a.score(), 1e-3), sb = quantised(b.score(), 1e-3);
    if (sa != sb) return sa > sb;
    const V3 pa = leaves[a.leaf].X_GO.t, pb = leaves[b.leaf].X_GO.t;
    const long ra = quantised(pa.x * pa.x + pa.y * pa.y, 1e-6), rb = quantised(pb.x * pb.x + pb.y * pb.y, 1e-6);
    if (ra != rb) return ra < rb;
    const long xa = quantised(pa.x, 1e-3), xb = quantised(pb.x, 1e-3);
    if (xa != xb) return xa < xb;
    const long ya = quantised(pa.y, 1e-3), yb = quantised(pb.y, 1e-3);
    if (ya != yb) return ya < yb;
    return leaves[a.leaf].root < leaves[b.leaf].root;
  });
}

}  // namespace

std::vector<Candidate> rankCandidates(const RankingInput& in, const PlannerConfig& config,
                                      const RobustnessCheck& check, PlanStats* stats,
                                      const PlacementCheck& place) {
  const auto& leaves = in.leaves;
  const int ranked = config.rankedCandidates();  // checked and ranked; max_candidates returned
  std::vector<Item> items;
  const Eigen::Vector3d near_G = in.R_GW * config.prefer_near;
  for (size_t i = 0; i < leaves.size(); ++i) {
    const TreeLeaf& l = leaves[i];
    if (l.quality < config.min_quality) continue;
    // The kind of placement asked for (config.h): hanging or standing only.
    if ((config.placement == PlacementKind::kStanding && l.hanging) ||
        (config.placement == PlacementKind::kHanging && !l.hanging))
      continue;
    const Eigen::Isometry3d X = toIsometry(l.X_GO);
    if (!gripperTiltOk(X.linear(), config)) {
      if (stats) ++stats->gripper_tilt_rejected;
      continue;
    }
    Item it{i, l.stable, l.quality, rotationAngle(in.R_held_G, X.linear()), {}, false, 0, {}, SupportKind::kSeen, {}, false};
    if (l.stable && in.completed_support) it.support = in.completed_support(i);
    if (l.stable && !l.hanging && in.drop_margin) it.drop_margin = in.drop_margin(i);
    if (config.rank_order == RankOrder::kLowest) it.preference = quantised((X * in.com_O).z(), 0.005);
    if (config.rank_order == RankOrder::kNearest) it.preference = quantised((X * in.com_O - near_G).norm(), 0.005);
    items.push_back(it);
  }
  sortItems(items, leaves);
  // Merge: a pose near a better one is the same candidate (G and W differ by a rotation only).
  const double merge_angle = config.merge_angle_deg * M_PI / 180.0;
  std::vector<Item> distinct;
  std::vector<Eigen::Isometry3d> kept;  // poses of `distinct`, converted once
  // A leaf the search already found robust stands for its group: it needs no check when the
  // budget has run out by the ranking.
  auto robustAlready = [&](size_t leaf) {
    return std::find(in.robust_leaves.begin(), in.robust_leaves.end(), leaf) != in.robust_leaves.end();
  };
  auto close = [&](const Eigen::Isometry3d& X, const Eigen::Isometry3d& Y) {
    return (X.translation() - Y.translation()).norm() < config.merge_distance &&
           rotationAngle(X.linear(), Y.linear()) < merge_angle;
  };
  for (const Item& it : items) {
    const Eigen::Isometry3d X = toIsometry(leaves[it.leaf].X_GO);
    std::vector<size_t> near;
    for (size_t k = 0; k < kept.size(); ++k)
      if (close(X, kept[k])) near.push_back(k);
    if (!near.empty()) {
      // It takes the group's place only where it is near that group alone (merged stays merged).
      const size_t dup = near.front();
      if (near.size() == 1 && it.stable && robustAlready(it.leaf) && !robustAlready(distinct[dup].leaf)) {
        distinct[dup] = it;
        kept[dup] = X;
      }
      continue;
    }
    distinct.push_back(it);
    kept.push_back(X);
  }
  // Placeability first (cheap next to robustness): a blocked candidate is not stable.
  int place_checks = 0;
  auto placeable = [&](Item& it) {
    if (!place || it.placement.checked) return it.placement.blocked.empty();
    // Bounded work: when the gripper blocks pose after pose, the search for more stops.
    if (++place_checks > 10L * ranked) return false;
    it.placement = place(it.leaf);
    if (it.placement.blocked.empty()) return true;
    if (stats) ++stats->gripper_rejected;
    it.stable = false;
    return false;
  };
  // Robustness, best stable first, until rankedCandidates() robust ones are found.
  if (config.robust_check && check) {
    // A leaf's robustness decides its stable flag; true when it holds.
    auto record = [&](Item& it, const Robustness& r) {
      it.robustness = r;
      it.checked = r.trials > 0;
      it.stable = it.checked && config.robustShare(r.share(), leaves[it.leaf].hanging);
      return it.stable;
    };
    int robust = 0, checked = 0;
    int robust_seen = 0;  // ... of them on seen surface: then no pose on unseen surface is checked
    // Which way is down in the object (O) at a leaf: the face it rests on, whatever its yaw and
    // place. While no pose has held, a face whose poses failed their releases is tried again only
    // after the faces not yet tried (on seen surface before unseen, as ranked): a bottle laid on
    // its side fails at every floor point of a table alike, and the bounded checks below went to
    // 40 such poses while 36 robust ones standing upright ranked after them (a held-out bottle's
    // scan, seed 1). Once one holds, the checks go on in rank order (deferring failing faces
    // then let lower-ranked faces fill max_candidates: a sugar box in the rack lost a confirmed
    // pose of its top 5).
    auto down = [&](const Item& it) { return rotateInv(leaves[it.leaf].X_GO, v3(0, 0, -1)); };
    std::vector<V3> failed_down;
    const double same_face = std::cos(kSameFaceDeg * M_PI / 180.0);
    auto failing = [&](const Item& it) {
      const V3 d = down(it);
      return robust == 0 &&
             std::any_of(failed_down.begin(), failed_down.end(), [&](const V3& f) { return dot(d, f) > same_face; });
    };
    std::vector<bool> tried(distinct.size(), false);
    // Bounded work: at most four times rankedCandidates() leaves are checked.
    while (robust < ranked && checked < 4L * ranked) {
      // The best stable leaves not tried yet: on seen surface first, then not on a failing face.
      std::vector<std::pair<int, size_t>> order;  // (2 * unseen + failing, rank)
      for (size_t k = 0; k < distinct.size(); ++k)
        if (!tried[k] && distinct[k].stable && (robust_seen == 0 || distinct[k].support == SupportKind::kSeen))
          order.emplace_back(2 * (distinct[k].support != SupportKind::kSeen) + failing(distinct[k]), k);
      std::stable_sort(order.begin(), order.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      std::vector<size_t> batch, where;
      for (const auto& [group, k] : order) {
        if (batch.size() >= static_cast<size_t>(ranked - robust)) break;
        tried[k] = true;
        if (placeable(distinct[k])) {
          batch.push_back(distinct[k].leaf);
          where.push_back(k);
        }
      }
      if (batch.empty()) break;
      const std::vector<Robustness> rs = check(batch);
      checked += static_cast<int>(batch.size());
      for (size_t j = 0; j < where.size(); ++j) {
        Item& it = distinct[where[j]];
        const bool ok = record(it, rs[j]);
        if (stats) {
          stats->robustness_checked += it.checked;
          stats->robustness_rejected += !ok;
        }
        robust += ok;
        robust_seen += ok && it.support == SupportKind::kSeen;
        if (!ok) failed_down.push_back(down(it));
      }
    }
    // Cut by a cancel or the budget, the checks above may end before the leaves the search found
    // robust: those stay robust (their results are the search's, not checked again), so what was
    // found is returned.
    std::vector<size_t> found, where;
    const bool cut = in.cut && in.cut();
    for (size_t k = 0; k < distinct.size() && cut; ++k)
      if (distinct[k].stable && !distinct[k].checked && robustAlready(distinct[k].leaf) && placeable(distinct[k])) {
        found.push_back(distinct[k].leaf);
        where.push_back(k);
      }
    if (!found.empty()) {
      const std::vector<Robustness> rs = check(found);
      for (size_t j = 0; j < where.size(); ++j) record(distinct[where[j]], rs[j]);
    }
    // Stable leaves never checked (out of time, or beyond the candidates needed) are not
    // claimed stable.
    for (Item& it : distinct)
      if (it.stable && !it.checked) it.stable = false;
    sortItems(distinct, leaves);
  }
  const Eigen::Matrix3d R_WG = in.R_GW.transpose();
  std::vector<Candidate> out;
  if (place) {
    // Without the robustness loop, or past it: the rest are checked in rank order.
    int kept = 0;
    for (Item& it : distinct) {
      if (kept >= ranked) break;
      kept += placeable(it) || config.keep_colliding;
    }
    sortItems(distinct, leaves);
  }
  // Unseen is not empty (model/completion.h): where a pose on seen surface holds, a pose that
  // rests on surface the scans never saw (a cap over the object's unseen side, the unseen border
  // of the area) is not offered as stable; it is offered, flagged, only where none on seen
  // surface holds. Ranked after the seen ones, half of them moved in Bullet over the held-out
  // scans, against 2 % of the seen ones (doc/validation.md, "Unseen support withheld").
  auto offered = [&](const Item& it) {
    return !(place && !it.placement.checked) && (it.placement.blocked.empty() || config.keep_colliding);
  };
  if (std::any_of(distinct.begin(), distinct.end(),
                  [&](const Item& it) { return it.stable && it.support == SupportKind::kSeen && offered(it); }))
    for (Item& it : distinct)
      if (it.support != SupportKind::kSeen) {  // statically stable (the support of those only is known)
        it.stable = false;
        if (stats) ++stats->unseen_withheld;
      }
  // Push resistance of the best stable candidates (bounded: rankedCandidates() of them),
  // from the contacts in cells of a tenth of the object's radius; they are ranked again with it.
  const ForceModelParams forces{config.friction, 8, 3.0};
  std::vector<Item*> to_push;
  for (Item& it : distinct) {
    if (static_cast<int>(to_push.size()) >= ranked) break;
    if (offered(it) && it.stable) to_push.push_back(&it);
  }
  // One small LP per direction and candidate, each candidate on its own: over the threads.
  parallelFor(to_push.size(), config.threads, [&](size_t k) {
    Item& it = *to_push[k];
    const TreeLeaf& l = leaves[it.leaf];
    it.push = pushResistance(reduceContacts(l.contacts, in.object_radius / 10.0), toIsometry(l.X_GO) * in.com_O, forces,
                             1.0, std::min(0.003, in.object_radius / 10.0));
    it.pushed = true;
  });
  sortItems(distinct, leaves);
  for (const Item& it : distinct) {
    if (static_cast<int>(out.size()) >= config.max_candidates) break;
    if (!offered(it)) continue;
    const TreeLeaf& l = leaves[it.leaf];
    Candidate c;
    const Eigen::Isometry3d X_GO = toIsometry(l.X_GO);
    c.X_WO.linear() = R_WG * X_GO.linear();
    c.X_WO.translation() = R_WG * X_GO.translation();
    c.quality = l.quality;
    c.stable = it.stable;
    c.support = it.support;
    c.robustness = it.robustness;
    c.start = in.root_kind[l.root];
    c.hanging = l.hanging;
    c.reorientation = it.reorientation;
    c.drop_margin = it.drop_margin;
    if (it.pushed) {
      c.push_resistance = it.push.min;
      c.push_resistance_mean = it.push.mean;
      c.push_weakest_W = R_WG * it.push.weakest;
    }
    // The result summarises the contacts in cells of a third of the object's radius.
    for (const auto& p : reduceContacts(l.contacts, in.object_radius / 3.0))
      c.contacts.push_back({R_WG * p.p_W, R_WG * p.n_W});
    c.floor_point_W = in.root_floor_point_W[l.root];
    c.placement = it.placement;
    if (config.has_grasp) {
      c.has_gripper_pose = true;
      c.X_WF = c.X_WO * config.grasp;
    }
    for (const Rigid& X : l.path) {
      const Eigen::Isometry3d T = toIsometry(X);
      Eigen::Isometry3d W = Eigen::Isometry3d::Identity();
      W.linear() = R_WG * T.linear();
      W.translation() = R_WG * T.translation();
      // A pose within 2 mm and 2 degrees of the one before replaces it (a swing's settle creeps
      // in steps a robot need not follow); the pre-placement pose stays the first, the goal the
      // last.
      if (c.intermediate_poses.size() >= 2) {
        const Eigen::Isometry3d& P = c.intermediate_poses.back();
        const double turn = Eigen::AngleAxisd(P.linear().transpose() * W.linear()).angle();
        if ((P.translation() - W.translation()).norm() < kPathStep && turn < kPathTurn) {
          c.intermediate_poses.back() = W;
          continue;
        }
      }
      c.intermediate_poses.push_back(W);
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace place_planner
