// Robust stability (robustness.h): perturbed releases settled by the tree stepper.
#include "place_planner/judgement/robustness.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace place_planner {
namespace {

constexpr int kTrials = 12;
const bool kTraceTrials = std::getenv("PP_ROBUST_TRACE") != nullptr;

struct Trial {
  Rigid X_start;  // released here, above the area
  V3 com_O;
};

// Trial k of pose X: 0-3 shifted by delta along +-x, +-y; 4-7 tilted by epsilon about +-x,
// +-y through the centre of mass; 8-11 with the centre of mass moved along +-x, +-y (G).
// The posed object's extent along x and y of G.
Eigen::Vector2d horizontalExtent(const Rigid& X, const ObjectModel& om) {
  Eigen::Vector2d lo(kInf, kInf), hi(-kInf, -kInf);
  for (const V3& v : om.vertices) {
    const V3 q = apply(X, v);
    lo = lo.cwiseMin(Eigen::Vector2d(q.x, q.y));
    hi = hi.cwiseMax(Eigen::Vector2d(q.x, q.y));
  }
  return hi - lo;
}

const Eigen::Vector3d kTrialDirs[4] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};

// `shift`: the shifted releases' offset (p.shift, or less where the area is nearer).
Trial makeTrial(const Rigid& X, int k, const ObjectModel& om, const Eigen::Vector2d& extent,
                const RobustnessParams& p, const Eigen::Vector3d& support, double shift) {
  const Eigen::Vector3d d = kTrialDirs[k % 4];
  Trial t{X, om.com};
  const Eigen::Vector3d com = toEigen(apply(X, om.com));
  double lift = p.lift;
  if (k < 4) {
    t.X_start.t = t.X_start.t + toV3(shift * d);
    if (support.allFinite()) lift += p.shift;  // hanging: so that a loop moved across its peg clears it
  } else if (k < 8) {
    // Tilted about the horizontal axis perpendicular to d: lifted clear of what it turns into.
    const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(d);
    if (support.allFinite()) {
      t.X_start = rotatedAbout(X, support, axis, p.tilt);  // hanging: swung about its support
    } else {
      t.X_start = rotatedAbout(X, com, axis, p.tilt);
      lift += std::sin(p.tilt) * om.bounding_radius;
    }
  } else {
    // The centre of mass off horizontally (G) by com_offset times the object's extent along
    // that direction (a slender object's error is slender too), expressed in O.
    const double along = d.x() != 0 ? extent.x() : extent.y();
    t.com_O = om.com + rotateInv(X, toV3(std::max(p.com_offset * along, p.min_com_offset) * d));
  }
  t.X_start.t = t.X_start.t + v3(0, 0, lift);
  return t;
}

}  // namespace

namespace {
std::vector<Robustness> check(const std::vector<Rigid>& X_GO, const TreeContext& ctx_in,
                              const RobustnessParams& p, const std::function<bool()>& keep_going,
                              bool tilted_trials, const std::vector<Eigen::Vector3d>& supports,
                              const std::vector<PegLine>& pegs) {
  TreeContext ctx = ctx_in;
  ctx.max_rotations = p.max_rotations;
  ctx.times = nullptr;  // the caller times the whole check
  TreeStepper stepper(ctx);
  const ObjectModel& om = ctx.om;
  std::vector<Eigen::Vector2d> extent;
  for (const Rigid& X : X_GO) extent.push_back(horizontalExtent(X, om));
  // A trial holds when it ended (all its leaves: a tree may branch) near the pose, stable or
  // statically supported (centre of mass inside its support with the tipping margin: a release
  // that settles a fraction of a degree off flat has a partial contact band).
  std::vector<int> state(X_GO.size() * kTrials, 0);  // 0 open or no leaf, 1 held, -1 failed
  if (!tilted_trials)
    for (size_t i = 0; i < X_GO.size(); ++i)
      for (int k = 4; k < 8; ++k) state[i * kTrials + k] = 1;
  // Tilted trials caught where they landed (stable, near, within the release tilt): their end
  // poses, each judged by its own shift and centre-of-mass trials below.
  std::vector<std::vector<Rigid>> caught(state.size());
  std::vector<double> tip(state.size(), kInf);
  std::vector<int> failures(X_GO.size(), 0);
  // Every trial must hold when min_share is 1: a pose's first failure ends its other trials.
  auto allowedFor = [](double share) { return static_cast<int>(std::floor((1.0 - share) * kTrials + 1e-9)); };
  const V3 k1_O = toV3(Eigen::Vector3d(om.principal_axes.col(0)));
  // Hanging poses (supports finite): pendulums, whose trials swing (see below).
  auto pendulum = [&](size_t i) { return i < supports.size() && supports[i].allFinite(); };
  std::vector<int> allowed(X_GO.size());
  for (size_t i = 0; i < X_GO.size(); ++i) allowed[i] = allowedFor(pendulum(i) ? p.min_share_hanging : p.min_share);
  // any_turn: only the centre of mass counts (a hanging pose's trials, see the hold test).
  auto near = [&](const Rigid& X, int trial, double scale, bool any_turn = false) {
    const size_t i = trial / kTrials;
    const Eigen::Vector3d c0 = toEigen(apply(X_GO[i], om.com)), c1 = toEigen(apply(X, om.com));
    const double moved = (c1 - c0).norm();
    if (moved > scale * p.end_distance) return false;
    if (any_turn || rotationAngle(X, X_GO[i]) <= scale * p.end_angle) return true;
    // Released at the pose with the centre of mass off, an object lying on its side that only
    // rolls about its long axis k1 to its heavier side stays where it was put (an elliptic
    // rod's rest roll moves ten degrees for 1.6 mm of centre of mass): these trials also hold
    // when k1 kept its direction and the centre of mass moved less than end_roll_move.
    if (trial % kTrials < 8 || moved > scale * p.end_roll_move) return false;
    const double c = std::clamp(dot(rotate(X, k1_O), rotate(X_GO[i], k1_O)), -1.0, 1.0);
    return std::acos(c) <= scale * p.end_angle;
  };
  auto fail = [&](int trial) {
    if (state[trial] != -1) ++failures[trial / kTrials];
    state[trial] = -1;
  };
  if (kTraceTrials)
    for (size_t i = 0; i < X_GO.size(); ++i)
      std::fprintf(stderr, "pose %zu at %.3f %.3f %.3f\n", i, X_GO[i].t.x, X_GO[i].t.y, X_GO[i].t.z);
  // A hanging pose's shifted releases stay in free space: a mug hung at a peg's root, against
  // the wall, cannot be let go a few millimetres inside the wall. Each shift is cut to the first
  // contact along it (V-A's translation, from the lifted release), less a millimetre.
  std::vector<double> shift(X_GO.size() * 4, p.shift);
  {
    std::vector<TranslationQuery> q;
    std::vector<size_t> at;
    for (size_t i = 0; i < X_GO.size(); ++i)
      if (pendulum(i)) {
        Rigid lifted = X_GO[i];
        lifted.t = lifted.t + v3(0, 0, p.lift + p.shift);  // as makeTrial lifts a hanging shift
        for (int k = 0; k < 4; ++k) {
          q.push_back(TranslationQuery{lifted, toV3(kTrialDirs[k]), p.shift + 0.001});
          at.push_back(i * 4 + k);
        }
      }
    std::vector<double> t;
    if (!q.empty()) ctx.backend.distance(q, t);
    for (size_t j = 0; j < at.size(); ++j) shift[at[j]] = std::clamp(t[j] - 0.001, 0.0, p.shift);
  }
  // In phases: the tilted releases first (the likeliest to fail: a pose they turn down needs
  // no other trial), one about x and one about y, then the other two, then the shifts and the
  // centre-of-mass offsets of the poses still open. Most poses that fail, fail the first
  // phase: on books_stack in principal_axis mode (55 poses checked, none robust) the trials'
  // tree nodes went 882 -> 753 against all four tilts at once.
  static constexpr int kPhaseOf[kTrials] = {2, 2, 2, 2, 0, 1, 0, 1, 2, 2, 2, 2};
  std::vector<TreeLeaf> leaves;
  bool finished = true;
  for (int phase = tilted_trials ? 0 : 2; phase < 3 && finished; ++phase) {
    for (size_t i = 0; i < X_GO.size(); ++i) {
      if (failures[i] > allowed[i]) continue;
      for (int k = 0; k < kTrials; ++k) {
        if (kPhaseOf[k] != phase) continue;
        const Eigen::Vector3d none = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
        const Trial t = makeTrial(X_GO[i], k, om, extent[i], p, i < supports.size() ? supports[i] : none,
                                  shift[i * 4 + k % 4]);
        const double tmax = p.lift + std::sin(p.tilt) * om.bounding_radius + 0.05;
        stepper.addRoot(t.X_start, static_cast<int>(i) * kTrials + k, t.com_O, v3(0, 0, -1), tmax,
                        i < pegs.size() ? pegs[i] : PegLine{});
      }
    }
    while (!stepper.empty()) {
      if (keep_going && !keep_going()) {
        finished = false;
        break;
      }
      leaves.clear();
      stepper.step(leaves);
      for (const TreeLeaf& l : leaves) {
        bool held = (l.stable || l.supported) && near(l.X_GO, l.root, 1.0);
        // A hanging pose's trial holds when it ends stable (hanging, or leaning further on a
        // wall below its peg) with its centre of mass within end_distance of the pose's,
        // whatever its turn (a pendulum's rest turns with its centre of mass: a ring with it
        // moved off its middle spins to hang it lowest).
        // Its centre of mass is the trial's (moved off in the centre-of-mass trials).
        const size_t pose = l.root / kTrials;
        if (!held && l.stable && pendulum(pose)) {
          const Trial t = makeTrial(X_GO[pose], l.root % kTrials, om, extent[pose], p, supports[pose],
                                    shift[pose * 4 + l.root % 4]);
          // Measured from where the trial let it go: a pendulum released shifted, or with its
          // centre of mass off, re-hangs about that far from the pose (a ring spins on its peg).
          const double perturb =
              (toEigen(apply(t.X_start, t.com_O)) - toEigen(apply(X_GO[pose], om.com))).head<2>().norm();
          held = (toEigen(apply(l.X_GO, t.com_O)) - toEigen(apply(X_GO[pose], om.com))).norm() <=
                 p.end_distance + perturb;
        }
        const int k = l.root % kTrials;
        if (!held && tilted_trials && p.recheck_caught && k >= 4 && k < 8 && l.stable &&
            l.tipping_angle >= p.caught_min_tip && rotationAngle(l.X_GO, X_GO[l.root / kTrials]) <= p.caught_angle &&
            (toEigen(apply(l.X_GO, om.com)) - toEigen(apply(X_GO[l.root / kTrials], om.com))).norm() <=
                p.end_distance) {
          caught[l.root].push_back(l.X_GO);
          held = true;
          if (kTraceTrials)
            std::fprintf(stderr, "caught at %.3f %.3f %.3f k %d tip %.2f Q %.3f contacts %zu\n",
                         X_GO[l.root / kTrials].t.x, X_GO[l.root / kTrials].t.y, X_GO[l.root / kTrials].t.z, k,
                         l.tipping_angle * 180 / M_PI, l.quality, l.contacts.size());
        }
        if (kTraceTrials) {
          const size_t i = l.root / kTrials;
          const Eigen::Vector3d c0 = toEigen(apply(X_GO[i], om.com)), c1 = toEigen(apply(l.X_GO, om.com));
          std::fprintf(stderr, "trial pose %zu k %d stable %d hanging %d supported %d rest %d moved %.4f turned %.2f tip %.2f held %d\n",
                       i, l.root % kTrials, l.stable, l.hanging, l.supported, l.at_rest, (c1 - c0).norm(),
                       rotationAngle(l.X_GO, X_GO[i]) * 180 / M_PI, l.tipping_angle * 180 / M_PI, held);
        }
        if (!held) fail(l.root);
        else if (state[l.root] == 0) state[l.root] = 1;
        if (held) tip[l.root] = std::min(tip[l.root], l.tipping_angle);
      }
      // A trial that has moved or turned twice the limit away does not come back: failed. A pose
      // with more failures than allowed is decided: its open trials stop.
      stepper.prune([&](const TreeNode& n) {
        const size_t i = n.root / kTrials;
        // A hanging pose's trial swings (its rest turns with its centre of mass): pruned at twice
        // the distance, its turn unbounded (a ring spins).
        if (failures[i] <= allowed[i] && near(n.X_GO, n.root, 2.0, pendulum(i))) return false;
        if (failures[i] <= allowed[i]) {
          if (kTraceTrials)
            std::fprintf(stderr, "trial pose %zu k %d pruned turned %.2f\n", i, n.root % kTrials,
                         rotationAngle(n.X_GO, X_GO[i]) * 180 / M_PI);
          fail(n.root);
        }
        return true;
      });
    }
  }
  // Trials cut by the caller fail.
  if (!finished)
    for (int r : stepper.openRoots()) fail(r);
  // A caught tilted trial holds when every pose it ended at holds its own shift and
  // centre-of-mass trials (the check without tilted trials: no recursion).
  std::vector<Rigid> ends;
  std::vector<int> owner;
  for (size_t r = 0; r < caught.size(); ++r)
    if (state[r] == 1 && failures[r / kTrials] <= allowed[r / kTrials])
      for (const Rigid& X : caught[r]) {
        ends.push_back(X);
        owner.push_back(static_cast<int>(r));
      }
  if (!ends.empty() && finished) {
    const std::vector<Robustness> re = check(ends, ctx_in, p, keep_going, false, {}, {});
    for (size_t j = 0; j < ends.size(); ++j) {
      if (kTraceTrials)
        std::fprintf(stderr, "recheck at %.3f %.3f %.3f k %d held %d\n", X_GO[owner[j] / kTrials].t.x,
                     X_GO[owner[j] / kTrials].t.y, X_GO[owner[j] / kTrials].t.z, owner[j] % kTrials, re[j].held);
      if (re[j].held < re[j].trials) fail(owner[j]);
    }
  } else if (!ends.empty()) {
    for (int r : owner) fail(r);
  }
  for (int& st : state)
    if (st == 0) st = -1;  // no leaf: the tree vanished (fell off the area)
  std::vector<Robustness> out(X_GO.size());
  for (size_t i = 0; i < X_GO.size(); ++i) {
    Robustness& r = out[i];
    r.trials = kTrials;
    r.min_tipping_angle = kInf;
    for (int k = 0; k < kTrials; ++k) {
      const int s = state[i * kTrials + k];
      r.held += s > 0;
      if (s > 0) r.min_tipping_angle = std::min(r.min_tipping_angle, tip[i * kTrials + k]);
    }
    if (r.held == 0) r.min_tipping_angle = 0;
  }
  return out;
}
}  // namespace

std::vector<Robustness> checkRobustness(const std::vector<Rigid>& X_GO, const TreeContext& ctx,
                                        const RobustnessParams& p,
                                        const std::function<bool()>& keep_going,
                                        const std::vector<Eigen::Vector3d>& supports,
                                        const std::vector<PegLine>& pegs) {
  return check(X_GO, ctx, p, keep_going, true, supports, pegs);
}

}  // namespace place_planner
