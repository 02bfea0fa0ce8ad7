// Physics check of placement poses with Bullet, and the paper's drop-and-settle baseline.
// Frames: W is the frame of the placement area mesh (z up, gravity -z unless configured),
// O the object mesh's own frame; X_WO is the pose of O in W, as in place_planner::Candidate.
//
// The header is Bullet-free (pimpl): only src/validation/*.cpp include Bullet.
//
// Model (settings measured on this machine, ../shared/ENVIRONMENT.md "Bullet"):
//  - area: one static btBvhTriangleMeshShape of all area triangles, friction 1.0, margin `margin`
//    (with the default margin 0 objects crept down slopes they should stick to);
//  - object: its convex hull when it is nearly convex (volume >= convex_volume_ratio of the
//    hull's), else a btCompoundShape of small btConvexHullShape pieces, each a group of neighbouring
//    triangles of similar normal, thickened inwards up to `piece_thickness` (a GImpact mesh
//    jitters on a triangle mesh; small hulls rest still), margins `margin` (1 mm: 0.5 mm gave
//    wrong static friction), each hull shrunk by the two margins so that the true surfaces touch
//    (a cube on a table rests at its geometric height, not 2 mm above; a piece too thin for
//    Bullet's clamped shrink is inset by the rest, a wall thinner than 4 margins is a sheet at
//    its middle: the YCB mug rests 1.3-1.5 mm high on its 1.5 mm bottom, 5-7 mm before),
//    friction mu (Bullet multiplies the two coefficients: mu x 1.0);
//  - mass = density x bounding-box volume, centred on the mesh's centre of mass c_O (the same
//    surface centroid the planner uses), inertia of the solid bounding box about c_O;
//  - the world simulated at `world_scale` (10) Bullet units per metre: lengths, margins and
//    gravity scaled, times, masses and friction not; every pose and speed in this API is in W.
#pragma once
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "place_planner/model/mesh.h"
#include "place_planner/planner.h"

namespace place_planner {
namespace validation {

struct ValidatorConfig {
  double friction = 0.2;                 // mu of the object; the area gets 1.0 (product = mu)
  double density = 400.0;                // kg/m^3 of the object's bounding box (household goods)
  double time_step = 1.0 / 480.0;        // s, fixed step
  int solver_iterations = 30;
  double margin = 0.001;                 // m, convex hull margins (1 mm, see above)
  // Bullet units per metre: the world is simulated scaled up (lengths and gravity times this,
  // time and friction unchanged: the same motion). Bullet's GJK/EPA tolerances are absolute
  // (1e-4 units); in metres they are a tenth of a millimetre, near a small object's contact
  // detail. Measured: at 1 unit per metre the 2 cm YCB marker, released at rest on a hull facet
  // with a 10 degree tipping margin, sank 1-2 mm into the table and rolled off at 0.3 m/s (its
  // normals came out of EPA skewed); at 10 it lies still at its geometric height.
  double world_scale = 10.0;
  // A closed object whose volume is at least this fraction of its convex hull's is simulated as
  // that one hull (boxes, bottles, markers: it fills only the cap's or neck's small concavity;
  // fast), unless it has a loop (the hull would fill the opening). Measured: a standing YCB
  // cracker box made of pieces walked 7 cm in 2 s, as its hull it stays (0.8 deg). 1.01 = always
  // pieces.
  double convex_volume_ratio = 0.85;
  double piece_thickness = 0.01;         // m, inward thickening of each piece (less in thin parts)
  int piece_max_triangles = 32;          // triangles per convex piece at most
  double piece_max_normal_deg = 40.0;    // piece triangles' normals within this of the seed's
  double piece_max_size = 0.05;          // m, largest distance of a piece triangle from its seed
  // Pieces whose normal is within 45 degrees of this direction keep the whole piece_thickness,
  // however near the other side (zero: off). MuJoCo's area (mujoco_validator.h): a floor's
  // slab may reach below a thin floor, where nothing rests, and must be thick to give a true
  // contact normal.
  Eigen::Vector3d piece_full_depth_along = Eigen::Vector3d::Zero();
  // A piece whose triangles cover less than this share of their convex outline (seen along the
  // piece's normal) is cut again, half as large, until they do (0: off). MuJoCo's pieces
  // (mujoco_validator.h): the flat flank of a J-hook, arm and turned-up tip in one plane, made
  // one L-shaped piece whose hull filled the corner where a handle hangs.
  double piece_min_fill = 0.0;
  // An object with a loop (search/loops.h: a handle's opening, a ring's hole) is cut into pieces
  // no larger than its narrowest loop's radius, so that no piece's hull bridges the opening.
  // Measured: the YCB mug hung by its handle on a peg, with 5 cm pieces, was pushed off the peg
  // (moved about 2 cm); with pieces of its handle's radius it stays on it.
  bool loop_sized_pieces = true;
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  // m/s^2, world frame
  // Bullet's velocity damping of the object (fraction of velocity lost per second, 0..1): a
  // hanging object is a pendulum that swings for long undamped; light damping lets it settle
  // within settle_time as air and the joint would. 0 = none (the default).
  double linear_damping = 0.0;
  double angular_damping = 0.0;
  // Stability check: simulate `settle_time` from the goal pose, released `release_gap`
  // above it (against gravity: a body started exactly in contact is pushed off by the margins);
  // confirmed when the object's centre of mass moved less than `max_translation` and the object
  // turned less than `max_rotation_deg`, both measured against the goal pose.
  double settle_time = 2.0;              // s
  double release_gap = 0.002;            // m
  double max_translation = 0.01;         // m
  double max_rotation_deg = 5.0;         // deg
  // Once the object has moved this far the run stops early (it cannot come back within bounds).
  double abort_translation = 0.05;       // m
  double abort_rotation_deg = 30.0;      // deg
  // Early accept (a shortcut, 0 = off: always the full settle_time): once the object has been
  // still (speeds below early_accept_*) for early_accept_steps consecutive steps while within
  // half the thresholds, it is confirmed. At 1 mm/s it could creep at most 1.5 mm more in the
  // remaining time; test_physics_validator checks the shortcut against full runs.
  int early_accept_steps = 240;          // 0.5 s at 1/480 s
  double early_accept_linear = 0.001;    // m/s
  double early_accept_angular = 0.01;    // rad/s
  // Drop-and-settle (the paper's baseline): step until linear speed < rest_linear and angular
  // speed < rest_angular for rest_steps consecutive steps; give up after max_drop_time, or once
  // the object is `fall_below` under the lowest point of the area (it fell off).
  double rest_linear = 0.005;            // m/s
  double rest_angular = 0.05;            // rad/s
  int rest_steps = 100;
  double max_drop_time = 3.0;            // s of simulated time
  double fall_below = 0.3;               // m
};

// Result of check(): the goal pose simulated for settle_time.
struct PoseCheck {
  bool confirmed = false;
  double moved_m = 0.0;        // displacement of the centre of mass, goal -> final
  double turned_deg = 0.0;     // rotation angle, goal -> final
  bool aborted = false;        // stopped early (moved past abort_*)
  bool early_accepted = false; // stopped early, still within half the thresholds
  bool interrupted = false;    // stopped by keep_going (no verdict: confirmed is false)
  double sim_time = 0.0;       // s simulated
  double wall_ms = 0.0;
  Eigen::Isometry3d X_WO_final = Eigen::Isometry3d::Identity();
};

// A hanging pose's check (its own criterion): the centre of mass within max_translation of the
// goal's and not dropped by more than 5 mm, whatever its turn. A pendulum's rest turns with its
// contact's friction (a ring spins about its peg), so max_rotation_deg, which is for a pose
// that stands, does not apply. com_O: the object's centre of mass, frame O.
bool stillHanging(const PoseCheck& check, const Eigen::Isometry3d& X_WO_goal, const Eigen::Vector3d& com_O,
                  const ValidatorConfig& config);

// The configuration a hanging pose is checked with: c with light damping (0.3 of the velocity
// per second, linear and angular, as air and the peg's friction give a pendulum, which swings
// long undamped) and 3 s to settle.
ValidatorConfig forHanging(ValidatorConfig c);

// Result of drop(): the object released at rest from X_WO_start.
struct DropResult {
  bool at_rest = false;        // velocities stayed below the thresholds for rest_steps steps
  bool fell_off = false;       // dropped below the area
  int steps = 0;               // simulation steps taken
  double sim_time = 0.0;       // s simulated
  double wall_ms = 0.0;        // wall time of the drop (world set-up + stepping; shapes prebuilt)
  Eigen::Isometry3d X_WO_rest = Eigen::Isometry3d::Identity();  // last pose (resting pose if at_rest)
};

// Builds the collision shapes once per object/area pair; every check() or drop() runs in a fresh
// dynamics world, so results do not depend on earlier calls (deterministic). check() and drop()
// may run concurrently on one validator: each call owns its world, bodies and solver and only
// reads the shared shapes (verifyTopK does so; test_physics_validator compares 1 and 2 threads).
class PhysicsValidator {
 public:
  // Throws std::invalid_argument for an empty mesh or a bad config value (naming the field).
  PhysicsValidator(const Mesh& object_O, const Mesh& area_W, const ValidatorConfig& config = {});
  ~PhysicsValidator();
  PhysicsValidator(const PhysicsValidator&) = delete;
  PhysicsValidator& operator=(const PhysicsValidator&) = delete;

  PoseCheck check(const Eigen::Isometry3d& X_WO_goal) const;
  // The same, asking keep_going every 16 steps (about 33 ms of simulated time; 1-100 ms of wall
  // time, measured); false interrupts the run without a verdict (a deadline, a cancel).
  PoseCheck check(const Eigen::Isometry3d& X_WO_goal, const std::function<bool()>& keep_going) const;
  DropResult drop(const Eigen::Isometry3d& X_WO_start) const;

  const ValidatorConfig& config() const;
  double mass() const;          // kg
  int convexPieces() const;     // number of convex hulls of the object
  double shapeBuildMs() const;  // one-off cost of building the shapes
  double convexity() const;     // object volume / convex hull volume (0: open mesh)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// What verifyTopK did (timings are wall times of this call).
// The engines verifyTopK asks: Bullet (the default), MuJoCo (mujoco_validator.h), or both (a
// pose stays only when both keep it: the project's two-engine check, in the product).
enum class Engines { kBullet, kMujoco, kBoth };
Engines enginesFromString(const std::string& s);  // "bullet", "mujoco", "both"; else invalid_argument
const char* toString(Engines e);

struct VerifyStats {
  int selected = 0;        // stable candidates among the best K (the ones it would check)
  int checked = 0;         // ... simulated before the budget ran out
  int stayed = 0;          // ... that stayed put (in every engine asked)
  int bullet_stayed = 0;   // ... in Bullet, when it was asked
  int mujoco_stayed = 0;   // ... in MuJoCo, when it was asked
  int demoted = 0;         // checked, did not stay, moved behind the other stable candidates
  double shape_ms = 0.0;   // building the Bullet shapes (once per call)
  double total_ms = 0.0;   // the whole call: shapes + simulations
  double per_check_ms = 0.0;  // mean wall time of one simulation (one thread)
  int threads = 1;
};

// Physics check in the product: simulates the best `k` stable candidates of `result`
// (candidates are ranked best first; unstable ones are skipped and do not count against k) with
// check() above, released 2 mm above the pose: stayed = moved < 1 cm and turned < 5 deg (a
// hanging candidate: checked with forHanging's damping, stayed = stillHanging). The
// object gets the plan's friction mu, gravity is 9.81 m/s^2 along cfg.gravity; everything else
// is ValidatorConfig's default. One validator (the shapes are built once per call), the checks
// run in rank order on `threads` threads (0 = all hardware threads), each in its own Bullet world.
// budget_ms: wall time for the whole call (shapes included); once it is spent no new check starts
// and a running one is interrupted within 16 steps (it counts as not checked); <= 0 = no limit.
// keep_going (optional, e.g. a cancelled goal): asked as often, false has the same effect.
// Fills Candidate::physics of every candidate (reset first: not checked = checked false).
// Ranking: a checked candidate that did not stay put keeps stable = true (the planner's verdict)
// but is moved behind every other stable candidate (still ahead of the unstable ones); all
// others keep their order. k <= 0 or no stable candidate: nothing is simulated, nothing moves.
// Throws std::invalid_argument for an empty mesh (from PhysicsValidator).
// engines: which engines check each candidate (MuJoCo's model is compiled once per call, and a
// MuJoCo check is not interrupted by the budget once started: about a second or two each).
VerifyStats verifyTopK(const Mesh& object_O, const Mesh& area_W, const PlannerConfig& cfg,
                       PlanResult& result, int k, double budget_ms, int threads,
                       const std::function<bool()>& keep_going = {}, Engines engines = Engines::kBullet);

// The budget verifyTopK gets from a plan's config and its planning time: 0 (no limit) when the
// plan had none, else what is left, at least a tiny positive amount (a spent budget checks
// nothing; it must not read as "no limit").
double remainingBudgetMs(double plan_budget_ms, double used_ms);

// The convex pieces both engines simulate a non-convex mesh with (Bullet here, MuJoCo in
// mujoco_validator.h): neighbouring triangles of similar normal (config.piece_max_normal_deg,
// piece_max_size, piece_max_triangles) grouped, each group the point set of a slab thickened
// inwards (against its normal) by config.piece_thickness, less where the other side is nearer,
// and inset by the margins (config.margin: Bullet's; 0 for an engine without margins). A closed
// mesh wound inwards (negative signed volume) is turned outwards first.
std::vector<std::vector<Eigen::Vector3d>> convexPieces(const Mesh& mesh, const ValidatorConfig& config);
// Every edge shared by exactly two triangles (`manifold`), or by two or more (a closed surface
// with a few non-manifold edges, as the YCB mug's and plate's 1k meshes have: its volume is
// still the divergence theorem's, whatever the origin).
bool closedMesh(const Mesh& mesh, bool manifold);
// Volume by the divergence theorem: positive for a closed mesh wound outwards.
double signedVolume(const Mesh& mesh);
// The same surface with every triangle's winding reversed (its normals flipped).
Mesh turnedOver(const Mesh& mesh);
// A closed mesh's volume over its convex hull's (0 for an open mesh).
double convexity(const Mesh& mesh);
// Moves every point of the pieces that lies outside the convex hull of `points` onto it: a
// slab thickened inwards at an edge sharper than a right angle (a cone's rim) otherwise reaches
// out through the other face.
void clipToHull(std::vector<std::vector<Eigen::Vector3d>>& pieces, const std::vector<Eigen::Vector3d>& points);

// The object's rigid body in both engines: mass = density x bounding-box volume, and the
// principal moments (kg m^2, about c_O along the axes of O) of that solid box.
struct BoxBody {
  double mass = 0.0;
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();
};
BoxBody boxBody(const Mesh& object_O, double density);

// Rotation angle between two orientations, degrees in [0, 180].
double rotationAngleDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

}  // namespace validation
}  // namespace place_planner
