// Unseen is not empty (beyond the paper, which names "complete unmodelled regions" as future
// work). A scanned object is open where the camera never looked: the bottom of an object scanned
// from above, the end hidden by the hand. The planner closes each open region (a loop of boundary
// edges) with a cap, the polygon the loop spans (ear-clipped in its best-fit plane by buildMesh),
// and remembers which surface is completed:
//   - the model planned on is closed, so the object rests on the cap, never on the open rim with
//     its unseen part below the area's surface, and the centre of mass (from the surface) moves
//     toward the unseen side as it should;
//   - a pose whose contacts lie on a cap (inside it, farther than `margin` from the seen rim) needs
//     surface that was not seen: it is flagged (Candidate::support), and offered as stable only
//     where no pose on seen surface holds (ranking.h).
// Frame: the object's own frame O throughout.
#pragma once
#include <Eigen/Core>
#include <array>
#include <vector>

#include "place_planner/model/mesh.h"

namespace place_planner {

struct CompletionCap {
  std::vector<Eigen::Vector3d> loop;  // the open region's boundary, in order
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // best-fit plane, pointing out of the object
  double flatness = 0;  // m, largest distance of a loop vertex from the plane
};

struct Completion {
  const Mesh* source = nullptr;    // the object given (not owned: it outlives the plan)
  Mesh capped;                     // the object with every open region capped, when completed()
  std::vector<CompletionCap> caps;  // empty: the mesh was closed
  double open_perimeter = 0;       // m, summed over the loops
  bool completed() const { return !caps.empty(); }
  // What is planned on: the capped mesh, or the object itself when it was closed.
  const Mesh& mesh() const { return completed() ? capped : *source; }
};

// Edges of exactly one triangle (vertex indices, in the direction they run in that triangle):
// the borders of what a scan saw. Empty for a closed mesh and for a triangle soup (more than
// half the edges open: no shared vertices).
std::vector<std::array<int, 2>> openEdges(const Mesh& mesh);

// Distance from p to the segment ab.
double segmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// True when p lies within `margin` of one of the edges (the area's open_edges, scene.h).
bool nearOpenEdge(const std::vector<std::array<Eigen::Vector3d, 2>>& edges, const Eigen::Vector3d& p, double margin);

// Caps every loop of boundary edges of `object` (edges of one triangle). A closed mesh or a
// triangle soup (more than half the edges open: no shared vertices) is not copied: mesh() is
// `object` itself, which must outlive the result.
Completion completeOpenRegions(const Mesh& object);

// True when the contact point p_O (on the object's surface, frame O) lies on a cap: within
// `margin` of its plane (or of its flatness, whichever is larger), inside the loop's polygon
// and farther than `margin` from the loop (the seen rim itself is seen).
bool onCompletedSurface(const Completion& completion, const Eigen::Vector3d& p_O, double margin);

// True when the contact p_O (normal n_O pointing at the object, frame O) lies within `margin` of
// the rim of an open region that faces the surface the contact is on (its cap's outward normal
// within 60 degrees of -n_O). The seen rim touches, but the unseen part inside it may bulge past
// the surface: a mug whose side was hidden by the hand, laid on that side, rests on the rim in the
// plan and on the bulge beyond the rim's chord in truth, and rolls. (The cap's own contacts are
// onCompletedSurface's; a rim whose region faces sideways, a bottom's edge under a hidden side,
// is not this.)
bool onOpenRimFacing(const Completion& completion, const Eigen::Vector3d& p_O, const Eigen::Vector3d& n_O,
                     double margin);

}  // namespace place_planner
