// The tree of rotations of every pending pose, advanced one batched step at a time (Sections
// V-A to VI, batched as in VII-C). Frame G (gravity -z). Each tree starts at a root pose with
// translations pending; its leaves are resting poses (stable or not).
#pragma once
#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <vector>

#include "place_planner/infra/backend.h"
#include "place_planner/planner.h"
#include "place_planner/model/scene.h"
#include "place_planner/judgement/stability.h"

namespace place_planner {

// The axis of the peg a hanging root is threaded on (search/hanging_starts.h), frame G.
struct PegLine {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // unit; zero: no peg known
  // The root was turned about the vertical off its hanging rest (a mug's body swung out from
  // a J-hook's wall): far past its support by construction, it swings to rest before the fall
  // cut may end it. Only those: a basket rolled onto a towel rail, swung on instead of cut,
  // stopped 1 cm above the rest Bullet finds (turned 30 degrees about the rail).
  bool swing_first = false;
  // m: the loop's room round the peg (its largest circle less the peg's half width); 0: unknown.
  // A swing's turn may carry the loop across the peg no farther (swingStep's pivot).
  double room = 0;
  // Each swing move is checked by all the object's probes (ObjectModel::probes), not only its
  // vertices: a tree run again after its rest was found inside the area (streamRoots).
  bool probe_swing = false;
  bool known() const { return axis.squaredNorm() > 0; }
};

struct TreeNode {
  Rigid X_GO;
  int root = 0;       // caller's id of the tree (root index, or robustness trial)
  int depth = 0;      // rotations of the tree (Section V-C), not counting small ones
  int turns = 0;      // all rotations, small ones included
  int opt = 0;        // local optimisation steps (Section VI)
  V3 com_O{0, 0, 0};  // centre of mass used for stability, frame O (perturbed in trials)
  std::vector<Rigid> path;      // X_GO after each translation or rotation
  std::vector<V3> pending;      // translations still to do: directions (G) ...
  std::vector<double> pending_tmax;  // ... and their search limits (m); negative: go that far when nothing is hit
  // Rotation request (Section V-C): axis through s_A along d_A (G).
  Eigen::Vector3d s_A = Eigen::Vector3d::Zero(), d_A = Eigen::Vector3d::UnitX();
  bool both_directions = true;
  bool local_rotation = false;
  std::vector<ContactPoint> contacts;  // frame G
  // Its last stability test, kept while it turns: a leaf when no turn is found.
  double quality = -1, tipping_angle = 0;
  bool supported = false;
  // Roll settle (rollStep, beyond the paper): 1 when this pose is the bottom of a roll about a
  // line of contacts, with `roll_margin` (rad) to the nearest crest of the roll either way.
  int roll = 0;
  double roll_margin = 0;
  int rocks = 0;          // rock settle steps taken (rockStep)
  bool held = false;      // its last stability test held it with margin (rocked when only balanced)
  bool overhang = false;  // its last pose was past its support over a drop (see fall_tip)
  bool hanging = false;   // its last stability test found every contact above the centre of mass
  // The swing (swingStep): its step (rad; 0 before the first), how many it took, and whether
  // no move lowers it any more (its rest).
  double swing_step = 0;
  int swings = 0;
  bool swung = false;
  int swing_pose = -1;  // index in `path` of the swing's last pose (-1: none)
  // Its last stability test's settle (Stability::settle_v, settle_w): zero when balanced.
  Eigen::Vector3d settle_v = Eigen::Vector3d::Zero(), settle_w = Eigen::Vector3d::Zero();
  // The peg it was threaded on, if any. The swing turns the loop round the peg and slides it
  // across; along it friction decides (only the settle, where friction does not hold, moves it
  // along).
  PegLine peg;
};

struct TreeLeaf {
  Rigid X_GO;
  int root = 0;
  bool stable = false;
  bool at_rest = true;   // false: cut by max_rotations while still tilting
  // Statically supported: the centre of mass inside the support with the tipping margin and
  // friction holding, without the quality bound that `stable` adds (robustness trials).
  bool supported = false;
  double quality = -1;
  double tipping_angle = 0;  // rad (planar supports)
  std::vector<ContactPoint> contacts;  // frame G
  std::vector<Rigid> path;
  bool rolled = false;  // it came to rest at the bottom of a roll (rollStep)
  bool fell = false;    // the tree was cut while falling over a ledge (TreeContext::fall_tip)
  bool hanging = false;  // its last stability test found every contact above the centre of mass
  bool inside = false;   // the result's penetration guard found it inside the area
  PegLine peg;  // its tree's peg (TreeNode), if any
};

struct TreeContext {
  const ObjectModel& om;
  const AreaModel& am;
  Backend& backend;
  StabilityParams stability;
  double cd = 0;             // collision distance, m (V-B)
  int max_rotations = 5;
  int max_opt = 8;
  int threads = 0;
  StepTimes* times = nullptr;  // accumulated per step, may be null
  long* tree_nodes = nullptr;  // poses evaluated, may be null
  // A tree ends, not stable, when two poses in a row have their centre of mass more than this
  // (rad) past their support, over a drop (tree_stepper.cpp); 0: never.
  double fall_tip = 35.0 * M_PI / 180.0;
  // A stable pose is rocked about the horizontal axes through its centre of mass and moves
  // where a rock lowers it (rockStep); false: the static test decides alone.
  bool rock_settle = false;
  // The object's shape uncertainty (m): a scan's noise (config.h scan_noise). The bottom of a
  // roll holds only when its crests rise more than this too (rollStep): a crest the noise could
  // have made, or flattened, is no evidence of a rest. 0: the mesh is taken as exact.
  double shape_uncertainty = 0;
  // A swing's move that leaves the object deeper than this below a surface straight above it,
  // or deeper than penetration_sideways in any surface (a wall, a post: penetration.h), is not
  // taken (m); the planner's result guard uses the same depths. 0: that one not checked.
  double penetration_limit = 0;
  double penetration_sideways = 0;
};

class TreeStepper {
 public:
  explicit TreeStepper(const TreeContext& ctx);
  // A tree: its first pose X_GO (also the first entry of its path) and the translation to do.
  // peg: the peg a hanging root is threaded on (TreeNode::peg), if any.
  void addRoot(const Rigid& X_GO, int root, const V3& com_O, const V3& direction, double tmax,
               const PegLine& peg = {});
  size_t active() const {
    return translate_.size() + contact_.size() + rotating_.size() + rolling_.size() + rocking_.size() +
           swinging_.size();
  }
  bool empty() const { return active() == 0; }
  // One batched step of every pending pose; trees that end append their leaves.
  void step(std::vector<TreeLeaf>& leaves);
  // Roots with poses still pending, sorted, unique.
  std::vector<int> openRoots() const;
  // Drops every pending pose for which drop(node) is true (a tree whose outcome is known).
  void prune(const std::function<bool(const TreeNode&)>& drop);

 private:
  void firstContactStep();                        // V-A
  void contactStep(std::vector<TreeLeaf>& leaves);  // V-B, VI, V-C.1
  void tiltStep(std::vector<TreeLeaf>& leaves);   // V-C.2
  void rollStep();                                // beyond the paper: a roller's rest
  void rockStep(std::vector<TreeLeaf>& leaves);   // beyond the paper: at rest, or rocking
  void swingStep();                               // beyond the paper: a hanging object's swing
  TreeContext ctx_;
  double diag_;  // of the area's bounds, limits slides
  std::vector<TreeNode> translate_, contact_, rotating_, rolling_, rocking_, swinging_;
};

}  // namespace place_planner
