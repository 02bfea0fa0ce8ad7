// Built-in analytic meshes and demo scenes, so the demo, the bag tool and the tests run without
// any third-party mesh file. All in metres, z up; areas rest on z = 0, centred in x/y.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "place_planner/model/mesh.h"

namespace place_planner {
namespace scenes {

// Closed axis-aligned box [−sx/2, sx/2] x [−sy/2, sy/2] x [−sz/2, sz/2] + center, 6 quads,
// outward CCW.
Mesh box(double sx, double sy, double sz, const Eigen::Vector3d& center = Eigen::Vector3d::Zero());
// Closed cylinder along z, radius r, height h, `segments` sides, centred at the origin.
Mesh cylinder(double r, double h, int segments = 32);
// The same with an elliptic cross-section: semi-axes a along x, b along y.
Mesh ellipticCylinder(double a, double b, double h, int segments = 32);
// A single square plane of side `size` at z = 0 (normal +z), optionally tilted about x.
Mesh plane(double size_x, double size_y, double tilt_deg = 0.0);
// Two planes forming a V trough along x, each tilted by +-angle_deg, meeting at z = 0.
Mesh vTrough(double size, double angle_deg);
// Closed torus about z: ring radius R, tube radius r, outward CCW (a napkin ring, a roll of tape).
Mesh torus(double R, double r, int segments = 48, int sides = 12);
// Closed tube about z from z = 0 to h: radii r_in and r_out, outward CCW (a roll of tape).
Mesh tube(double r_in, double r_out, double h, int segments = 32);
// Appends b to a (vertices re-indexed); the result is rebuilt and validated.
Mesh merge(const std::vector<Mesh>& parts, const std::string& name = "merged");

// Demo placement areas.
Mesh table();         // 1.0 x 0.8 m table top, 3 cm thick
Mesh dishRack();      // tray 0.45 x 0.45 m with a grid of vertical pegs
Mesh openBox();       // box with walls, open on top (0.3 x 0.25 x 0.12 m)
Mesh binderStack();   // three binders stacked with offsets on a table top
// A storage shelf unit 1.0 m wide (x), 0.4 m deep (y), 2.4 m tall: six 2 cm boards 0.45 m apart
// (tops at z = 0.02, 0.47, ..., 2.27), side walls and a back wall at y = +0.2; open towards -y,
// so it is approached from the side (d_vis = +y). Every face split into `subdivisions`^2 quads
// (12: about 15k triangles, the size of a scanned shelf).
Mesh shelfUnit(int subdivisions = 12);
// A wall 0.6 x 0.6 m (its face at y = +0.09) with two rows of three pegs 10 cm long sticking
// out towards -y, rising rise_deg towards their tips (coat pegs); nothing to stand on but the
// wall's 2 cm top and the pegs.
Mesh pegWall(double rise_deg = 0.0);
// A mug tree: a foot 0.2 m across, a post and four arms rising 25 degrees at two heights.
Mesh mugTree();
// A wall mug rack: a board 0.5 m wide and only 12 cm tall (its face at y = 0) with four pegs
// 8 mm thick and 8 cm long rising `rise_deg` towards -y, each with a knob on its end. What
// hangs from a peg reaches below the board.
Mesh mugRack(double rise_deg = 15.0);
// Cup hooks under a shelf: a board 0.6 x 0.2 m (its underside at z = 0.4) with three J hooks of
// 6 mm wire, each a stem 5 cm down, an arm 3.5 cm out towards -y and a tip turned up 1 cm. A
// loop is lifted over the tip, then lowered onto the arm.
Mesh cupHooks();
// Demo objects (mesh frame at their base centre, like a scan).
Mesh mug();           // cylinder body with a handle, 0.08 m diameter
Mesh plate();         // flat disc 0.24 m, 2 cm thick rim
Mesh pen();           // thin cylinder 0.14 m long
Mesh loopMug();       // the mug with a handle it can hang by: an opening 5.8 x 2.4 cm

// Names accepted by byName(): table, dish_rack, open_box, binder_stack, shelf, peg_wall,
// peg_wall_rising (its pegs rising 10 degrees), mug_tree, mug_rack, cup_hooks, mug, loop_mug, ring (torus 6 cm
// across, 12 mm thick), tape_roll (tube 11 cm across, a hole 7.6 cm across, 4.8 cm deep), plate, pen, cube.
Mesh byName(const std::string& name);
std::vector<std::string> areaNames();
std::vector<std::string> objectNames();

}  // namespace scenes
}  // namespace place_planner
