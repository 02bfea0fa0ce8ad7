// Planner parameters: one plain struct, the default beside each field (voxblox style).
// config/place_planner.yaml mirrors it field for field; validate() names a bad field.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <memory>
#include <string>

namespace place_planner {

struct GripperModel;  // gripper.h

enum class OrientationMode {
  kAuto,           // default: resting faces of the hull, the held orientation, the principal
                   // axis and turns about d_vis where the area has direction, likeliest first
  kPrincipalAxis,  // Section IV-A: k1 of the object parallel to the approach direction
  kKeep,           // keep the orientation the object is given in
  kAllAxes,        // try +-k1, +-k2, +-k3 along the approach direction
};

enum class BackendKind { kAuto, kCpu, kCuda };

// Ranking preference (ranking.h): the primary key among stable candidates.
enum class RankOrder {
  kQuality,  // default: Q with robustness and re-orientation
  kLowest,   // lowest centre of mass along gravity first (bins, cups: the paper's 2nd observation)
  kNearest,  // nearest to prefer_near first
};

// Which placements the search offers (search/hanging_starts.h).
enum class PlacementKind {
  kAny,       // default: standing and hanging poses compete on the same ranking
  kStanding,  // resting on the area from above (the paper)
  kHanging,   // hanging by a loop of the object from a peg of the area
};

struct PlannerConfig {
  Eigen::Vector3d gravity{0.0, 0.0, -1.0};   // d_g, normalised by the planner
  Eigen::Vector3d approach{0.0, 0.0, 0.0};   // d_vis; zero = gravity (Section VII)
  double friction = 0.2;                     // mu (Section VII)
  double floor_point_spacing = 0.09;         // m, grid of rays (Section VII-B)
  int min_floor_points = 16;                 // spacing is refined until this many are tried
  int lowest_n = 0;                          // box-like areas: keep the n lowest (0 = all)
  int max_rotations = 5;                     // depth of the rotation tree (Section VII-C)
  double sphere_radius = 0.0;                // m, surface sphere model; 0 = derived from sizes
  double grid_cell_size = 0.0;               // m, 2D height grid; 0 = derived from sphere radius
  OrientationMode orientation = OrientationMode::kAuto;
  int max_resting_faces = 6;                 // kAuto: resting faces tried, best tipping margin first
  // Robust stability (robustness.cpp): a stable pose must also hold when released off it.
  double robust_shift = 0.003;               // m, horizontal release offset delta
  double robust_tilt_deg = 3.0;              // release tilt epsilon
  double robust_com_offset = 0.05;           // centre of mass off by this share of the object's extent along x, y
  double robust_min_share = 1.0;             // share of perturbed releases that must hold
  // The same for a hanging pose: a pendulum's releases swing into the wall or board below its
  // peg, which the swing settles only roughly (doc/validation.md, Hanging); each failed
  // release lowers the pose's score (ranking.h).
  double robust_min_share_hanging = 0.75;
  double minShare(bool hanging) const { return hanging ? robust_min_share_hanging : robust_min_share; }
  // A pose whose share of held releases is `share` is robust (hanging or standing).
  bool robustShare(double share, bool hanging) const { return share >= minShare(hanging) - 1e-9; }
  bool robust_check = true;                  // false: static stability only (the paper)
  // Tilted releases caught where they land (3.5 deg off, stable, tipping margin >= 20 deg) also
  // hold when that pose holds its own shift and centre-of-mass trials: poses on domed supports
  // (peg tops) and in a ring of rests (a bowl in a round cup). On the 56 1k scenes, checked in
  // Bullet: coverage 35/37 -> 37/37, precision 0.982 -> 0.977 (doc/validation.md).
  bool robust_recheck_caught = true;
  // Rock settle (tree_stepper.cpp): a pose the static test holds is rocked 1 degree about the
  // horizontal axes through its centre of mass and moves where that lowers it, so a tilted
  // release on domes, rims or a dish's underside comes back to its rest. On by default: with
  // the wedge rule it lifts the coverage of the 56 1k scenes from 32/39 to 36/38 at a precision
  // of 0.981 in Bullet (doc/method.md, "Rock settle").
  bool rock_settle = true;
  double time_budget_ms = 0.0;               // 0 = no budget
  int max_candidates = 10;                   // after ranking and merging
  // The search's and the ranking's work is sized for at least kMinRankedCandidates, whatever
  // max_candidates: the first k candidates of an answer are the default answer's first k
  // (k <= 10), so a robot asking for the one best pose gets the default's best, not a worse
  // one or none (the robustness checks, bounded per candidate, stopped before it was reached).
  static constexpr int kMinRankedCandidates = 10;
  int rankedCandidates() const { return std::max(max_candidates, kMinRankedCandidates); }
  int threads = 0;                           // 0 = all hardware threads
  int max_local_optimisation_steps = 8;      // slides/rotations per leaf (Section VI)
  double min_support_width = 0.0;            // m, narrower support polygons do not hold (0 = off)
  double min_tipping_angle_deg = 3.0;        // stable needs at least this tilt to tip over
  // Start orientation R_WO of the object (mode keep uses it; the others rotate it minimally).
  Eigen::Quaterniond start_orientation = Eigen::Quaterniond::Identity();
  double min_quality = 0.0;                  // candidates below are dropped
  double merge_distance = 0.005;             // m, poses closer than this ...
  double merge_angle_deg = 3.0;              // ... and this are one candidate
  BackendKind backend = BackendKind::kAuto;  // kAuto: CUDA where a GPU answers, else the CPU (doc/gpu.md)
  // Bounded work (work_limits.h), each checked before the work it bounds. Generous: the
  // paper's workload is 1k triangles, 140 floor points, ~30k tree nodes, ~20 MB of models.
  int max_triangles = 300000;                // per mesh; a larger one is decimated (a warning says so)
  int max_floor_points = 5000;               // rays cast; a finer spacing is coarsened (a warning)
  long max_tree_nodes = 3000000;             // poses evaluated; the search stops there (a warning)
  double max_model_mb = 2000;                // estimated memory of both models; above: LimitError
  double max_object_size = 3.0;              // m across; above: LimitError naming the unit (mm?)
  double max_area_size = 100.0;              // m across; above: LimitError
  // Manipulation (beyond the paper; placeability.h). With a grasp, the gripper rides with the
  // object: its frame F is `grasp` (X_OF) in the object frame, F's z the approach axis.
  bool has_grasp = false;
  Eigen::Isometry3d grasp = Eigen::Isometry3d::Identity();
  std::shared_ptr<const GripperModel> gripper;  // collision geometry in F; null: none
  double max_gripper_tilt_deg = 60.0;        // F's z axis at most this far from straight down
  double gripper_min_clearance = 0.001;      // m; the gripper nearer the area collides
  bool keep_colliding = false;               // keep blocked candidates, marked with the reason
  double approach_distance = 0.10;           // m, desired straight approach along d_vis
  double approach_min_distance = 0.03;       // m, shortest acceptable
  double retreat_distance = 0.10;            // m, the gripper backs off along -z of F
  double retreat_min_distance = 0.03;        // m
  // Preferences (ranking.h)
  PlacementKind placement = PlacementKind::kAny;
  RankOrder rank_order = RankOrder::kQuality;
  Eigen::Vector3d prefer_near{0.0, 0.0, 0.0};  // W, for kNearest
  double min_edge_clearance = 0.0;           // m from a drop-off of the area (0 = off)
  // Scanned input (model/completion.h): the uncertainty of a scanned surface, m. A structured-light
  // camera at arm's length (0.5-0.8 m) has an axial noise of 1.3-2 mm (sigma, Nguyen et al. 2012)
  // and fused scans of objects are within 1-4 mm at p95. Where the object's mesh is open (a scan:
  // its open regions are capped), a pose resting on a cap is raised by at least this much against
  // gravity (scan_unseen_reach below), a hanging pose is moved this much farther out of the area,
  // and the centre-of-mass trials and the despiking use it.
  double scan_noise = 0.002;
  // How far the part of a scan that was not seen may reach past a cap (m). A fused scan's surface
  // stops short of where it was last seen: the signed-distance band has no far side at an open
  // border. Stood on their caps, the shared upper scans' true objects reach 1.9-5.5 mm past the
  // lowest seen point (boxes' and a bottle's straight walls the most, the mug's rounded foot the
  // least); released 5 mm higher they start from 0.5 mm inside to 2.8 mm above the table. A
  // standing candidate resting on a cap is released max(scan_noise, scan_unseen_reach) higher,
  // with its path and pre-place pose (a hanging one scan_noise higher: it would fall onto its peg).
  double scan_unseen_reach = 0.005;
  // A closed object mesh is a scan too (a scan fused all around, closed by its reconstruction):
  // planned with a scan's noise as an open one is (despiked, its curved supports levelled and
  // ranked after flat ones, its centre-of-mass trials by scan_noise, its rolls not a rest), and
  // planned again as exact where no pose holds within that noise (a warning says so). Off: a
  // closed mesh is exact, a CAD model (doc/method.md, "Closed scans").
  bool closed_scan = true;
  // Optional region (planning frame) the floor points must lie in; inactive when min > max.
  Eigen::Vector3d region_min{1.0, 1.0, 1.0};
  Eigen::Vector3d region_max{-1.0, -1.0, -1.0};
  bool hasRegion() const { return (region_min.array() <= region_max.array()).all(); }
};

// Throws std::invalid_argument naming the first out-of-range field, e.g.
// "friction = -0.1 is out of range (must be >= 0)".
void validate(const PlannerConfig& config);

OrientationMode orientationModeFromString(const std::string& s);  // throws on an unknown name
std::string toString(OrientationMode m);
// "any", "standing", "hanging"; `field` names the option in the error of an unknown name.
PlacementKind placementKindFromString(const std::string& s, const std::string& field = "placement");
const char* toString(PlacementKind k);

}  // namespace place_planner
