// Which way is up in a placement area mesh. The method (Section IV-B) takes gravity as given;
// a scan still in its camera frame is not z-up, and with the wrong gravity nothing is flat.
// Frames: everything is in the area mesh's frame W.
#pragma once
#include <Eigen/Core>

#include "place_planner/model/mesh.h"

namespace place_planner {

struct UpEstimate {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // unit normal of the largest flat region
  double share = 0.0;                              // its share of the surface (0..1)
};

// The normal of the largest flat region (triangles whose normals agree within 10 degrees,
// area-weighted), on the side of hint_up (the up the caller assumed: a camera's tilt keeps the
// table's normal within 80 degrees of it). Where the region is nearly at right angles to
// hint_up, on the side the rest of the mesh is on (things stand on a table, not under it).
UpEstimate estimateUp(const Mesh& area, const Eigen::Vector3d& hint_up = Eigen::Vector3d::UnitZ());

// Share (0..1) of the surface whose normal, either sign, is within max_deg of `up`.
double upFacingShare(const Mesh& area, const Eigen::Vector3d& up, double max_deg = 20.0);

}  // namespace place_planner
