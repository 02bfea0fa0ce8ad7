// The batched tree steps (tree_stepper.h): first contact, contact points with stability and
// tilt axis, tilt angles. Every pending pose of every tree advances together.
#include "place_planner/search/tree_stepper.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "place_planner/judgement/penetration.h"
#include "place_planner/search/contact_points.h"
#include "place_planner/search/local_optimisation.h"
#include "place_planner/infra/parallel_for.h"
#include "place_planner/search/tilt_axis.h"

namespace place_planner {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// PP_TRACE=1 in the environment prints every tree node and rotation to stderr.
const bool kTrace = std::getenv("PP_TRACE") != nullptr;
constexpr double kSmallTurn = 2.0 * M_PI / 180.0;
constexpr int kMaxTurnsPerRotation = 4;
constexpr int kMaxRocks = 8;  // rock settle steps per tree
// Swing steps per tree: a mug swung in from a start turned about the vertical (hanging_starts)
// took up to 72 on J-hooks.
constexpr int kMaxSwings = 120;
constexpr double kSwingDrop = 1e-6;  // m: a swing move counts when it lowers the centre of mass this much
// Roll settle: coarse roll steps searched each way, their size, the fine steps refining a
// bottom within a coarse step either side, and the steepest roll axis.
constexpr int kRollSteps = 8;
constexpr double kRollStep = 3.0 * M_PI / 180.0;
constexpr int kRollFine = 2;  // 1 degree
constexpr int kRollNear = 4;  // coarse steps dropped in the first round
constexpr double kMaxRollAxisSlope = 0.34;  // sin 20 degrees
// The bottom of a roll holds when the crests either way rise at least this (m) above it; a
// lower crest does not hold a release and the roll goes on over it. Measured (Bullet in its
// scaled world, ValidatorConfig::world_scale, released 2 mm above): the 1k YCB marker stays on
// 15 of its 16 hull facets whose crests rise 0.017-0.27 mm and rolls off 9 of the 12 below
// 0.015 mm; a round rod has no crest at all. (0.5 mm, the earlier value, was measured against
// Bullet at 1 unit per metre, which rolled the marker off every facet: no lying marker held.)
constexpr double kMinRollRise = 5e-5;
constexpr double kRollBump = 1e-5;  // m, dents a rolling object passes over
// Rock settle: the rock tried about each horizontal axis of G, and the drop of the centre of
// mass (m) that makes the pose rock there (a tenth of a millimetre: above a scan's dents under a
// 1 degree rock, well below the 0.3-1 mm a pose propped a few degrees off drops).
constexpr double kRockStep = 1.0 * M_PI / 180.0;
constexpr double kRockDrop = 1e-4;
// A rocked pose whose contacts include two steeper than kWedgeTilt from vertical, facing each
// other (horizontal parts more than 120 degrees apart), hangs between two edges: a box lowered
// across a tray compartment, its rounded edges on its walls' edges. The area's spheres round a sharp
// edge into a cylinder of their radius (3-6 mm), Bullet's margins by 1 mm: the object sinks
// deeper between the planner's edges, onto contacts that tilt more than Bullet's. Not at rest.
// Measured on the 56 1k scenes with rock settle (place_planner_suite --pairs _1k@ --holes none
// --max-drops 4 --no-fig6): precision 209/217 -> 206/210 at 52 degrees (the three cracker boxes
// across the tray's compartment are gone), coverage 35/37 -> 36/38; at 45 degrees the mug on
// the rack's peg tops was lost too, at 60 the sugar box hung between pegs was kept.
constexpr double kWedgeTilt = 52.0 * M_PI / 180.0;

// Falling (TreeContext::fall_tip): the area under the centre of mass (the highest surface within
// kFallProbe of it, m) lies more than kFallDrop (m) below the lowest contact: a drop, not a floor.
constexpr double kFallDrop = 0.01;
constexpr double kFallProbe = 0.015;

// The kWedgeTilt test on a rocked pose's contacts. A pose that also stands on a floor (a contact
// within kFloorTilt of vertical: a pen's foot in a cup, leaning on the rim) does not hang.
constexpr double kFloorTilt = 25.0 * M_PI / 180.0;
bool hangsBetweenEdges(const std::vector<ContactPoint>& contacts) {
  const double c = std::cos(kWedgeTilt);
  for (const ContactPoint& p : contacts)
    if (p.n_W.z() >= std::cos(kFloorTilt)) return false;
  for (size_t a = 0; a < contacts.size(); ++a) {
    const Eigen::Vector3d& na = contacts[a].n_W;
    if (na.z() > c) continue;
    for (size_t b = a + 1; b < contacts.size(); ++b) {
      const Eigen::Vector3d& nb = contacts[b].n_W;
      if (nb.z() > c) continue;
      if (Eigen::Vector2d(na.x(), na.y()).normalized().dot(Eigen::Vector2d(nb.x(), nb.y()).normalized()) < -0.5)
        return true;
    }
  }
  return false;
}

// A planar support whose every contact normal is within kFlatNormal of vertical: any rock about
// the centre of mass lifts it, so the rock settle's probes are skipped (a table, a box's top).
constexpr double kFlatNormal = 5.0 * M_PI / 180.0;
bool flatSupport(const Stability& s, const std::vector<ContactPoint>& contacts) {
  if (!s.planar) return false;
  const double up = std::cos(kFlatNormal);
  for (const ContactPoint& c : contacts)
    if (c.n_W.z() < up) return false;
  return true;
}

Rigid translated(Rigid X, const V3& d) {
  X.t = X.t + d;
  return X;
}

// A direction is blocked when a contact away from the axis would move into the area.
bool blocked(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& s,
             const Eigen::Vector3d& d, int sigma, double lever_tol) {
  for (const auto& c : contacts) {
    const Eigen::Vector3d r = c.p_W - s;
    const Eigen::Vector3d v = sigma * d.cross(r);
    if (v.norm() < lever_tol) continue;  // on the axis
    if (v.normalized().dot(c.n_W) < -0.3) return true;
  }
  return false;
}

// Whether a turn about the axis (s, d), `sign` 1 counter-clockwise or -1, raises the centre of
// mass com: gravity cannot tip a free object that way (tiltStep does not follow it).
bool raises(const Eigen::Vector3d& com, const Eigen::Vector3d& s, const Eigen::Vector3d& d, int sign) {
  return sign * d.cross(com - s).z() > 1e-3 * (com - s).norm();  // d(com.z)/d(angle), signed
}

// Whether a turn about the axis (s, d) that does not raise the centre of mass com is free of
// the contacts (tiltStep's limits: the uphill turn is not followed, a blocked one not searched).
bool downhillTurn(const std::vector<ContactPoint>& contacts, const Eigen::Vector3d& com, const Eigen::Vector3d& s,
                  const Eigen::Vector3d& d, double lever_tol) {
  return (!raises(com, s, d, 1) && !blocked(contacts, s, d, 1, lever_tol)) ||
         (!raises(com, s, d, -1) && !blocked(contacts, s, d, -1, lever_tol));
}

// Highest area surface within `radius` of (x, y) in the height grid; -inf over nothing.
double surfaceBelow(const HeightGrid& g, double x, double y, double radius) {
  const int r = static_cast<int>(std::ceil(radius / g.cell));
  const int cx = static_cast<int>(std::floor((x - g.x0) / g.cell));
  const int cy = static_cast<int>(std::floor((y - g.y0) / g.cell));
  double top = -kInf;
  for (int iy = std::max(0, cy - r); iy <= std::min(g.ny - 1, cy + r); ++iy)
    for (int ix = std::max(0, cx - r); ix <= std::min(g.nx - 1, cx + r); ++ix)
      top = std::max(top, g.max_z[iy * g.nx + ix]);
  return top;
}

// The roll and rock settles' probe (rollStep, rockStep): X turned by `angle` about the horizontal
// axis through the centre of mass com, lifted clear (R: the object's bounding radius) and
// dropped to first contact along -z (V-A). After the drop by t the centre of mass is
// probeRise(q, t) higher than in X (it was turned about itself).
TranslationQuery rolledProbe(const Rigid& X, const Eigen::Vector3d& com, const Eigen::Vector3d& axis, double angle,
                             double R, double gap) {
  const double lift = R * std::abs(angle) + gap;
  Rigid Y = angle == 0 ? X : rotatedAbout(X, com, axis, angle);
  Y.t = Y.t + v3(0, 0, lift);
  return TranslationQuery{Y, v3(0, 0, -1), lift + gap + 0.01};
}
double probeRise(const TranslationQuery& q, double t, double gap) { return t >= kInf ? kInf : q.tmax - gap - 0.01 - t; }

void addTime(double* slot, Clock::time_point t0) {
  if (slot) *slot += msSince(t0);
}

}  // namespace

TreeStepper::TreeStepper(const TreeContext& ctx) : ctx_(ctx), diag_(norm(ctx.am.bounds.hi - ctx.am.bounds.lo)) {}

void TreeStepper::addRoot(const Rigid& X_GO, int root, const V3& com_O, const V3& direction, double tmax,
                          const PegLine& peg) {
  TreeNode n;
  n.peg = peg;
  n.X_GO = X_GO;
  n.root = root;
  n.com_O = com_O;
  n.path.push_back(X_GO);
  n.pending.push_back(direction);
  n.pending_tmax.push_back(tmax);
  translate_.push_back(std::move(n));
}

std::vector<int> TreeStepper::openRoots() const {
  std::vector<int> open;
  for (const auto* list : {&translate_, &contact_, &rotating_, &rolling_, &rocking_, &swinging_})
    for (const TreeNode& n : *list) open.push_back(n.root);
  std::sort(open.begin(), open.end());
  open.erase(std::unique(open.begin(), open.end()), open.end());
  return open;
}

void TreeStepper::prune(const std::function<bool(const TreeNode&)>& drop) {
  for (auto* list : {&translate_, &contact_, &rotating_, &rolling_, &rocking_, &swinging_})
    list->erase(std::remove_if(list->begin(), list->end(), drop), list->end());
}

void TreeStepper::step(std::vector<TreeLeaf>& leaves) {
  if (!translate_.empty()) firstContactStep();
  if (!contact_.empty()) contactStep(leaves);
  if (!rotating_.empty()) tiltStep(leaves);
  if (!rolling_.empty()) rollStep();
  if (!rocking_.empty()) rockStep(leaves);
  if (!swinging_.empty()) swingStep();
}

// ---------------------------------------------------------------- first contact (V-A)
// Exact translation along each pending direction until the object first touches the area.
void TreeStepper::firstContactStep() {
  const auto t0 = Clock::now();
  std::vector<TranslationQuery> q;
  // A negative reach: the move goes that far when nothing is hit on the way.
  for (const TreeNode& n : translate_) q.push_back({n.X_GO, n.pending.front(), std::abs(n.pending_tmax.front())});
  std::vector<double> t;
  ctx_.backend.distance(q, t);
  std::vector<TreeNode> again;
  for (size_t i = 0; i < translate_.size(); ++i) {
    TreeNode& n = translate_[i];
    if (t[i] >= kInf && n.pending_tmax.front() < 0) t[i] = -n.pending_tmax.front();
    if (t[i] >= kInf) continue;  // nothing below: the object would fall off the area
    n.X_GO = translated(n.X_GO, t[i] * n.pending.front());
    n.path.push_back(n.X_GO);
    n.pending.erase(n.pending.begin());
    n.pending_tmax.erase(n.pending_tmax.begin());
    (n.pending.empty() ? contact_ : again).push_back(std::move(n));
  }
  translate_.swap(again);
  addTime(ctx_.times ? &ctx_.times->first_contact : nullptr, t0);
}

// ---------------------------------------------------------------- contact points (V-B),
// stability (VI), tilt axis (V-C.1) and the tree's decision for each pose.
void TreeStepper::contactStep(std::vector<TreeLeaf>& leaves) {
  auto t0 = Clock::now();
  std::vector<Rigid> X;
  for (const TreeNode& n : contact_) X.push_back(n.X_GO);
  std::vector<std::vector<SphereContact>> raw;
  ctx_.backend.contactPoints(X, raw);
  addTime(ctx_.times ? &ctx_.times->contact_points : nullptr, t0);
  t0 = Clock::now();
  if (ctx_.tree_nodes) *ctx_.tree_nodes += static_cast<long>(contact_.size());
  const double cd = ctx_.cd;
  // Contacts, stability and tilt axis of every node are independent: computed on the pool;
  // the tree decisions below stay serial, in node order.
  std::vector<Stability> stab(contact_.size());
  std::vector<TiltAxis> axes(contact_.size());
  parallelFor(contact_.size(), ctx_.threads, [&](size_t i) {
    TreeNode& n = contact_[i];
    n.contacts = reduceContacts(raw[i], cd);
    const Eigen::Vector3d com = toEigen(apply(n.X_GO, n.com_O));
    stab[i] = evaluateStability(n.contacts, com, ctx_.stability);
    const Eigen::Vector3d k1 = toEigen(rotate(n.X_GO, toV3(ctx_.om.principal_axes.col(0))));
    axes[i] = tiltAxis(n.contacts, com, k1, Eigen::Vector3d(0, 0, -1), 1.5 * cd, n.root + 7919u * n.depth);
  });
  for (size_t i = 0; i < contact_.size(); ++i) {
    TreeNode& n = contact_[i];
    const Eigen::Vector3d com = toEigen(apply(n.X_GO, n.com_O));
    const Stability& s = stab[i];
    const TiltAxis& axis = axes[i];
    const bool supported = s.stable || (s.planar && s.friction_ok && s.com_inside &&
                                        s.tipping_angle >= ctx_.stability.min_tipping_angle);
    auto leaf = [&](bool stable, bool at_rest) {
      leaves.push_back(TreeLeaf{n.X_GO, n.root, stable, at_rest, supported, s.quality, s.tipping_angle, n.contacts, n.path});
      leaves.back().hanging = s.hanging;
      leaves.back().peg = n.peg;
    };
    n.quality = s.quality;
    n.tipping_angle = s.tipping_angle;
    n.supported = supported;
    n.hanging = s.hanging;
    if (kTrace)
      std::fprintf(stderr, "node root %d depth %d opt %d: %zu contacts layout %d planar %d stable %d hanging %d peg %d swung %d swings %d tip %.1f deg Q %.3f slips %d d_f %.2f %.2f %.2f\n",
                   n.root, n.depth, n.opt, n.contacts.size(), (int)axis.layout, s.planar, s.stable, s.hanging, n.peg.known(), n.swung, n.swings,
                   s.tipping_angle * 180 / M_PI, s.quality, s.slips, s.d_f.x(), s.d_f.y(), s.d_f.z());
    if (n.contacts.empty()) continue;
    // One contact or a line of contacts never holds an object as a polygon (a ball rolls, a
    // cylinder on its side turns about its line): tilt (Section V-C) about the point or the line.
    // (Accepting a band of contacts along a line as a support was tried: Bullet rolled every
    // such marker, its centre of mass not above the true line of contact.)
    bool line = axis.layout == ContactLayout::kSingle || axis.layout == ContactLayout::kCollinear;
    const bool can_turn = n.depth < ctx_.max_rotations &&
                          n.turns < kMaxTurnsPerRotation * std::max(1, ctx_.max_rotations);
    // A line of contacts under the centre of mass: the object lies on a curved side (a
    // marker, a bottle). Its band of contacts is as wide as the contact tolerance, not as its
    // support, so it neither holds as a polygon nor tips about the band's edge: it rolls to
    // the bottom of its roll (rollStep) and holds there when a roll either way lifts it.
    const bool rolls = axis.layout == ContactLayout::kCollinear && s.com_inside && !s.hanging &&
                       std::abs(axis.d_A.z()) < kMaxRollAxisSlope;
    // A line that does not roll, whose downhill turns its own contacts block (a rod's foot on a
    // floor and its lean on a wall, a tenth of their length apart), is no hinge: the pose is
    // judged as a support (it holds, or it slides: the local optimisation), not turned.
    if (line && !rolls && !downhillTurn(n.contacts, com, axis.s_A, axis.d_A, 1.5 * cd)) line = false;
    if (line && rolls && n.roll == 1) {
      const bool holds = n.roll_margin >= ctx_.stability.min_tipping_angle;
      n.tipping_angle = n.roll_margin;
      leaves.push_back(TreeLeaf{n.X_GO, n.root, holds, true, holds, s.quality, n.roll_margin, n.contacts, n.path, true});
      continue;
    }
    n.roll = 0;
    // Falling (beyond the paper): an object whose centre of mass lies far past its support
    // (tipping angle below -fall_tip) over a drop, at two poses of the tree in a row, is going
    // over a ledge. Its quasi-static walk down the ledge, facet by facet, would end where the
    // roots below it land anyway (measured: the same precision and coverage over the suite's
    // 56 scenes; 1963 -> 1607 nodes for the 1k mug on books_stack), so the tree ends there, not stable. One such
    // pose alone is not enough: a box released tilted lands on one edge, far past it, and
    // turns back flat.
    bool overhang = ctx_.fall_tip > 0 && !s.stable && !rolls && s.tipping_angle < -ctx_.fall_tip;
    if (overhang) {
      double low = kInf;
      for (const ContactPoint& c : n.contacts) low = std::min(low, c.p_W.z());
      overhang = surfaceBelow(ctx_.am.grid, com.x(), com.y(), kFallProbe) < low - kFallDrop;
    }
    // A root turned off its hanging rest swings to it first (PegLine::swing_first).
    const bool falls = overhang && n.overhang && (!n.peg.swing_first || n.swung || n.swings >= kMaxSwings);
    n.overhang = overhang;
    // Local optimisation (Section VI): slide down the slope, or tip into the failure direction.
    auto optimise = [&] {
      const auto tl = Clock::now();
      // A slide down a steep surface lifts the object clear of it by half the last lift: between
      // two surfaces that each slide it onto the other (a trough's sides) it settles into
      // contact with both within a few slides, instead of bouncing by the same lift forever.
      const LocalStep step = localOptimisationStep(s, com, s.slips_downhill ? std::ldexp(cd, -std::min(n.opt, 8)) : cd);
      addTime(ctx_.times ? &ctx_.times->local_optimisation : nullptr, tl);
      if (step.kind == LocalStep::kSlide) {
        ++n.opt;
        n.X_GO = translated(n.X_GO, toV3(step.lift));
        n.path.push_back(n.X_GO);
        n.pending = {toV3(step.slide), v3(0, 0, -1)};
        // Down a steep surface: at most the object's size, and that far when nothing is hit
        // (a negative reach, firstContactStep); the drop then finds where it lands.
        n.pending_tmax = {s.slips_downhill ? -ctx_.om.bounding_radius : 0.5 * diag_, diag_};
        translate_.push_back(std::move(n));
      } else if (step.kind == LocalStep::kRotate) {
        ++n.opt;
        n.s_A = step.s_A;
        n.d_A = step.d_A;
        n.both_directions = false;
        n.local_rotation = true;
        rotating_.push_back(std::move(n));
      } else {
        leaf(false, true);
      }
    };
    if (s.hanging && n.peg.known() && !n.swung && n.swings < kMaxSwings && !falls) {
      n.settle_v = s.settle_v;
      n.settle_w = s.settle_w;
      swinging_.push_back(std::move(n));  // threaded on a peg: to the pendulum's rest first
    } else if (s.hanging && s.stable) {
      leaf(true, true);  // hanging at the bottom of its swing (on a point or a line, too)
    } else if (falls) {
      TreeLeaf l{n.X_GO, n.root, false, true, supported, s.quality, s.tipping_angle, n.contacts, n.path};
      l.fell = true;
      leaves.push_back(std::move(l));
    } else if (s.slips && n.opt < ctx_.max_opt) {
      optimise();  // friction alone fails: it slides before it turns (even on a line of contacts)
    } else if (line && rolls && can_turn) {
      n.d_A = axis.d_A;
      rolling_.push_back(std::move(n));
    } else if (line && can_turn) {
      n.s_A = axis.s_A;
      n.d_A = axis.d_A;
      n.both_directions = true;
      n.local_rotation = false;
      rotating_.push_back(std::move(n));
    } else if (line) {
      leaf(false, false);  // still tilting when the tree was cut
    } else if ((s.stable || s.balanced) && ctx_.rock_settle && n.rocks < kMaxRocks &&
               !flatSupport(s, n.contacts)) {
      // Held, or balanced by the contact forces without their margin (propped a few degrees
      // off on domes or a rim): the rock settle finds whether it sinks to a lower pose.
      n.held = s.stable;
      rocking_.push_back(std::move(n));
    } else if (s.stable) {
      leaf(true, true);
    } else if (n.opt < ctx_.max_opt) {
      optimise();
    } else {
      leaf(false, true);
    }
  }
  contact_.clear();
  addTime(ctx_.times ? &ctx_.times->stability : nullptr, t0);
}

// ---------------------------------------------------------------- the swing (beyond the paper)
// A hanging object on its peg comes to rest where its centre of mass is lowest: a pendulum's
// rest, found by descent. Each step tries the object turned both ways about the two horizontal
// axes (along and across the peg) through the middle of its contacts (a swing, a pitch), about
// the peg's axis (the loop sliding round the peg) and moved both ways across the peg (a loop
// sliding over it), each lowered back onto the support (V-A's translation); it takes the move
// that lowers the centre of mass most, or halves the step when none does, from kSwingStart down
// to kSwingEnd. Along the peg friction decides (the stability test); where it does not hold,
// or a wall stops a turn half-way, the settle of the unbalanced contact wrench
// (ContactForces::unbalanced, first-order physics: no contact pushed in) is one more move. The
// exact rotation to the next contact (V-C.2) does not serve here: a loop's own contacts, within a
// collision distance of the peg all round it, stop a turn after a fraction of a degree. The path
// keeps the swing's last pose only: the robot lets go, the object swings by itself.
void TreeStepper::swingStep() {
  const auto t0 = Clock::now();
  constexpr double kSwingStart = 4.0 * M_PI / 180.0, kSwingEnd = 0.25 * M_PI / 180.0;
  // None; turns both ways about the two horizontal axes (along and across the peg) through the
  // contacts' middle, and about the peg's axis; slides both ways across the peg; and, while
  // gravity is not balanced, the settle its unbalanced wrench starts (down a peg that friction
  // does not hold; a mug pressed against a rack's board turns along it, which no single move
  // above can do).
  constexpr int kMoves = 1 + 2 * 2 + 2 + 2 + 1;
  const double gap = 0.5 * ctx_.cd;
  // Per node: the pivot, how far its contacts spread about it, the centre of mass's depth
  // below it, and the horizontal axes along and across the peg (swingStep runs on known pegs).
  struct Frame {
    Eigen::Vector3d mid, com, along, across;
    double reach, depth;
  };
  std::vector<Frame> frames;
  std::vector<TranslationQuery> q, across_q;
  q.reserve(swinging_.size() * kMoves);
  for (TreeNode& n : swinging_) {
    if (n.swing_step <= 0) n.swing_step = kSwingStart;
    // The pivot: the middle of its contacts (held by the peg and leaning on a board, it turns
    // about both), or of the loop's contacts on the peg (those nearest its axis) where the
    // swing's first turn about the former would carry the loop across the peg farther than its
    // room (PegLine::room; a pan's disc leaning on the wall 10 cm below a slot with 6 mm either
    // side of the wire): lowered straight down, nothing stops the loop's side going into the
    // peg, and only the result's guard would see it (the vertices are far off). Mugs leaning on
    // a rack's board or a tree's trunk keep the middle of all (turns of 1-4 mm at their loops).
    auto toAxis = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector3d v = p - n.peg.point;
      return (v - v.dot(n.peg.axis) * n.peg.axis).norm();
    };
    double nearest = kInf;
    for (const ContactPoint& c : n.contacts) nearest = std::min(nearest, toAxis(c.p_W));
    Frame f;
    Eigen::Vector3d on_peg = Eigen::Vector3d::Zero();
    f.mid = Eigen::Vector3d::Zero();
    int m = 0;
    for (const ContactPoint& c : n.contacts) {
      f.mid += c.p_W / static_cast<double>(n.contacts.size());
      if (toAxis(c.p_W) <= nearest + 1.5 * ctx_.cd) on_peg += c.p_W, ++m;
    }
    on_peg /= static_cast<double>(std::max(1, m));
    if (n.peg.room > 0 && (on_peg - f.mid).norm() * kSwingStart > n.peg.room) f.mid = on_peg;
    f.reach = ctx_.cd;  // how far the contacts spread about the middle: what may dig in
    for (const ContactPoint& c : n.contacts) f.reach = std::max(f.reach, (c.p_W - f.mid).norm() + ctx_.cd);
    f.com = toEigen(apply(n.X_GO, n.com_O));
    f.depth = std::max(f.mid.z() - f.com.z(), ctx_.cd);
    f.along = Eigen::Vector3d(n.peg.axis.x(), n.peg.axis.y(), 0).normalized();
    f.across = Eigen::Vector3d::UnitZ().cross(f.along);
    // The slides across the peg, swept first (lifted off the peg's top): one ends where the
    // loop's side meets the peg (a pan handle's slot, 6 mm either side of a J-hook's wire), as
    // V-A's translation does.
    Rigid Y = n.X_GO;
    Y.t = Y.t + v3(0, 0, gap);
    for (const double sign : {1.0, -1.0})
      across_q.push_back(TranslationQuery{Y, toV3(sign * f.across), n.swing_step * f.depth});
    frames.push_back(f);
  }
  std::vector<double> d, d_across;
  ctx_.backend.distance(across_q, d_across);
  for (size_t i = 0; i < swinging_.size(); ++i) {
    const TreeNode& n = swinging_[i];
    const Frame& f = frames[i];
    const double t = n.swing_step;
    auto push = [&](const Rigid& Y0, double lift) {
      Rigid Y = Y0;
      Y.t = Y.t + v3(0, 0, lift);
      q.push_back(TranslationQuery{Y, v3(0, 0, -1), lift + gap + 0.01});
    };
    push(n.X_GO, gap);
    for (const Eigen::Vector3d& axis : {f.along, f.across})
      for (const double sign : {1.0, -1.0}) push(rotatedAbout(n.X_GO, f.mid, axis, sign * t), gap + f.reach * t);
    // Round the peg's axis: the loop slides round the peg (its contact moves over the peg).
    for (const double sign : {1.0, -1.0}) push(rotatedAbout(n.X_GO, n.peg.point, n.peg.axis, sign * t), gap + f.reach * t);
    for (int k = 0; k < 2; ++k) {
      const double len = std::min(t * f.depth, d_across[2 * i + k]);
      push(translated(n.X_GO, toV3((k == 0 ? 1.0 : -1.0) * len * f.across)), gap);
    }
    {
      // A point at the contacts' reach moves t * depth (a slide's length).
      const double len = t * f.depth;
      const Eigen::Vector3d w = len * n.settle_w;
      Rigid Y = w.norm() > 0 ? rotatedAbout(n.X_GO, f.com, w.normalized(), w.norm()) : n.X_GO;
      push(translated(Y, toV3(len * n.settle_v)), gap + len);
    }
  }
  ctx_.backend.distance(q, d);
  for (size_t i = 0; i < swinging_.size(); ++i) {
    TreeNode& n = swinging_[i];
    int best = 0;
    double h[kMoves];
    const size_t i0 = i * kMoves;
    for (int k = 0; k < kMoves; ++k) {
      const TranslationQuery& tq = q[i0 + k];
      const double dk = d[i0 + k];
      h[k] = dk >= kInf || dk >= tq.tmax ? kInf : apply(tq.X_GO, n.com_O).z - dk;
      if (k == kMoves - 1 && n.settle_v.squaredNorm() + n.settle_w.squaredNorm() == 0) h[k] = kInf;
    }
    // The lowest move that leaves the object out of the area: lowered straight down, a turn can
    // still push it sideways into a wall (a ring into the board behind its peg, a mug into a
    // mug tree's trunk, which only a sideways ray sees), which the result's penetration guard
    // would then reject; the next lowest is taken instead. By the vertices alone (the result's
    // guard looks at all the probes, penetration.h, at 4-5 times the swing's time if each move
    // did), unless the tree runs again because its rest was inside (PegLine::probe_swing).
    for (int tries = 0; tries < kMoves; ++tries) {
      best = 0;
      for (int k = 1; k < kMoves; ++k)
        if (h[k] < h[best]) best = k;
      if (best == 0 || ctx_.penetration_limit <= 0 || h[best] >= h[0] - kSwingDrop) break;
      const Rigid Y = translated(q[i0 + best].X_GO, v3(0, 0, -d[i0 + best]));
      if (penetration(ctx_.om, ctx_.am, Y, 0.03, n.peg.probe_swing).within(ctx_.penetration_limit, ctx_.penetration_sideways)) break;
      h[best] = kInf;
    }
    ++n.swings;
    // A move counts when it lowers the centre of mass by a micrometre: at the last step (0.25
    // degrees) a centre of mass 1 mm off under a 6 cm pendulum drops 4 micrometres.
    if (best != 0 && h[best] < h[0] - kSwingDrop) {
      n.X_GO = translated(q[i0 + best].X_GO, v3(0, 0, -d[i0 + best]));
      // The path's last pose is replaced while the swing goes on (nothing else moved it since).
      if (n.swing_pose == static_cast<int>(n.path.size()) - 1) n.path.back() = n.X_GO;
      else n.path.push_back(n.X_GO);
      n.swing_pose = static_cast<int>(n.path.size()) - 1;
      // Not counted against the tree's turns: the swing has its own bound (kMaxSwings), and a
      // ring spun 76 degrees to its rest must still tilt onto what it meets after it.
    } else {
      n.swing_step *= 0.5;
      if (h[0] < kInf) n.X_GO = translated(q[i0].X_GO, v3(0, 0, -d[i0]));
      n.swung = n.swing_step < kSwingEnd;
    }
    contact_.push_back(std::move(n));
  }
  swinging_.clear();
  addTime(ctx_.times ? &ctx_.times->tilt_vertex : nullptr, t0);
}

// ---------------------------------------------------------------- tilt angles (V-C.2)
// Exact angles to the next contact, vertex/surface and edge/edge, in both directions.
void TreeStepper::tiltStep(std::vector<TreeLeaf>& leaves) {
  std::vector<RotationQuery> q;
  std::vector<std::pair<double, double>> swing;  // ccw, cw: a hanging object's swing to rest
  for (const TreeNode& n : rotating_) {
    RotationQuery rq{n.X_GO, toV3(n.s_A), toV3(n.d_A)};
    // Of the tree's two branches only those that lower the centre of mass are followed:
    // gravity cannot tip a free object the other way, and the cut keeps the tree linear in
    // the number of rotations instead of exponential.
    const Eigen::Vector3d c = toEigen(apply(n.X_GO, n.com_O));
    const bool up_ccw = raises(c, n.s_A, n.d_A, 1), up_cw = raises(c, n.s_A, n.d_A, -1);
    if (!n.local_rotation && up_ccw) rq.limit_ccw = 0;
    if (!n.local_rotation && up_cw) rq.limit_cw = 0;
    // Neutral (the centre of mass above the axis: a cylinder on its side, a ball): after the
    // first turn of a tree only one way is followed, so rolling costs a path, not a tree.
    if (!n.local_rotation && !up_ccw && !up_cw && n.turns > 0) rq.limit_cw = 0;
    // A tilt ends where gravity can no longer carry it about this axis: once the centre of
    // mass has dropped below the axis (its lever past horizontal) the object slides or falls off
    // the pivot rather than keep turning on it. So the search covers the lever's elevation plus
    // 20 degrees (at least the paper's 60): an object on its end tips over until it lies (90),
    // one hanging over an edge is not turned round it to the side of a box.
    const Eigen::Vector3d lev = (c - n.s_A) - (c - n.s_A).dot(n.d_A) * n.d_A;
    const double elevation = lev.norm() > 1e-9 ? std::asin(std::clamp(lev.z() / lev.norm(), -1.0, 1.0)) : 0.0;
    const double reach = std::clamp(elevation + 20.0 * M_PI / 180.0, 60.0 * M_PI / 180.0, M_PI);
    if (!n.local_rotation) {
      rq.limit_ccw = std::min(rq.limit_ccw, reach);
      rq.limit_cw = std::min(rq.limit_cw, reach);
    }
    // Directions a contact blocks, or not asked for, are not searched (limit 0).
    if (blocked(n.contacts, n.s_A, n.d_A, 1, 1.5 * ctx_.cd)) rq.limit_ccw = 0;
    if (!n.both_directions || blocked(n.contacts, n.s_A, n.d_A, -1, 1.5 * ctx_.cd)) rq.limit_cw = 0;
    // The swing (beyond the paper) of an object hanging off no known peg: it turns about its
    // support until its centre of mass is straight below the axis, unless a contact stops it
    // first. Its lever's height after a turn t is A cos t + B sin t, lowest at t* = atan2(-B, -A).
    swing.push_back({kInf, kInf});
    if (n.hanging && lev.norm() > 1e-9) {
      const double A = lev.z(), B = n.d_A.cross(lev).z();
      const double t = std::atan2(-B, -A);
      if (t > 0 && t <= rq.limit_ccw) swing.back().first = t;
      if (t < 0 && -t <= rq.limit_cw) swing.back().second = -t;
    }
    q.push_back(rq);
  }
  std::vector<AnglePair> av, ae;
  auto t0 = Clock::now();
  ctx_.backend.vertexSurfaceRotation(q, av);
  addTime(ctx_.times ? &ctx_.times->tilt_vertex : nullptr, t0);
  // Edge/edge only has to beat the vertex/surface angle. Where no vertex meets a patch over
  // the whole tilt range, the object turns off the area: no edge/edge search.
  for (size_t i = 0; i < q.size(); ++i) {
    q[i].limit_ccw = av[i].ccw >= kInf ? 0.0 : std::min(q[i].limit_ccw, av[i].ccw);
    q[i].limit_cw = av[i].cw >= kInf ? 0.0 : std::min(q[i].limit_cw, av[i].cw);
  }
  t0 = Clock::now();
  ctx_.backend.edgeEdgeRotation(q, ae);
  addTime(ctx_.times ? &ctx_.times->tilt_edge : nullptr, t0);
  for (size_t i = 0; i < rotating_.size(); ++i) {
    const TreeNode& n = rotating_[i];
    bool turned = false;
    for (int sigma : {1, -1}) {
      if (sigma < 0 && !n.both_directions) continue;
      double a = sigma > 0 ? std::min(av[i].ccw, ae[i].ccw) : std::min(av[i].cw, ae[i].cw);
      const double sw = sigma > 0 ? swing[i].first : swing[i].second;
      if (sw < a) a = sw;  // it swings to rest before anything stops it
      if (kTrace && a < kInf)
        std::fprintf(stderr, "root %d depth %d sigma %d angle %.2f deg\n", n.root, n.depth, sigma, a * 180 / M_PI);
      else if (kTrace)
        std::fprintf(stderr, "root %d depth %d sigma %d angle none (blocked or free)\n", n.root, n.depth, sigma);
      if (a >= kInf) continue;  // blocked, or turns freely: no resting pose that way
      TreeNode c;
      c.X_GO = rotatedAbout(n.X_GO, n.s_A, n.d_A, sigma * a);
      c.root = n.root;
      c.com_O = n.com_O;
      // Rolling over the facets of a curved surface takes many small turns; only turns of a
      // few degrees count against max_rotations (all of them against a hard cap).
      c.depth = n.depth + (n.local_rotation || a < kSmallTurn ? 0 : 1);
      c.turns = n.turns + 1;
      c.opt = n.opt;
      c.overhang = n.overhang;
      // A turn does not take it off its peg: the leaf keeps it, so that the pose's robustness
      // trials swing on it (without it a ring leaning on a mug tree's post had none robust).
      // The tree itself swings no more after a turn: the exact tilt (V-C) goes on to the next
      // contact. Measured: swinging again after a turn, a ring's releases on a level peg held
      // 9-10 of 12 instead of 12, and the swing and the tilt took turns in steps of 0.2 deg.
      c.peg = n.peg;
      c.swings = n.swings;
      c.swung = true;
      c.path = n.path;
      c.path.push_back(c.X_GO);
      contact_.push_back(std::move(c));
      turned = true;
    }
    // No turn found either way (blocked, or the object turns off the area): the tree ends here,
    // not stable, statically supported or not as its last test said.
    if (!turned)
      leaves.push_back(TreeLeaf{n.X_GO, n.root, false, true, n.supported, n.quality, n.tipping_angle, n.contacts, n.path});
  }
  rotating_.clear();
}

// ---------------------------------------------------------------- roll settle (beyond the paper)
// An object lying on a line of contacts with its centre of mass above them rolls about the line
// until its centre of mass is lowest. Each pose is rolled about the horizontal line through its
// centre of mass by -kRollSteps .. kRollSteps coarse steps and dropped to first contact (the
// exact translation of V-A, batched); it goes downhill to the bottom of its own valley. At the
// end of the range it rolls on from there; inside it, the bottom is refined to kRollFine (a
// second batch), and its margin (its tipping angle) is the roll to the nearer crest, zero when
// a crest rises less than kMinRollRise (a round rod has no bottom). Its time counts as the
// distance step's.
namespace {

struct Crest {
  double angle, rise;
  bool at_end;  // still rising where the range ends
};

}  // namespace

void TreeStepper::rollStep() {
  const auto t0 = Clock::now();
  constexpr int kN = 2 * kRollSteps + 1;
  const double R = ctx_.om.bounding_radius;
  const double gap = 0.5 * ctx_.cd;
  std::vector<Eigen::Vector3d> axes(rolling_.size()), coms(rolling_.size());
  for (size_t i = 0; i < rolling_.size(); ++i) {
    Eigen::Vector3d d = rolling_[i].d_A;
    d.z() = 0;
    axes[i] = d.normalized();
    coms[i] = toEigen(apply(rolling_[i].X_GO, rolling_[i].com_O));
  }
  // Rolled by `a` about the line through the centre of mass, lifted clear, to be dropped; the
  // centre of mass's height after the drop, relative to now.
  auto query = [&](size_t i, double a) { return rolledProbe(rolling_[i].X_GO, coms[i], axes[i], a, R, gap); };
  auto height = [&](const TranslationQuery& q, double t) { return probeRise(q, t, gap); };
  std::vector<TranslationQuery> q;
  q.reserve(rolling_.size() * kN);
  for (size_t i = 0; i < rolling_.size(); ++i)
    for (int k = -kRollSteps; k <= kRollSteps; ++k) q.push_back(query(i, k * kRollStep));
  // The coarse rolls are dropped in two rounds: those within kRollNear steps first, the rest
  // only for the poses whose walk or crests reach past them (most bottoms and crests are near).
  // The decisions read the same heights either way: the result is that of one full round.
  std::vector<double> t(q.size(), kInf);
  std::vector<char> known(q.size(), 0);
  auto drop = [&](const std::vector<size_t>& which) {
    std::vector<TranslationQuery> sub;
    sub.reserve(which.size());
    for (size_t k : which) sub.push_back(q[k]);
    std::vector<double> ts;
    ctx_.backend.distance(sub, ts);
    for (size_t j = 0; j < which.size(); ++j) t[which[j]] = ts[j], known[which[j]] = 1;
  };
  {
    std::vector<size_t> near;
    for (size_t i = 0; i < rolling_.size(); ++i)
      for (int j = kRollSteps - kRollNear; j <= kRollSteps + kRollNear; ++j) near.push_back(i * kN + j);
    drop(near);
  }

  std::vector<int> bottom(rolling_.size(), -1);  // coarse bottom of the bracketed ones
  std::vector<char> keep(rolling_.size(), 0);     // 0: nothing below any roll (falls off)
  // Pose i's bottom and margin; false (nothing changed) when a height it needs is not known yet.
  auto decide = [&](size_t i) {
    TreeNode& n = rolling_[i];
    bool unknown = false;
    double hv[kN];
    for (int j = 0; j < kN; ++j) hv[j] = height(q[i * kN + j], t[i * kN + j]);
    struct Heights {  // every height the decisions read, noting one not dropped yet
      const double* v;
      const char* k;
      bool* unknown;
      double operator[](int j) const {
        if (!k[j]) *unknown = true;
        return v[j];
      }
    } h{hv, &known[i * kN], &unknown};
    // Downhill from where it lies (a crest lower than kMinRollRise does not hold a release: it
    // rolls over into the next valley): the bottom of its own valley, not the lowest of the range.
    int best = kRollSteps;
    for (bool moved = true; moved;) {
      moved = false;
      for (int dir : {1, -1}) {
        for (int j = best + dir; j >= 0 && j < kN && h[j] < h[best] + kMinRollRise; j += dir)
          if (h[j] < h[best] - 1e-9) {
            best = j;
            moved = true;
            break;
          }
        if (moved) break;
      }
    }
    if (unknown) return false;
    if (h[best] >= kInf) return true;  // nothing below: it falls off the area
    // Each way: the crest, the highest rise before the roll descends by more than kMinRollRise
    // or below the bottom (lower crests are dents it passes over), and the roll to it.
    auto crest = [&](int dir) {
      int top = best;
      for (int j = best + dir; j >= 0 && j < kN; j += dir) {
        if (h[j] >= h[top]) top = j;
        if (h[j] < h[top] - kMinRollRise || h[j] < h[best] - kRollBump)
          return Crest{std::abs(top - best) * kRollStep, h[top] - h[best], false};
      }
      return Crest{std::abs(top - best) * kRollStep, h[top] - h[best], true};
    };
    const Crest cp = crest(1), cm = crest(-1);
    if (unknown) return false;
    keep[i] = 1;
    // Not bracketed (the lowest roll at the end of the range, or a side still rising but less
    // than kMinRollRise where the range ends): roll on from the lowest pose, the range centred
    // on it. Centred already, the range is what is known.
    const bool short_side = (cp.at_end && cp.rise < kMinRollRise) || (cm.at_end && cm.rise < kMinRollRise);
    const bool at_end = best == 0 || best == kN - 1;
    n.turns += 1;  // rolls count against the hard cap only, like small turns
    if (at_end || (short_side && best != kRollSteps)) {
      n.roll = 0;
      n.X_GO = translated(q[i * kN + best].X_GO, v3(0, 0, -t[i * kN + best]));
    } else {
      const double holding_rise = std::max(kMinRollRise, ctx_.shape_uncertainty);
      auto margin = [&](const Crest& c) { return c.rise < holding_rise ? 0.0 : c.angle; };
      n.roll = 1;
      n.roll_margin = std::min(margin(cp), margin(cm));
      bottom[i] = best;
    }
    return true;
  };
  std::vector<size_t> later, far;
  for (size_t i = 0; i < rolling_.size(); ++i)
    if (!decide(i)) later.push_back(i);
  for (size_t i : later)
    for (int j = 0; j < kN; ++j)
      if (!known[i * kN + j]) far.push_back(i * kN + j);
  if (!far.empty()) drop(far);
  for (size_t i : later) decide(i);
  // The bracketed bottoms refined: the fine rolls within a coarse step either side.
  std::vector<TranslationQuery> fq;
  std::vector<size_t> fi;
  for (size_t i = 0; i < rolling_.size(); ++i) {
    if (bottom[i] < 0) continue;
    const double a0 = (bottom[i] - kRollSteps) * kRollStep;
    for (int k = -kRollFine; k <= kRollFine; ++k) {
      fq.push_back(query(i, a0 + k * kRollStep / (kRollFine + 1)));
      fi.push_back(i);
    }
  }
  // The middle fine roll is the coarse bottom, dropped already.
  constexpr int kF = 2 * kRollFine + 1;
  std::vector<TranslationQuery> send;
  for (size_t f = 0; f < fq.size(); ++f)
    if (f % kF != kRollFine) send.push_back(fq[f]);
  std::vector<double> st, ft(fq.size());
  if (!send.empty()) ctx_.backend.distance(send, st);
  for (size_t f = 0, j = 0; f < fq.size(); ++f)
    ft[f] = f % kF == kRollFine ? t[fi[f] * kN + bottom[fi[f]]] : st[j++];
  for (size_t i = 0, f = 0; i < rolling_.size(); ++i) {
    if (bottom[i] < 0) continue;
    int best = kRollFine;  // the coarse bottom itself
    for (int k = 0; k < kF; ++k)
      if (height(fq[f + k], ft[f + k]) < height(fq[f + best], ft[f + best]) - 1e-9) best = k;
    rolling_[i].X_GO = translated(fq[f + best].X_GO, v3(0, 0, -ft[f + best]));
    f += kF;
  }
  for (size_t i = 0; i < rolling_.size(); ++i) {
    TreeNode& n = rolling_[i];
    if (!keep[i]) continue;
    n.path.push_back(n.X_GO);
    if (kTrace)
      std::fprintf(stderr, "root %d rolled, bottom %d margin %.1f deg\n", n.root, n.roll, n.roll_margin * 180 / M_PI);
    contact_.push_back(std::move(n));
  }
  rolling_.clear();
  addTime(ctx_.times ? &ctx_.times->first_contact : nullptr, t0);
}

// ---------------------------------------------------------------- rock settle (beyond the paper)
// A pose the static test holds need not be at rest: its contacts are those within the contact
// tolerance, so a pose released a few degrees off on a curved or domed support (peg tops, a
// dish's underside, a rounded lip) is held where it landed, propped on contacts a millimetre
// away. At rest, the centre of mass is at a local minimum of its height over small rolls: the
// pose is rocked by kRockStep about the two horizontal axes of G through its centre of mass,
// both ways, and each rock is dropped to first contact (V-A, batched), beside the unrocked pose
// dropped the same way. When a rock lowers the centre of mass by more than kRockDrop the object
// moves there and is tested again (a turn against the hard cap only); otherwise it is the
// stable leaf. Its time counts as the distance step's.
void TreeStepper::rockStep(std::vector<TreeLeaf>& leaves) {
  const auto t0 = Clock::now();
  const double R = ctx_.om.bounding_radius;
  const double gap = 0.5 * ctx_.cd;
  constexpr int kProbes = 5;  // unrocked, then +-x, +-y
  const Eigen::Vector3d axes[kProbes] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(),
                                         Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitY()};
  std::vector<TranslationQuery> q;
  q.reserve(rocking_.size() * kProbes);
  for (const TreeNode& n : rocking_) {
    const Eigen::Vector3d com = toEigen(apply(n.X_GO, n.com_O));
    for (int k = 0; k < kProbes; ++k) q.push_back(rolledProbe(n.X_GO, com, axes[k], k == 0 ? 0.0 : kRockStep, R, gap));
  }
  std::vector<double> t;
  ctx_.backend.distance(q, t);
  for (size_t i = 0; i < rocking_.size(); ++i) {
    TreeNode& n = rocking_[i];
    double h[kProbes];  // the centre of mass's height after each drop
    for (int k = 0; k < kProbes; ++k) h[k] = probeRise(q[i * kProbes + k], t[i * kProbes + k], gap);
    int best = 0;
    for (int k = 1; k < kProbes; ++k)
      if (h[k] < h[best]) best = k;
    if (h[0] >= kInf || best == 0 || h[best] > h[0] - kRockDrop) {
      if (kTrace) {
        double rise = kInf;
        for (int k = 1; k < kProbes; ++k) rise = std::min(rise, h[k] - h[0]);
        std::fprintf(stderr, "root %d at rest (rock %.1f um) rise %.1f um\n", n.root, (h[best] - h[0]) * 1e6, rise * 1e6);
      }
      // Rocked down between steep contacts facing each other, it hangs in a V of edges.
      const bool wedged = n.rocks > 0 && hangsBetweenEdges(n.contacts);
      leaves.push_back(TreeLeaf{n.X_GO, n.root, n.held && !wedged, true, n.supported && !wedged, n.quality, n.tipping_angle, n.contacts, n.path});
      leaves.back().hanging = n.hanging;
      continue;
    }
    if (kTrace) std::fprintf(stderr, "root %d rocks %d by %.1f um\n", n.root, best, (h[0] - h[best]) * 1e6);
    n.X_GO = translated(q[i * kProbes + best].X_GO, v3(0, 0, -t[i * kProbes + best]));
    n.path.push_back(n.X_GO);
    ++n.rocks;
    ++n.turns;
    contact_.push_back(std::move(n));
  }
  rocking_.clear();
  addTime(ctx_.times ? &ctx_.times->first_contact : nullptr, t0);
}

}  // namespace place_planner
