#include "place_planner/judgement/stability.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "place_planner/judgement/contact_forces.h"
#include "place_planner/judgement/quality.h"
#include "place_planner/search/contact_points.h"

namespace place_planner {
namespace {

// A contact whose normal is within asin(0.3) = 17 degrees of horizontal pushes sideways only.
constexpr double kSideContact = 0.3;

const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();  // -d_g in G


// d_g projected onto the plane with unit normal n (not vertical), unit: the way down its slope.
Eigen::Vector3d downSlope(const Eigen::Vector3d& n) { return (-kUp - (-kUp).dot(n) * n).normalized(); }

// 2D analysis of a support polygon in the plane through `origin` with normal `n` (unit),
// centre of mass projected along gravity (-z).
struct Support {
  bool valid = false;
  std::vector<Eigen::Vector2d> hull2;
  std::vector<Eigen::Vector3d> hull3;
  Eigen::Vector2d c_hat_O, c_omega;
  double inside = 0, h = 0, quality = -1, tip = 0;
  Eigen::Vector3d u, w, origin, n;
};

// The 2D hull of pts in the plane through `origin` with normal n (basis u, w); false when it is
// degenerate (fewer than 3 points off one line).
bool projectHull(Support& s, const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& n) {
  s.origin = origin;
  s.n = n;
  s.u = n.unitOrthogonal();
  s.w = n.cross(s.u);
  std::vector<Eigen::Vector2d> p2;
  for (const auto& p : pts) p2.emplace_back((p - origin).dot(s.u), (p - origin).dot(s.w));
  s.hull2 = convexHull2d(p2);
  return s.hull2.size() >= 3 && std::abs(polygonArea(s.hull2)) >= 1e-10;
}

Support analyse(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& origin,
                const Eigen::Vector3d& n, const Eigen::Vector3d& com) {
  Support s;
  if (!projectHull(s, pts, origin, n)) return s;
  // c^_O: the centre of mass projected along gravity onto P.
  const double den = -kUp.dot(n);
  if (std::abs(den) < 1e-9) return s;
  const double t = (origin - com).dot(n) / den;
  const Eigen::Vector3d proj = com - t * kUp;
  s.c_hat_O = Eigen::Vector2d((proj - origin).dot(s.u), (proj - origin).dot(s.w));
  s.c_omega = polygonCentroid(s.hull2);
  s.h = std::abs((com - origin).dot(n));
  s.inside = signedBoundaryDistance(s.hull2, s.c_hat_O);
  s.tip = std::atan2(s.inside, std::max(s.h, 1e-9));
  s.quality = quality(s.hull2, s.c_hat_O, s.h);
  for (const auto& q : s.hull2) s.hull3.push_back(origin + q.x() * s.u + q.y() * s.w);
  s.valid = true;
  return s;
}

// Failure direction in 3D from a support: away from the hull centre, or (centred but too close
// to an edge) outward through the nearest edge.
Eigen::Vector3d tipDirection(const Support& s) {
  Eigen::Vector2d d = s.c_hat_O - s.c_omega;
  if (d.norm() < 1e-6) {
    double best = 1e300;
    for (size_t i = 0; i < s.hull2.size(); ++i) {
      const Eigen::Vector2d a = s.hull2[i], e = s.hull2[(i + 1) % s.hull2.size()] - a;
      const Eigen::Vector2d outward(e.y(), -e.x());
      const double dist = (a - s.c_hat_O).dot(outward.normalized());
      if (dist < best) {
        best = dist;
        d = outward;
      }
    }
  }
  const Eigen::Vector3d d3 = d.x() * s.u + d.y() * s.w;
  Eigen::Vector3d h = d3 - d3.dot(kUp) * kUp;  // rotations tip about horizontal axes
  if (h.norm() < 1e-9) h = d3;
  return h.normalized();
}

// The hull edge crossed by the ray from c_Omega through c^_O (or the nearest edge when they
// coincide), in 3D.
void tipEdge(const Support& s, Eigen::Vector3d* point, Eigen::Vector3d* dir) {
  const size_t n = s.hull2.size();
  if (n < 3) return;
  Eigen::Vector2d d = s.c_hat_O - s.c_omega;
  size_t best_i = 0;
  double best = 1e300;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d a = s.hull2[i], e = s.hull2[(i + 1) % n] - a;
    double key;
    if (d.norm() > 1e-9) {
      const double den = d.x() * e.y() - d.y() * e.x();
      if (std::abs(den) < 1e-18) continue;
      const Eigen::Vector2d r = a - s.c_omega;
      const double t = (r.x() * e.y() - r.y() * e.x()) / den;
      const double u = (r.x() * d.y() - r.y() * d.x()) / den;
      if (t < 0 || u < -1e-9 || u > 1 + 1e-9) continue;
      key = t;
    } else {
      key = std::abs((a - s.c_hat_O).x() * e.y() - (a - s.c_hat_O).y() * e.x()) / e.norm();
    }
    if (key < best) {
      best = key;
      best_i = i;
    }
  }
  *point = s.hull3[best_i];
  *dir = (s.hull3[(best_i + 1) % n] - s.hull3[best_i]).normalized();
}

Eigen::Vector3d farthest(const std::vector<ContactPoint>& c, const Eigen::Vector3d& d) {
  Eigen::Vector3d best = c.front().p_W;
  for (const auto& p : c)
    if (p.p_W.dot(d) > best.dot(d)) best = p.p_W;
  return best;
}

// The contacts merged (reduceContacts) in cells of an eighth of their extent (at least the
// contact tolerance): a few dozen at most, so the NNLS stays small whatever the sphere model's
// density. Only contacts whose normals lie within kMergeNormal of each other merge: a loop's
// contacts fan round its peg, and one mean normal in their place keeps one friction cone of
// the several that grip the peg together (a mug hung against a wall lost its balance so,
// depending on where the cells fell).
constexpr double kMergeNormal = 30 * M_PI / 180;
std::vector<ContactPoint> forceContacts(const std::vector<ContactPoint>& contacts, const StabilityParams& prm) {
  double extent = 0;
  for (const ContactPoint& p : contacts) extent = std::max(extent, (p.p_W - contacts.front().p_W).norm());
  // Greedy groups by normal, each merged on its own.
  std::vector<Eigen::Vector3d> seeds;
  std::vector<std::vector<ContactPoint>> groups;
  for (const ContactPoint& p : contacts) {
    size_t g = 0;
    while (g < seeds.size() && p.n_W.dot(seeds[g]) < std::cos(kMergeNormal)) ++g;
    if (g == seeds.size()) {
      seeds.push_back(p.n_W);
      groups.emplace_back();
    }
    groups[g].push_back(p);
  }
  std::vector<ContactPoint> out;
  for (const auto& group : groups) {
    const std::vector<ContactPoint> merged = reduceContacts(group, std::max(prm.tol, extent / 8));
    out.insert(out.end(), merged.begin(), merged.end());
  }
  return out;
}

// The contact forces (contact_forces.h) on the merged contacts.
ContactForces forceModel(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                         const StabilityParams& prm) {
  return ContactForces(forceContacts(contacts, prm), com, ForceModelParams{prm.friction, 8, prm.max_load});
}

// Where only friction fails (slipDirection: wide cones would hold it), the horizontal direction
// the object slips in; the local optimisation slides it there (a plate's foot against the peg
// behind it), where the paper's tip direction would turn it over.
Eigen::Vector3d slipOf(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                       const StabilityParams& prm) {
  return slipDirection(forceContacts(contacts, prm), com, ForceModelParams{prm.friction, 8, prm.max_load}, 1.0, true);
}

// A pose that slips (slip non-zero) slides that way, before any turn.
bool slides(Stability& r, const Eigen::Vector3d& slip) {
  if (slip.norm() == 0) return false;
  r.failure = Failure::kSlide;
  r.slips = true;
  r.d_f = slip;
  return true;
}

// A contact that only pushes sideways: the area's own normal there (where known) within
// kSideContact of horizontal.
bool sideContact(const ContactPoint& p) {
  const Eigen::Vector3d& n = p.n_area_W.squaredNorm() > 0 ? p.n_area_W : p.n_W;
  return std::abs(n.dot(kUp)) < kSideContact;
}

// Where the normals of the contacts above the centre of mass meet (least squares), when they
// spread enough to say how high: the point a support held from above turns about as the object
// rolls and slides on it. NaN when the normals are too near parallel to place it in height.
Eigen::Vector3d supportPivot(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com, double tol) {
  const Eigen::Vector3d none = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& p : contacts) {
    if (p.p_W.z() <= com.z() + tol) continue;  // the walls it leans on below
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - p.n_W * p.n_W.transpose();
    A += P;
    b += P * p.p_W;
    ++n;
  }
  if (n < 3) return none;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(A);
  // Normals within about 15 degrees of one direction leave the point free along it.
  const double spread = 0.067 * n;
  Eigen::Vector3d x = com;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = es.eigenvectors().col(k);
    if (es.eigenvalues()(k) < spread) {
      if (std::abs(e.z()) > 0.5) return none;
      continue;  // free horizontally: kept at the centre of mass
    }
    x += e * (e.dot(b - A * com) / es.eigenvalues()(k));
  }
  return x;
}

// Hanging: the contact forces, inside their friction cones, balance gravity (the centre of mass
// straight below the support). A ring on a peg sloping down past atan mu slides off.
Stability hangingStability(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                           const StabilityParams& prm) {
  Stability r;
  r.hanging = true;
  Eigen::Vector3d c = Eigen::Vector3d::Zero(), nbar = Eigen::Vector3d::Zero();
  for (const auto& p : contacts) c += p.p_W, nbar += p.n_W;
  c /= static_cast<double>(contacts.size());
  // Hanging on one peg, the contacts lie on the peg's top under the loop: one support, whose
  // normal is their mean. A contact's own normal blends the meshes' around it (sphereContact):
  // where a flat bar rests on a faceted peg's ridge it leans towards the facet beside it (25
  // to 45 degrees, past the friction cone), though the bar rests on the ridge. Contacts on
  // surfaces facing different ways (a peg and a wall) keep their own.
  std::vector<ContactPoint> support = contacts;
  // A wall below the centre of mass pushes along its own normal (sideContact).
  for (auto& p : support)
    if (p.p_W.z() <= com.z() + prm.tol && p.n_area_W.squaredNorm() > 0) p.n_W = p.n_area_W;
  bool one_support = nbar.norm() > 1e-9;
  for (const auto& p : contacts) one_support = one_support && p.n_W.dot(nbar.normalized()) >= 0.5;
  if (one_support)
    for (auto& p : support) p.n_W = nbar.normalized();
  ContactForces forces = forceModel(support, com, prm);
  Eigen::VectorXd weights;  // the solve's forces: the settle below reads its residual
  r.balanced = forces.balances(-kUp, &weights);
  // A pendulum rests where its centre of mass is straight below its support, which contacts
  // within tol of touching locate only roughly: a centre of mass within tol, horizontally, of
  // the segments between its contacts is at rest to the model's resolution (and to the swing's,
  // whose drops onto the sphere lattice are uneven by tens of micrometres).
  if (!r.balanced) {
    const Eigen::Vector2d m = com.head<2>();
    Eigen::Vector2d nearest = support.front().p_W.head<2>();
    for (size_t i = 0; i < support.size(); ++i)
      for (size_t j = i; j < support.size(); ++j) {
        const Eigen::Vector2d a = support[i].p_W.head<2>(), e = support[j].p_W.head<2>() - a;
        const double s = e.squaredNorm() > 1e-18 ? std::clamp((m - a).dot(e) / e.squaredNorm(), 0.0, 1.0) : 0.0;
        if ((a + s * e - m).norm() < (nearest - m).norm()) nearest = a + s * e;
      }
    if ((nearest - m).norm() <= prm.tol) {
      ContactForces shifted = forceModel(support, Eigen::Vector3d(nearest.x(), nearest.y(), com.z()), prm);
      if (shifted.balances(-kUp)) {
        r.balanced = true;
        forces = std::move(shifted);
      }
    }
  }
  // Equilibrium is the decision (gravity loads the contacts inside their friction cones); the
  // margin a standing pose needs is the perturbed releases' here, each settled by the swing.
  // But a support held from above is a pendulum only when its contacts' normals meet above the
  // centre of mass (a loop on a round peg turns about the peg's axis): a dome over a ring (a
  // bowl upside down on a cup's rim) turns about its curvature's centre, below its centre of
  // mass, and slides off the ring's side. Balanced, not at rest: no tilt of the tree follows
  // that roll (the rock settle may find where it sinks).
  // (The contacts' own normals: merged into their mean above, a dome's would meet nowhere.)
  const Eigen::Vector3d pivot = supportPivot(contacts, com, prm.tol);
  const bool inverted = std::isfinite(pivot.z()) && pivot.z() < com.z() - prm.tol;
  const bool holds = r.balanced && !inverted;
  r.stable = holds;
  r.friction_ok = holds;
  r.com_inside = r.balanced;
  // Q: 1 less the centre of mass's horizontal offset from the support's centre over the
  // support's reach (at least 0.3): straight below its support, a pendulum's Q is 1.
  double reach = 1e-9;
  for (const auto& p : contacts) reach = std::max(reach, (p.p_W - c).norm());
  const Eigen::Vector3d off = com - c;
  // Its margin: the swing the support allows before the centre of mass comes level with it;
  // unstable, how far it is swung off straight below its support (negative: far off, over a
  // drop, the tree's fall cut ends it as it does an object going over a ledge).
  r.tipping_angle = holds ? std::atan2(-off.z(), reach) : -std::atan2(std::hypot(off.x(), off.y()), -off.z());
  r.quality = holds ? std::max(0.3, 1.0 - std::hypot(off.x(), off.y()) / reach) : -1.0;
  // Where friction alone fails (a loop on a round peg's shoulder: wide cones would hold it),
  // it slides round the peg, towards straight below it, before any swing.
  const Eigen::Vector3d slip = holds || r.balanced ? Eigen::Vector3d::Zero() : slipOf(support, com, prm);
  if (!holds) {
    // The settle the unbalanced wrench starts (the swing's descent takes it as one move).
    double L = 1e-3;
    for (const auto& p : support) L = std::max(L, (p.p_W - com).norm());
    forces.unbalanced(-kUp, &r.settle_v, &r.settle_w, &weights);
    const double scale = r.settle_v.norm() + r.settle_w.norm() * L;
    if (scale > 1e-12) {
      r.settle_v /= scale;
      r.settle_w /= scale;
    }
  }
  if (holds) {
    r.failure = Failure::kNone;
  } else if (inverted) {
    r.failure = Failure::kTip;  // d_f left zero: no turn about a point is that roll
  } else if (!slides(r, slip)) {
    // It swings: towards its centre of mass's side, about the support.
    r.failure = Failure::kTip;
    const Eigen::Vector3d h(off.x(), off.y(), 0);
    r.d_f = h.norm() > 1e-9 ? Eigen::Vector3d(h.normalized()) : Eigen::Vector3d::UnitX();
  }
  r.pivot = c;
  return r;
}

// The contact forces balance gravity, and gravity tilted by half the friction angle towards each
// of the 4 horizontal axis directions of G (a margin against sliding and tipping).
bool balancedWithMargin(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                        const StabilityParams& prm, bool* balanced = nullptr) {
  const ContactForces forces = forceModel(contacts, com, prm);
  const bool at_all = forces.balances(-kUp);
  if (balanced) *balanced = at_all;
  if (!at_all) return false;
  const double tilt = 0.5 * std::atan(prm.friction);
  for (int k = 0; k < 4; ++k) {
    const double phi = k * M_PI / 2;
    if (!forces.balances(Eigen::Vector3d(std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi), -std::cos(tilt))))
      return false;
  }
  return true;
}

// A line of contacts (longer than the contact tolerance: a body's side, not a point on an
// edge) where the object's surface lies on one flat surface of the area (each contact's normal,
// the two meshes' blend, within kFaceOnFace of the area's own there, and those within
// kOneSurface of their mean: face on face on one plane, not an edge on an edge nor across a
// curved surface's facets), steeper than the friction angle and at most kSteepestSlope:
// nothing there holds it (the planar case's angle(P, -d_g) < atan mu fails for any plane the
// contacts lie on), and it slides down that surface before it turns. A round body on a ramp
// steeper than atan mu rolls and slides down to what stops it (a trough's other side), where
// tilts about its line of contact would turn it by fractions of a degree at a time along its
// curved side. False (r unchanged) otherwise.
constexpr double kOneSurface = 3 * M_PI / 180;
constexpr double kFaceOnFace = 20 * M_PI / 180;
// Steeper than this the surface is a wall, not a slope (a bin's flared sides, a tray's drafted
// walls): what touches it there leans or falls, and the tree turns it as before. (Up to 90
// degrees: on the rack and tray scans one best pose fewer kept, on the shared scans a marker
// stood in a bin's corner.)
constexpr double kSteepestSlope = 45 * M_PI / 180;
bool slidesDownSteepSurface(Stability& r, const std::vector<ContactPoint>& contacts, double cone, double tol) {
  Eigen::Vector3d mid = Eigen::Vector3d::Zero(), m = Eigen::Vector3d::Zero();
  for (const auto& p : contacts) {
    if (p.n_area_W.squaredNorm() == 0 || p.n_W.dot(p.n_area_W) < std::cos(kFaceOnFace)) return false;
    mid += p.p_W;
    m += p.n_area_W;
  }
  mid /= static_cast<double>(contacts.size());
  double reach = 0;
  for (const auto& p : contacts) reach = std::max(reach, (p.p_W - mid).norm());
  if (reach <= tol) return false;  // within tol of one point (ContactLayout::kSingle)
  if (m.norm() < 1e-9 || m.dot(kUp) <= 0) return false;
  m.normalize();
  const double slope = std::acos(std::clamp(m.dot(kUp), -1.0, 1.0));
  if (slope <= cone || slope > kSteepestSlope) return false;
  for (const auto& p : contacts)
    if (p.n_area_W.dot(m) < std::cos(kOneSurface)) return false;
  r.friction_ok = false;
  r.failure = Failure::kSlide;
  r.slips = true;
  r.slips_downhill = true;
  r.plane_normal = m;
  r.d_f = downSlope(m);
  r.pivot = farthest(contacts, r.d_f);
  return true;
}

}  // namespace

Stability evaluateStability(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com,
                            const StabilityParams& prm) {
  Stability r;
  if (contacts.empty()) return r;
  const double cone = std::atan(prm.friction);
  // ---------------------------------------------------------------- hanging (beyond the paper,
  // whose heuristic needs contacts beneath the centre of mass: its stated limit). Every contact
  // above the centre of mass, pushing up on the whole (an object pressed under a table is not
  // hanging: its contacts push down).
  // Below the centre of mass only side contacts (a wall the hanging object leans on, normals
  // within kSideContact of horizontal), nothing that holds it up from below.
  // And a support above it that pushes up (a wall alone holds nothing up).
  // Below it, the area's own normal tells a wall (sideContact): the blended one leans up where
  // the object's rim or bottom edge meets the wall.
  // Above the centre of mass a wall pushes neither up nor down (sideContact: a pan handle's end
  // against the wall beside its hook, whose blended normals lean down). (Below it too: poses
  // on a shelf unit's walls were then judged hanging, and its search took 10 % longer.)
  bool hangs = true, held_above = false;
  double up_push = 0;
  for (const auto& p : contacts) {
    const bool below = p.p_W.z() <= com.z() + prm.tol;
    if (below) hangs = hangs && sideContact(p);
    else held_above = held_above || p.n_W.dot(kUp) >= kSideContact;
    if (below || !sideContact(p)) up_push += p.n_W.dot(kUp);
  }
  if (hangs && held_above && up_push > 0) return hangingStability(contacts, com, prm);
  // ---------------------------------------------------------------- planar case
  std::vector<Eigen::Vector3d> pts;
  for (const auto& p : contacts) pts.push_back(p.p_W);
  const PlaneFit fit = fitPlane(pts);
  const Eigen::Vector3d& c = fit.centroid;
  const Eigen::Vector3d n = fit.normal.dot(kUp) < 0 ? Eigen::Vector3d(-fit.normal) : fit.normal;
  const double off = fit.off, spread2 = fit.spread;
  // Planar: on one plane and spanning it (contacts on a line lie on every plane through it).
  // The contacts must push the object up: their mean normal (pointing at the object) against
  // gravity. Contacts from above (an object pressed under a table) never support it.
  Eigen::Vector3d nbar = Eigen::Vector3d::Zero();
  for (const auto& p : contacts) nbar += p.n_W;
  const bool from_below = nbar.dot(kUp) > 0;
  // The planar test is the contact-force model's closed form when the contacts are faces on the
  // plane (forces along its normal balance gravity exactly when c^_O lies in Omega). A contact's
  // normal blends the object's and the area's (sphereContact), so where either surface is the
  // plane's face it lies within 45 degrees of the plane's normal. A normal farther off proves
  // neither is (box edges against the walls of a V-groove, a body between two walls, a marker's
  // foot and its lean across a cup): then the contact forces decide.
  bool faces_on_plane = true;
  for (const auto& p : contacts) faces_on_plane = faces_on_plane && p.n_W.dot(n) >= std::cos(M_PI / 4) - 1e-9;
  if (off <= prm.tol && spread2 > prm.tol && n.dot(kUp) > 1e-3) {
    r.planar = true;
    r.plane_normal = n;
    const Support s = analyse(pts, c, n, com);
    if (!s.valid) {  // collinear: the tree rotates further, unless it slides first
      slidesDownSteepSurface(r, contacts, cone, prm.tol);
      return r;
    }
    r.hull = s.hull3;
    r.quality = s.quality;
    r.tipping_angle = s.tip;
    r.com_inside = s.inside >= 0;
    r.friction_ok = std::acos(std::clamp(n.dot(kUp), -1.0, 1.0)) < cone;  // angle(P, -d_g) < atan(mu)
    r.stable = from_below && r.friction_ok && r.com_inside && s.tip >= prm.min_tipping_angle && s.quality >= 0.3 &&
               polygonWidth(s.hull2) >= prm.min_support_width;
    // Contacts that are not faces on the plane: the contact forces decide, with their margin
    // (a marker leaning across a cup, its foot in the corner). The closed form's verdict still
    // counts as balanced: propped on domes, the rock settle finds where it sinks.
    r.balanced = r.stable;
    if (!faces_on_plane) {
      bool forces_balance = false;
      r.stable = balancedWithMargin(contacts, com, prm, &forces_balance);
      r.balanced = r.balanced || forces_balance;
      r.friction_ok = r.friction_ok || r.stable;
    }
    Eigen::Vector3d slip = Eigen::Vector3d::Zero();
    if (!faces_on_plane && !r.balanced) slip = slipOf(contacts, com, prm);
    if (r.stable) {
      r.failure = Failure::kNone;
    } else if (slides(r, slip)) {
      // slides along slip
    } else if (!r.friction_ok) {
      r.failure = Failure::kSlide;
      r.d_f = downSlope(n);
    } else {
      r.failure = Failure::kTip;
      r.d_f = tipDirection(s);
      tipEdge(s, &r.tip_edge_point, &r.tip_edge_dir);
    }
    r.pivot = farthest(contacts, r.d_f);
    return r;
  }
  // ---------------------------------------------------------------- non-planar case
  // The paper's heuristic (contacts whose normal lies in the friction cone about -d_g form
  // Omega', tested like the planar case) gives Q and the failure direction for the local
  // optimisation. Stability is decided by the contact forces (contact_forces.h): forces in
  // the contacts' friction cones balance gravity, and gravity tilted by half the friction angle
  // towards each of the 4 axis directions of G (a margin against sliding and tipping, the force
  // model's form of the planar case's tipping angle). This accepts leaning (a pen in a cup, a
  // plate against a peg) and gravity-loaded wedging, and rejects a ball on one point, a body on
  // a line of contacts, and a squeeze between parallel walls.
  std::vector<Eigen::Vector3d> below;
  double zmin = 1e300;
  for (const auto& p : contacts) {
    zmin = std::min(zmin, p.p_W.z());
    if (std::acos(std::clamp(p.n_W.dot(kUp), -1.0, 1.0)) < cone) below.push_back(p.p_W);
  }
  Support s1;
  if (below.size() >= 3) {
    Eigen::Vector3d cb = Eigen::Vector3d::Zero();
    for (const auto& p : below) cb += p;
    cb /= static_cast<double>(below.size());
    s1 = analyse(below, cb, kUp, com);
  }
  // The projected support of all contacts ranks non-planar poses.
  const Support all = analyse(pts, Eigen::Vector3d(c.x(), c.y(), zmin), kUp, com);
  const Support& ref = s1.valid ? s1 : all;
  if (ref.valid) {
    r.hull = ref.hull3;
    r.tipping_angle = ref.tip;
    r.quality = ref.quality;
    r.com_inside = ref.inside >= 0;
  }
  const bool stable = balancedWithMargin(contacts, com, prm, &r.balanced);
  r.friction_ok = stable;
  r.stable = stable;
  const Eigen::Vector3d slip = stable || r.balanced ? Eigen::Vector3d::Zero() : slipOf(contacts, com, prm);
  if (stable) {
    r.failure = Failure::kNone;
    r.quality = std::max(r.quality, 0.3);  // Q is a ranking here; equilibrium decided stability
  } else if (!slides(r, slip) && (r.balanced || !slidesDownSteepSurface(r, contacts, cone, prm.tol))) {
    r.failure = Failure::kTip;
    r.d_f = ref.valid ? tipDirection(ref) : Eigen::Vector3d::UnitX();
    if (ref.valid) tipEdge(ref, &r.tip_edge_point, &r.tip_edge_dir);
  }
  r.pivot = farthest(contacts, r.d_f);
  return r;
}

}  // namespace place_planner
