// Start orientations of the search (Section IV-A, generalised). Frame G (gravity -z).
#pragma once
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "place_planner/config.h"
#include "place_planner/model/mesh.h"
#include "place_planner/planner.h"
#include "place_planner/model/scene.h"

namespace place_planner {

struct StartOrientation {
  Eigen::Matrix3d R_GO;
  StartKind kind;
};

// Direction of the area's walls about gravity (rack slots, dividers, a box's sides), an angle
// in [0, pi/2) of their horizontal normals in G; empty when under a third of the near-vertical
// surface shares one direction (within 5 degrees, modulo 90) or there is hardly any.
std::optional<double> areaWallDirection(const AreaModel& area);

// Direction of the fall lines of the area's sloped up-facing surface (tilted 2 to 72 degrees)
// about gravity, modulo 90 degrees, each face weighted by its area times its slope's sine;
// empty as areaWallDirection (a level area, or slopes every way: terrain, a noisy scan).
std::optional<double> areaSlopeDirection(const AreaModel& area);

// The roots' orientations, likeliest first. kAuto: the resting faces (best tipping margin
// first, each turned minimally from the held orientation), the held orientation, the principal
// axis, and turns about d_vis that align the object's long horizontal side with the area's
// walls and across them, and with its slopes' fall lines and across them; orientations within
// 8 degrees of an earlier one are dropped.
// The other modes are the paper's (pre_orientation.h).
std::vector<StartOrientation> startOrientations(const Mesh& object, const Eigen::Matrix3d& R_held_G,
                                                const Eigen::Vector3d& d_vis_G,
                                                const AreaModel& area, const PlannerConfig& config,
                                                const StopSignal* stop = nullptr);

}  // namespace place_planner
