// A second physics engine for the placement check: MuJoCo (Debian's 2.2), beside Bullet
// (physics_validator.h). The same question, asked of an engine with another contact model:
// Bullet keeps bodies apart by margins and an impulse solver; MuJoCo solves soft, convex
// contacts for accelerations. A pose both keep is not an artefact of one engine's tuning.
// Frames as in physics_validator.h: W the area's, O the object's, X_WO the pose of O in W.
//
// Model (measured on this machine: a cube on a plane tilted 10 and 12 degrees at mu 0.2 sticks
// and slides, 15 and 20 degrees at mu 0.3 the same: tan(slope) = mu decides; test_mujoco_validator):
//  - object and area both as convex pieces (convexPieces, no margins): MuJoCo 2.2 finds one
//    contact point between two convex meshes, by MPR along the line between their centres, so a
//    face resting on the area must be several pieces to rest on several points, and a piece
//    must be about as long as it is thick for its contact normal to be true: the object in
//    pieces of at most piece_size (2 cm), the area in slabs twice that, 2 cm under its surface
//    (less in thin walls), both meshes first split to edges of half their piece size; each area
//    slab a static body of its own (MuJoCo prunes pairs by bodies);
//  - friction mu on both (MuJoCo takes the larger), elliptic cones (impratio 10), contacts
//    stiffened to a 4 ms time constant at a 1 ms step; no restitution;
//  - mass and inertia as Bullet's: density x bounding box, its solid-box inertia about c_O;
//  - damping (a hanging pendulum's) as Bullet's: the share of velocity lost per second.
// The header is MuJoCo-free (pimpl): only src/validation/mujoco_validator.cpp includes it.
#pragma once
#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "place_planner/model/mesh.h"
#include "place_planner/validation/physics_validator.h"

namespace place_planner {
namespace validation {

class MujocoValidator {
 public:
  // The model is compiled once per object/area pair; check() may run concurrently (each call
  // has its own mjData). Thresholds, release gap, settle time, friction, density, gravity and
  // damping come from `config` (ValidatorConfig: the same check as Bullet's). `piece_size`:
  // the largest convex piece, m. Throws std::runtime_error with MuJoCo's message when the model
  // does not compile, std::invalid_argument for an empty mesh.
  MujocoValidator(const Mesh& object_O, const Mesh& area_W, const ValidatorConfig& config = {},
                  double piece_size = 0.02);
  ~MujocoValidator();
  MujocoValidator(const MujocoValidator&) = delete;
  MujocoValidator& operator=(const MujocoValidator&) = delete;

  // Released config.release_gap above X_WO_goal and simulated for config.settle_time:
  // confirmed when the centre of mass moved less than max_translation and the object turned
  // less than max_rotation_deg (PoseCheck as Bullet's; stillHanging applies the same way).
  PoseCheck check(const Eigen::Isometry3d& X_WO_goal) const;

  int objectPieces() const;
  int areaPieces() const;
  double buildMs() const;  // compiling the model

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The object's convex pieces as the MuJoCo model gets them (frame O): split to half the piece
// size, grown from seeds that are no slivers, kept inside the object's hull when it is nearly
// convex without a loop. What the constructor builds; tests read the slabs through it.
std::vector<std::vector<Eigen::Vector3d>> mujocoObjectPieces(const Mesh& object_O, const ValidatorConfig& config = {},
                                                             double piece_size = 0.02);

}  // namespace validation
}  // namespace place_planner
