// Candidate ranking (Section VI's Q, with robustness and re-orientation): leaves of all trees
// into the ranked, merged candidates of a PlanResult. Leaves are in G, candidates in W.
#pragma once
#include <Eigen/Geometry>
#include <functional>
#include <vector>

#include "place_planner/planner.h"
#include "place_planner/search/tree_stepper.h"

namespace place_planner {

struct RankingInput {
  const std::vector<TreeLeaf>& leaves;
  const std::vector<StartKind>& root_kind;      // per root index
  const std::vector<Eigen::Vector3d>& root_floor_point_W;  // per root index
  Eigen::Matrix3d R_GW;       // planning frame W into G
  Eigen::Matrix3d R_held_G;   // the held orientation, for the re-orientation key
  double object_radius = 0;   // m, bounding radius (contact summaries)
  Eigen::Vector3d com_O = Eigen::Vector3d::Zero();  // object's centre of mass (kLowest)
  // Leaves the search already found robust (kept when merging).
  std::vector<size_t> robust_leaves = {};
  // True once a cancel or the budget has cut the plan: the robust leaves above stay robust even
  // where the ranking's own checks did not reach them.
  std::function<bool()> cut = {};
  // True when a stable leaf rests on completed surface (model/completion.h): such poses rank
  // after every stable pose on seen surface. Empty: the object was closed.
  std::function<SupportKind(size_t)> completed_support = {};
  // A stable standing leaf's distance to a drop-off of the area, 0 to 1 (drop_margin.h). Empty:
  // not counted.
  std::function<double(size_t)> drop_margin = {};
};

// Robustness of the leaves given by index (robustness.h); called on the best stable leaves
// first, a few at a time, until max_candidates robust ones are found.
using RobustnessCheck = std::function<std::vector<Robustness>(const std::vector<size_t>&)>;
// Approach, gripper and retreat of a leaf (placeability.h), asked lazily like robustness.
using PlacementCheck = std::function<Placement(size_t)>;

// Ranks stable before not stable, then by config.rank_order (kLowest: centre of mass height in
// 5 mm steps; kNearest: distance to prefer_near in 5 mm steps), then by the score
//   Q - 0.05 * reorientation / pi - w * (1 - robust share) + 0.25 * mean push resistance
//     + 0.05 * clamp(smallest tipping margin of the held releases / 5 deg, 0, 1)
//     + 0.1 * (drop margin - 1)
// (re-orientation: the angle from the held orientation, a secondary key: a half turn costs as
// much as 0.05 of Q; w = 1 for a stable pose, where a failed release of 12 costs 0.083, and
// 0.05 for one that is not, ranking.cpp). It merges poses within merge_distance and
// merge_angle_deg of a better one, drops Q < min_quality, and checks robustness lazily
// (config.robust_check): a stable leaf whose share of held trials is below robust_min_share
// (robust_min_share_hanging for a hanging one) is returned as not stable. With a grasp, leaves
// pointing the gripper over max_gripper_tilt_deg are dropped; a candidate that `place` finds
// blocked is dropped (kept, not stable, with the reason when keep_colliding) and the next one
// checked in its stead.
std::vector<Candidate> rankCandidates(const RankingInput& in, const PlannerConfig& config,
                                      const RobustnessCheck& check, PlanStats* stats,
                                      const PlacementCheck& place = {});

}  // namespace place_planner
