// The release pose of a standing candidate on a scan (beyond the paper): its support face level
// with the area's support plane, not tilted by the scan's noise. Frame G (gravity -z), object O.
//
// The tree rests a scanned object on the few points of its scan that reach lowest: where a fused
// scan rounds a bottle's bottom edge outward by 2-4 mm, on two bulges of its rim, 2.2° off level.
// The true bottle, released so, lands on its flat bottom's edge and settles level, turning; a
// rotationally symmetric one also spins about its axis (Bullet: 5-16° over the held-out bottle's
// poses, against 0° released level). The support face is the object's surface that faces the
// support plane within `band` of it (three times the scan's noise), and its least-squares plane
// says how the true face lies better than its lowest points do. On a curved support too: a
// curved tube lying (a banana) rests on its arc, and its strip's plane is the arc's, where the
// lowest points of a scan set the roll about the chord a few degrees wrong; a straight rod's
// strip is symmetric about its lowest line whatever the roll, so it is only levelled along it.
#pragma once
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "place_planner/model/mesh.h"
#include "place_planner/model/scene.h"

namespace place_planner {

struct LevelReleaseParams {
  double band = 0.006;                  // m: the support face's depth above the support plane
  double facing_deg = 30.0;             // its triangles face the plane within this
  double min_tilt_deg = 0.2;            // a face already this level is left as it is
  double max_tilt_deg = 10.0;           // a larger tilt is not the scan's error: left as it is
  double min_face_area = 1e-4;          // m^2 of support face, at least
  double max_curve_deg = 15.0;          // flat: its normals' area-weighted mean at least cos of it long
  bool curved = true;                   // curved faces levelled too (a scan's; off: flat ones only)
  double contact_tol = 0.003;           // m: contacts this near one plane are a planar support
  double area_tol = 0.002;              // m: the area under the face is that plane within this
  // A face (flat, or a scan's warped one) is levelled square to the walls around it where they
  // stand square to one axis within max_tilt_deg of its normal (wallAxis): false, by its own
  // plane only (an exact mesh's face is exact; levelReleaseParams: open scans only).
  bool square_to_walls = true;
  // Only square to the walls: none where they define no axis (a face that is a guess: a cap).
  bool walls_only = false;
};

// The planner's levelling parameters for a scan's noise (m): the support face within three times
// the noise of the contacts' plane, the area under it that plane within twice the noise (the
// plane is fitted through contacts on the same noisy surface, so a corner and the plane each
// stray by up to the noise: a table scan's ragged front edge stands 2-4 mm off it, and a held-out
// wedge seen in the hand, resting there 3.9 degrees off level, was turned 5.6 degrees by Bullet).
// A curved support is levelled on a scan only (`scanned`, a closed one too with closed_scan): on
// an exact mesh a curved rest is tilted from its strip's plane by the shape itself (the marker's
// cap: 1.3-3 degrees), and levelled there Bullet turned the 1k marker 19 degrees in the divided
// tray. Squared to its walls on an open scan only (`open`, capped by the completion:
// square_to_walls): a face beside what the camera never saw was seen obliquely, if at all, while
// a closed scan's faces were seen as well as its walls (a YCB pudding box squared to its scanned
// sides stood 1.3 degrees off the face it rests on, and Bullet turned it 5 degrees back).
LevelReleaseParams levelReleaseParams(double scan_noise, bool scanned, bool open = false);

// The axis of the walls of `object_O` (vertices v_G, frame G) round a face of normal `face_n`:
// the triangles within 20 degrees of square to the face, where their area outweighs the face's
// (`face_area`), face two ways at least (not one wall) and stand square to one line within 6
// degrees r.m.s. (a can's or a bottle's body, a box's or a prism's sides; not a bowl's curve, a
// cone's taper or a scan's warped flare). Then that line (the least eigenvector of their normals'
// area-weighted scatter), turned along face_n. None otherwise.
std::optional<Eigen::Vector3d> wallAxis(const Mesh& object_O, const std::vector<Eigen::Vector3d>& v_G,
                                        const Eigen::Vector3d& face_n, double face_area);

// The turn (a rotation about the support face's centroid, frame G) that makes the least-squares
// plane of the support face of `object_O` at X_GO parallel to the plane of `contacts_G` (their
// least-squares plane, facing against gravity, with every contact's normal within 45 degrees of
// it: a face resting on a plane, not a lean). None when the contacts are not such a plane, the
// face is smaller than min_face_area, or curved (max_curve_deg) with `curved` off, or its tilt
// lies outside [min_tilt_deg, max_tilt_deg]. A curved face is cut again by its own plane until
// the cut holds still. A face, flat or curved, whose walls' axis (wallAxis) lies within
// max_tilt_deg of its normal is turned so that axis is square to P instead (square_to_walls): a
// scan sees a bottle's bottom obliquely, a few triangles fused 1-2 degrees askew, while its body's
// hundreds of triangles say where its axis is, and a made thing's bottom is square to its sides
// (the held-out bottle seen in the hand stood 2.2 degrees off its axis, its bottom's plane 0.8
// degrees off that, and Bullet spun the true bottle 5-29 degrees about its axis as it landed on
// its edge; a wedge seen from above lay on its side, warped 5-6 degrees and so taken as curved,
// and Bullet turned it 5-6 degrees).
// Only where the area under the face is that plane too: under each sample of the face (up to
// 16) that lies over area triangles facing along P within 60 degrees, one with its corners
// within area_tol of P, and at least three in four samples so (a table, a board, up to a scan's
// ragged edge; not peg tops, a rack's rails or a terrain's swell, where they, not the face, set
// the tilt). `area_G` null: not checked.
std::optional<Eigen::Isometry3d> levelingTurn(const Mesh& object_O, const Eigen::Isometry3d& X_GO,
                                              const std::vector<Eigen::Vector3d>& contacts_G,
                                              const std::vector<Eigen::Vector3d>& normals_G,
                                              const LevelReleaseParams& params,
                                              const MeshModel* area_G = nullptr);

// True when a standing pose rests on a curved face of the object: contacts on one plane as
// levelingTurn takes them, and a support face whose normals add up to under cos max_curve_deg
// of its area (the side of a can, a bottle or a rod lying down; a rounded rim). On a scan, where
// on such a face the true object comes to rest is finer than the scan (the held-out can planned
// lying on its in-hand scan: Bullet rolled the true can 18°), so the planner ranks these poses
// after those on a flat face (planner.cpp).
bool restsOnCurvedFace(const Mesh& object_O, const Eigen::Isometry3d& X_GO,
                       const std::vector<Eigen::Vector3d>& contacts_G,
                       const std::vector<Eigen::Vector3d>& normals_G, const LevelReleaseParams& params);

}  // namespace place_planner
