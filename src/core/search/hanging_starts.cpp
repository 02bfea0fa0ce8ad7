// Hanging roots (hanging_starts.h).
#include "place_planner/search/hanging_starts.h"

#include <algorithm>
#include <cmath>

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
  std::vector<char> off_centre;    // per start: the loop's centre off the peg's axis
  int groups = 0;
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d com_O = toEigen(om.com);
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
        const Eigen::Matrix3d R = to * from.transpose();
        // How far the object reaches from the loop's centre towards the base and towards the tip.
        double back = 0, front = 0;
        for (const V3& v : om.vertices) {
          const double s = (R * (toEigen(v) - loop.centre)).dot(peg.axis);
          back = std::max(back, -s);
          front = std::max(front, s);
        }
        // Along the peg: in the middle of the room between the object clear of the base (by a
        // collision distance and a millimetre) and the loop's far side short of the tip by half
        // its thickness (at most 1 cm: a roll of tape's 5 cm need not be), so a swing or a push
        // meets neither.
        const double length = peg.to_base + peg.to_tip;
        // Where the object reaches farther back than the peg is long (a mug's body below a cup
        // hook's short arm), only the far end is tried: the sweep finds whether what hangs below
        // the peg clears its base (a wall does not let it; a hook's stem above the arm does).
        const double farthest = length - 0.5 * loop.thickness - std::min(0.5 * loop.thickness, 0.01);
        const double nearest = std::min(back + cd + 0.001, farthest);
        if (farthest <= 0) continue;
        // Threaded to the middle of that room or, where the sweep finds the middle blocked (a
        // wide loop on a steep arm meets the post behind it), to its far end: on a rising peg it
        // then slides to where it rests either way (below).
        // Where a knob on the tip or a scan's rough loop leaves both blocked, the same with the
        // loop's centre off the peg's axis by a third of the room round the peg, up, down and
        // to either side (the loop's centre is found to a silhouette pixel); and lifted by all
        // that room but a collision distance and a millimetre, the peg just inside the loop's
        // bottom, so the opening passes over a tip that turns up (a cup hook), then lowered.
        const double room = loop.radius - peg.half_width;
        const double off = room / 3.0, lift = std::max(off, room - cd - 0.001);
        const Eigen::Vector3d side = peg.axis.cross(hang);
        const Eigen::Vector3d offsets[] = {Eigen::Vector3d::Zero(), off * hang, -off * hang, off * side, -off * side,
                                           -lift * hang};
        for (int k = 0; k < 12; ++k) {
          if (k % 2 == 0 && nearest >= farthest) continue;  // the middle is the far end
          if (k / 2 == 5 && lift <= off) continue;          // a loop too tight to lift: as off-centre up
          const Eigen::Vector3d& o = offsets[k / 2];
          const double along = k % 2 ? farthest : 0.5 * (nearest + farthest);
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
          Eigen::Isometry3d pre = X;
          pre.translation() += h.approach_distance * peg.axis;
          sweeps.push_back(
              TranslationQuery{toRigid(pre), toV3(h.approach), h.approach_distance + 0.01});
          starts.push_back(h);
          group.push_back(groups);
          off_centre.push_back(k >= 2);
        }
        ++groups;
      }
    }
  if (starts.empty()) return starts;
  // Threaded by the sweep: its first contact (V-A's distance kernel) is past the threaded pose.
  // The centred starts are swept first, the off-centre ones only for what that left unthreaded.
  std::vector<double> t(starts.size(), -1.0);  // -1: not swept
  auto isFree = [&](size_t i) { return t[i] >= starts[i].approach_distance + 1e-3; };
  std::vector<char> threaded(groups, 0);  // one start per peg, loop and way round: the first free
  for (const char phase : {0, 1}) {
    std::vector<TranslationQuery> batch;
    std::vector<size_t> which;
    for (size_t i = 0; i < starts.size(); ++i)
      if (off_centre[i] == phase && !threaded[group[i]]) {
        batch.push_back(sweeps[i]);
        which.push_back(i);
      }
    if (batch.empty()) continue;
    std::vector<double> tb;
    backend.distance(batch, tb);
    for (size_t j = 0; j < which.size(); ++j) t[which[j]] = tb[j];
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
