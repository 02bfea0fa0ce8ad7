// Hanging roots (hanging_starts.h).
#include "place_planner/search/hanging_starts.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace place_planner {
namespace {
// m: short of the first contact towards the base (a release a few millimetres off still clears it).
constexpr double kBaseGap = 0.001;
}  // namespace

std::vector<HangingStart> hangingStarts(const std::vector<Peg>& pegs, const std::vector<Loop>& loops,
                                        const ObjectModel& om, Backend& backend, double cd, double friction) {
  // A peg rising more than half the friction angle (the margin a standing pose keeps against
  // gravity tilted that far, stability.cpp) is hung where the object slides down to; on a
  // flatter one it stays where it is threaded.
  const double rising_slope = std::sin(0.5 * std::atan(friction));
  std::vector<HangingStart> starts;
  std::vector<TranslationQuery> sweeps;
  std::vector<int> group;          // per start: its peg, loop and way round
  // per start: its phase (0 centred, 1 off the axis, 2 lifted at its rest, 3 rolled, 4 rolled and turned)
  std::vector<char> phase_of;
  int groups = 0;
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d com_O = toEigen(om.com);
  // Rolled and also turned about the vertical by 20, 35 or 50 degrees either way (phase 4,
  // only where phases 0-3 leave it unthreaded; the least turn that threads is kept): a
  // mug's body beside its handle swings away from the wall a short J-hook stands on, so the
  // handle passes the hook's tip before the body meets the wall. On 36 J-hooks (4-6 cm out,
  // rising 0-20 degrees, tips 1.5-2.5 cm, 6-8 mm wire) 35 degrees alone hung the YCB mug on
  // 15 and the tall mug on 19; the three turns 17 and 24 (none before: 0 and 10).
  // (roll about the peg, yaw about the vertical) of each start off its rest: the rest, rolled a
  // quarter either way (phase 3, below), and those also turned (phase 4).
  std::vector<std::pair<double, double>> turns = {{0.0, 0.0}, {0.5 * M_PI, 0.0}, {-0.5 * M_PI, 0.0}};
  for (const double yaw_deg : {20.0, 35.0, 50.0})
    for (const double roll : {0.5 * M_PI, -0.5 * M_PI})
      for (const double sign : {1.0, -1.0}) turns.emplace_back(roll, sign * yaw_deg * M_PI / 180.0);
  for (const Peg& peg : pegs)
    for (const Loop& loop : loops) {
      // The loop must go round the peg (the sweep below checks it with the sphere models).
      if (loop.radius < peg.half_width + 0.001) continue;
      const Eigen::Vector3d hang = (down - down.dot(peg.axis) * peg.axis).normalized();  // down, across the peg
      Eigen::Vector3d below = com_O - loop.centre;
      below -= below.dot(loop.axis) * loop.axis;
      if (below.norm() < 1e-6) below = loop.axis.unitOrthogonal();  // a ring: any way round
      below.normalize();
      for (const double sign : {1.0, -1.0}) {
        // R takes the loop's axis to the peg's (either way) and `below` to straight down across it.
        Eigen::Matrix3d from, to;
        from << loop.axis, below, loop.axis.cross(below);
        to << sign * peg.axis, hang, (sign * peg.axis).cross(hang);
        const Eigen::Matrix3d R_rest = to * from.transpose();
        // The loop's room round the peg, by its largest circle.
        const double room = loop.radius - peg.half_width;
        // Rolled a quarter turn either way about the peg (phase 3, only where the rest's own
        // starts are all blocked): an opening longer one way than its largest circle (a mug's
        // handle, 6 cm tall and 3 cm deep) passes over a tip that turns up (a J-hook's, a cup
        // hook's) with that length upright, lifted by up to four times the circle's room; the
        // swing then turns it to its rest about the peg.
        for (const auto& [roll, yaw] : turns) {
          const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                    Eigen::AngleAxisd(roll, peg.axis).toRotationMatrix() * R_rest;
          const char phase = roll == 0.0 ? 0 : yaw == 0.0 ? 3 : 4;
          // How far the object reaches from the loop's centre towards the base.
          double back = 0;
          for (const V3& v : om.vertices) back = std::max(back, -(R * (toEigen(v) - loop.centre)).dot(peg.axis));
          // Along the peg: in the middle of the room between the object clear of the base (by a
          // collision distance and a millimetre) and the loop's far side short of the tip by half
          // its thickness (at most 1 cm: a roll of tape's 5 cm need not be), so a swing or a push
          // meets neither.
          const double length = peg.to_base + peg.to_tip;
          // Where the object reaches farther back than the peg is long (a mug's body below a cup
          // hook's short arm), the room starts at the loop's own clearance of the base: the sweep
          // finds whether what hangs below the peg clears the base (a wall does not let it; a
          // hook's stem above the arm does). (Only the far end was tried there: a pan's slot,
          // threaded against a cup hook's turned-up tip, fell off it in Bullet.)
          const double farthest = length - 0.5 * loop.thickness - std::min(0.5 * loop.thickness, 0.01);
          const double nearest = back + cd + 0.001 < farthest ? back + cd + 0.001
                                                                : std::min(0.5 * loop.thickness + cd + 0.001, farthest);
          if (farthest <= 0) continue;
          // Threaded to the middle of that room or, where the sweep finds the middle blocked (a
          // wide loop on a steep arm meets the post behind it), to its far end: on a rising peg it
          // then slides to where it rests either way (below).
          // Where a knob on the tip or a scan's rough loop leaves both blocked, the same with the
          // loop's centre off the peg's axis by a third of the room round the peg, up, down and
          // to either side (the loop's centre is found to a silhouette pixel); and lifted by all
          // that room but a collision distance and a millimetre, the peg just inside the loop's
          // bottom, so the opening passes over a tip that turns up (a cup hook), then lowered.
          const double off = room / 3.0, lift = std::max(off, room - cd - 0.001);
          const Eigen::Vector3d side = peg.axis.cross(hang);
          std::vector<Eigen::Vector3d> offsets;
          std::vector<char> phases;
          if (phase == 0) {
            offsets = {Eigen::Vector3d::Zero(), off * hang, -off * hang, off * side, -off * side, -lift * hang};
            phases = {0, 1, 1, 1, 1, 1};
            if (lift <= off) offsets.pop_back(), phases.pop_back();  // a loop too tight to lift: as off-centre up
            // At its rest lifted by two to four times the room (phase 2): an opening longer
            // along the hang than its largest circle (a pan handle's slot) passes over a tip
            // that turns up as it hangs.
            for (int k = 2; k <= 4; ++k) offsets.push_back(-(k * room - cd - 0.001) * hang), phases.push_back(2);
          } else {
            for (int k = 1; k <= 4; ++k) offsets.push_back(-(k * room - cd - 0.001) * hang), phases.push_back(phase);
          }
          for (size_t j = 0; j < 2 * offsets.size(); ++j) {
            const bool far_end = j % 2;
            if (!far_end && nearest >= farthest) continue;  // the middle is the far end
            const Eigen::Vector3d& o = offsets[j / 2];
            const double along = far_end ? farthest : 0.5 * (nearest + farthest);
            const Eigen::Vector3d at = peg.point + (along - peg.to_base) * peg.axis + o;
            Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
            X.linear() = R;
            X.translation() = at - R * loop.centre;
            HangingStart h;
            h.X_GO = toRigid(X);
            h.drop = 2 * om.bounding_radius;  // its first contact ends it (V-A), below the opening's top
            h.approach = -peg.axis;
            h.approach_distance = (length - along) + back + 0.01;
            h.peg_point = at;
            h.turned = phase == 4;
            h.room = room;
            Eigen::Isometry3d pre = X;
            pre.translation() += h.approach_distance * peg.axis;
            sweeps.push_back(TranslationQuery{toRigid(pre), toV3(h.approach), h.approach_distance + 0.01});
            starts.push_back(h);
            group.push_back(groups);
            phase_of.push_back(j < 2 ? phase : phases[j / 2]);
          }
        }
        ++groups;
      }
    }
  if (starts.empty()) return starts;
  // Threaded by the sweep: its first contact (V-A's distance kernel) is past the threaded pose.
  // The centred starts are swept first, the off-centre ones only for what that left unthreaded,
  // the ones turned a quarter about the peg only for what both left.
  std::vector<double> t(starts.size(), -1.0);  // -1: not swept
  auto isFree = [&](size_t i) { return t[i] >= starts[i].approach_distance + 1e-3; };
  std::vector<char> threaded(groups, 0);  // one start per peg, loop and way round: the first free
  for (const char phase : {0, 1, 2, 3, 4}) {
    std::vector<TranslationQuery> batch;
    std::vector<size_t> which;
    for (size_t i = 0; i < starts.size(); ++i)
      if (phase_of[i] == phase && !threaded[group[i]]) {
        batch.push_back(sweeps[i]);
        which.push_back(i);
      }
    if (batch.empty()) continue;
    std::vector<double> tb;
    backend.distance(batch, tb);
    for (size_t j = 0; j < which.size(); ++j) t[which[j]] = tb[j];
    if (phase >= 2) {
      // A rolled start lifted that far may pass over the whole object, not through its loop:
      // threaded only when the object meets the peg both ways across it, up and down.
      std::vector<TranslationQuery> ud;
      std::vector<size_t> at;
      for (size_t j = 0; j < which.size(); ++j)
        if (isFree(which[j]))
          for (const double dir : {1.0, -1.0}) {
            ud.push_back(TranslationQuery{starts[which[j]].X_GO, v3(0, 0, dir), 2 * om.bounding_radius});
            at.push_back(which[j]);
          }
      std::vector<double> tu;
      if (!ud.empty()) backend.distance(ud, tu);
      for (size_t k = 0; k < at.size(); ++k)
        if (tu[k] >= 2 * om.bounding_radius) t[at[k]] = -1.0;  // open one way: not round the peg
    }
    for (size_t i = 0; i < starts.size(); ++i)
      if (isFree(i)) threaded[group[i]] = 1;
  }
  std::fill(threaded.begin(), threaded.end(), 0);
  std::vector<HangingStart> free;
  for (size_t i = 0; i < starts.size(); ++i)
    if (!threaded[group[i]] && isFree(i)) {
      threaded[group[i]] = 1;
      free.push_back(starts[i]);
    }
  // On a peg rising towards its tip the object would slide back down it: it is threaded on
  // until its first contact towards the base (V-A's translation along the peg: the wall, a
  // post, what hangs below meeting them first), kBaseGap short of it, and hangs there.
  std::vector<TranslationQuery> slides;
  std::vector<size_t> sliding;
  for (size_t i = 0; i < free.size(); ++i)
    if (free[i].approach.z() < -rising_slope) {
      sliding.push_back(i);
      slides.push_back(TranslationQuery{free[i].X_GO, toV3(free[i].approach), 0.2});
    }
  if (slides.empty()) return free;
  backend.distance(slides, t);
  for (size_t k = 0; k < sliding.size(); ++k) {
    HangingStart& h = free[sliding[k]];
    const double s = std::max(0.0, std::min(t[k], 0.2) - kBaseGap);
    h.X_GO.t = h.X_GO.t + toV3(s * h.approach);
    h.approach_distance += s;
    h.peg_point += s * h.approach;
  }
  return free;
}

}  // namespace place_planner
