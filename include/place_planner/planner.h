// The placement planner (the paper's Sections IV-VI): floor points, pre-orientation, first
// contact, contact points, tilt axis and exact tilt angles in a binary tree of rotations,
// stability, local optimisation and quality, batched over all pending poses.
// Frames: W is the planning frame of the placement area mesh, O the object mesh's own frame.
#pragma once
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "place_planner/config.h"
#include "place_planner/model/mesh.h"

namespace place_planner {

struct ContactPoint {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  // position
  Eigen::Vector3d n_W = Eigen::Vector3d::UnitZ(); // unit normal, pointing at the object
  // The area's own normal there, pointing at the object (n_W blends it with the object's); zero
  // when not known. A wall's is horizontal where the object's edge meets it.
  Eigen::Vector3d n_area_W = Eigen::Vector3d::Zero();
};

// How a stable pose holds when it is released a little off it (robustness.cpp): each trial
// shifts the release horizontally, tilts it or moves the centre of mass, settles it with the
// planner's own kernels, and holds when it ends stable within 1 cm and 5 degrees of the pose.
struct Robustness {
  int trials = 0;                  // perturbed releases settled (0: not checked)
  int held = 0;                    // ... that came to rest near the pose, stable
  double min_tipping_angle = 0.0;  // rad, smallest tilt that tips it over, over the trials
  double share() const { return trials > 0 ? static_cast<double>(held) / trials : 0.0; }
};

// The physics engines' verdict (Bullet, and MuJoCo when asked: validation::verifyTopK; filled by
// the CLI and the node when verify_top_k > 0, never by the core planner).
struct PhysicsCheck {
  bool checked = false;   // false: not simulated (not in the top K, or out of time)
  bool stayed = false;    // moved < 1 cm and turned < 5 degrees after release, in every engine asked
  double moved_m = 0.0;   // Bullet's (MuJoCo's when it was the only engine asked)
  double turned_deg = 0.0;
  // Each engine's own verdict, when it was asked (validation::Engines): Bullet's moved_m and
  // turned_deg are those above; MuJoCo is the second engine.
  bool bullet_checked = false;
  bool bullet_stayed = false;
  bool mujoco_checked = false;
  bool mujoco_stayed = false;
  double mujoco_moved_m = 0.0;
  double mujoco_turned_deg = 0.0;
  // The candidate's place in the planner's ranking (set by validation::verifyTopK, which moves a
  // candidate that fell behind the stable ones that did not, so the list may differ from it).
  int planner_rank = -1;
};

// What carries a candidate: seen surface, or surface a scan never saw (model/completion.h).
enum class SupportKind { kSeen, kCompleted, kAreaBorder };
const char* toString(SupportKind s);  // "seen", "completed", "area_border"

// Which start orientation a candidate's tree began from (Section IV-A, generalised).
enum class StartKind { kRestingFace, kHeld, kPrincipalAxis, kAreaTurn, kAxis, kLoopOnPeg };
const char* toString(StartKind k);

// A straight motion (moveit_msgs/GripperTranslation): along `direction`, at least min_distance,
// desired_distance if free. free_distance: how far it was checked free (up to desired).
struct LinearMotion {
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit; frame below
  double min_distance = 0.0, desired_distance = 0.0, free_distance = 0.0;
};

// The gripper and the motions around the goal (placeability.h); filled when the plan has a
// grasp (retreat, gripper) or always (approach).
struct Placement {
  bool checked = false;
  // Object pose before the approach: desired_distance back along the approach from its end
  // (the goal when `straight`, else the first intermediate pose after the first contact).
  Eigen::Isometry3d pre_place_W = Eigen::Isometry3d::Identity();
  bool straight = true;         // the straight approach ends at the goal
  LinearMotion approach;        // direction in W (d_vis)
  LinearMotion retreat;         // the gripper's, direction in F (-z): free once released
  double gripper_clearance = -1.0;  // m at the goal and on the way (-1: no gripper)
  std::string blocked;          // empty, or why the gripper cannot place it ("goal", "approach", ...)
};

struct Candidate {
  Eigen::Isometry3d X_WO = Eigen::Isometry3d::Identity();  // goal pose of the object mesh frame
  double quality = 0.0;                                     // Q (Section VI), <= 1
  bool stable = false;             // statically stable and robust (see Robustness)
  Robustness robustness;
  PhysicsCheck physics;
  StartKind start = StartKind::kPrincipalAxis;
  // It hangs: every contact above its centre of mass (a loop on a peg, a ring on a hook). Its
  // approach threads the loop along the peg (placement.approach), then lowers it.
  bool hanging = false;
  // What carries it (model/completion.h): kSeen, or surface the scans never saw: kCompleted (a
  // contact on a cap over an open region of the object) or kAreaBorder (a contact at the border
  // of what the area's scan saw). Those are offered as stable only where no pose on seen
  // surface holds (then flagged, after the seen ones in rank; PlanStats::unseen_withheld).
  SupportKind support = SupportKind::kSeen;
  bool completed_support() const { return support != SupportKind::kSeen; }
  // A scanned object resting on a curved face of its scan (a can on its side, a rounded rim:
  // manipulation/level_release.h restsOnCurvedFace): where it comes to rest there is finer than
  // the scan. Ranked after the stable poses on a flat face of seen surface.
  bool curved_support = false;
  double reorientation = 0.0;      // rad, rotation from the held orientation to the goal
  // The largest horizontal push its contacts resist, in weights (judgement/contact_forces.h):
  // the smallest over 8 directions, their mean, and the weakest direction (W, horizontal).
  // Capped at 1 (a push of the full weight); 0 when not stable or not computed.
  double push_resistance = 0.0;
  double push_resistance_mean = 0.0;
  Eigen::Vector3d push_weakest_W = Eigen::Vector3d::UnitX();
  // How far a standing pose is from a drop-off of the area, 0 to 1 (judgement/drop_margin.h):
  // 1 in the middle of a table, in a cup or a compartment, about 0.5 on a narrow wall top. 1
  // for a hanging pose or one not stable.
  double drop_margin = 1.0;
  std::vector<ContactPoint> contacts;                       // at the goal pose
  Eigen::Vector3d floor_point_W = Eigen::Vector3d::Zero();
  // Ordered: pre-placement pose above the floor point first, one per translation or rotation,
  // the goal pose last.
  std::vector<Eigen::Isometry3d> intermediate_poses;
  Placement placement;
  // With a grasp: the gripper frame F at the goal, X_WO * grasp.
  bool has_gripper_pose = false;
  Eigen::Isometry3d X_WF = Eigen::Isometry3d::Identity();
};

struct StepTimes {  // wall time per batched step, ms
  double setup = 0;  // sphere models, BVHs, height grid
  double floor_points = 0, first_contact = 0, contact_points = 0, tilt_vertex = 0, tilt_edge = 0,
         stability = 0, local_optimisation = 0;
};

struct PlanStats {
  int roots_total = 0;             // floor points x start orientations, and the hanging starts
  int pegs = 0;                    // the area's pegs (search/pegs.h), when hanging is searched
  int loops = 0;                   // the object's loops (search/loops.h), when pegs were found
  int hanging_starts = 0;          // loop-on-peg roots threaded free
  int hanging_starts_done = 0;     // ... whose trees are done (the progress of a hanging search)
  int start_orientations = 0;
  int spikes_flattened = 0;        // vertices of a scanned object moved onto their neighbours' plane (model/despike.h)
  int roll_bottoms = 0;            // leaves at the bottom of a roll (tree_stepper rollStep), stable or not
  int trees_without_rest = 0;      // trees cut by max_rotations before reaching a resting pose
  int trees_fallen = 0;            // trees cut while falling over a ledge (TreeContext::fall_tip)
  int robustness_checked = 0;      // stable leaves whose releases were perturbed
  int robustness_rejected = 0;     // ... found not robust (returned as not stable)
  int gripper_rejected = 0;        // candidates the gripper blocks (dropped unless keep_colliding)
  int gripper_tilt_rejected = 0;   // leaves whose gripper would point over max_gripper_tilt_deg
  int unseen_withheld = 0;         // distinct statically stable poses on unseen surface not offered: one on seen surface holds
  int floor_points_total = 0;
  int floor_points_done = 0;
  long tree_nodes = 0;             // poses evaluated over all trees
  double first_stable_ms = -1.0;   // -1: none found
  double total_ms = 0.0;
  StepTimes steps;
  double robustness_ms = 0.0;      // wall time of the robustness check
  std::string backend;             // "cpu" or "cuda"
  std::string backend_note;        // with backend auto: which backend it chose and why, else empty
  double sphere_radius = 0.0;      // as used (derived when the config says 0)
};

// What a plan came to; the CLI's exit code and the node's error code follow it.
enum class PlanOutcome {
  kStable,               // at least one stable candidate, search complete
  kNoStable,             // search complete, nothing stable
  kTimedOutWithStable,   // budget ran out; stable candidates so far (a partial answer)
  kTimedOutNone,         // budget ran out before anything stable
  kCancelled,            // the progress callback said stop
};
const char* toString(PlanOutcome o);
// What a search covered, for messages: "F of N floor points", "H of M threaded starts" (with
// placement hanging the floor points are found but not searched: no start orientation), or
// both joined by "and"; "0 of 0 floor points" when it stopped before any root was found.
std::string searchedRoots(const PlanStats& st);

struct PlanResult {
  std::vector<Candidate> candidates;  // ranked: stable first, then by quality
  std::vector<Eigen::Vector3d> floor_points_W;
  PlanStats stats;
  bool cancelled = false;
  bool timed_out = false;
  // Doubts about the input that did not stop the plan, one sentence each (e.g. an area with
  // almost nothing facing against gravity: a scan in its camera frame?).
  std::vector<std::string> warnings;
  PlanOutcome outcome() const;
  int stableCount() const;
};

struct Progress {
  int floor_points_done = 0;
  int floor_points_total = 0;  // searched: 0 with placement hanging (the roots are threaded starts)
  int hanging_starts_done = 0;   // threaded starts (loop on peg) whose trees are done ...
  int hanging_starts_total = 0;  // ... of these; 0 with placement standing or nothing to hang on
  double best_quality = 0.0;  // of stable candidates so far; 0 when none
  int candidates = 0;
  double elapsed_ms = 0.0;
};

// Called between batched steps (every few ms). Return false to cancel: plan() then returns the
// candidates found so far with cancelled = true.
using ProgressCallback = std::function<bool(const Progress&)>;

class AreaModelCache;

// Threads: one Planner may be shared by several threads at once (a robot with two arms, a node
// serving goals while a preview plans). plan() is const; the only state it touches is the
// area-model cache, whose lookups and insertions hold its mutex, and the models it hands out
// are immutable and shared by reference count. Concurrent plans share the CPU worker pool: the
// one that finds it busy runs its batch on its own thread, with the same answers
// (test/core/test_threads.cpp, run under ThreadSanitizer by scripts/test).
class Planner {
 public:
  Planner();
  // object: M_O in its own frame O. area: M_P in the planning frame W.
  // Throws std::invalid_argument for a bad config (naming the field).
  PlanResult plan(const Mesh& object, const Mesh& area, const PlannerConfig& config,
                  const ProgressCallback& progress = {}) const;

  // The prepared area (sphere model, BVHs, height grid) of the last few areas is kept by this
  // planner (and its copies), as a robot places several objects on one area; objects of
  // similar size share one model (area_model_cache.h); stats.steps.setup shows the cost.
  // This drops it (benchmarks of cold starts).
  void clearAreaCache() const;

 private:
  // One plan; *closed says whether the object mesh had no open region.
  PlanResult planOnce(const Mesh& object, const Mesh& area, const PlannerConfig& config,
                      const ProgressCallback& progress, bool* closed) const;
  std::shared_ptr<AreaModelCache> cache_;
};

}  // namespace place_planner
