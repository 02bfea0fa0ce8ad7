// Pegs of the area (pegs.h): probes from the tops of thin parts, by rays through the area's
// triangle BVH. Frame G.
#include "place_planner/search/pegs.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "place_planner/model/bvh.h"

namespace place_planner {
namespace {

// Distance along d from o to the area's surface (either side), `reach` when nothing is nearer.
double ray(const AreaModel& am, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double reach) {
  const V3 O = toV3(o), D = toV3(d);
  return bvhRay(view(am.triangle_bvh), O, D, reach, [&](int i) {
    const auto& f = am.triangles[i];
    return rayTriangle(O, D, am.vertices[f[0]], am.vertices[f[1]], am.vertices[f[2]]);
  });
}

// Inside a thin part at c: its length through c along d (both ways) and the part ahead of c.
struct Span {
  double ahead, behind;
  double total() const { return ahead + behind; }
};
Span span(const AreaModel& am, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  constexpr double kReach = 1.0;
  return {ray(am, c, d, kReach), ray(am, c, -d, kReach)};
}

// A cheap necessary condition from the height grid (Section V-B's, each cell's area spheres
// highest first): no sphere lies between the band of the thin part under the top (max_thickness
// deep) and min_free_below under that band. Books, boards and floors fail it without a ray.
bool roomBelowInGrid(const AreaModel& am, const Eigen::Vector3d& top, const PegParams& p) {
  const HeightGrid& g = am.grid;
  const int ix = static_cast<int>(std::floor((top.x() - g.x0) / g.cell));
  const int iy = static_cast<int>(std::floor((top.y() - g.y0) / g.cell));
  if (ix < 0 || iy < 0 || ix >= g.nx || iy >= g.ny) return true;
  const int cell = iy * g.nx + ix;
  const double band = top.z() - p.max_thickness - am.spheres.radius;
  for (int k = g.start[cell]; k < g.start[cell + 1]; ++k) {
    const double z = am.spheres.centres[g.items[k]].z;
    if (z >= band) continue;
    return z < band - p.min_free_below;  // the highest sphere under the band
  }
  return true;
}

// How far a peg's end reaches past the first surface its axis meets at `tip` (a ball knob on
// its end, or an end face left inside a knob where a mesh's parts overlap): each next surface
// within max_thickness ahead counts while the space before it is a knob's inside (rays across
// the axis from its middle all meet the area within a knob's radius, 3 half widths of the peg
// and 2 mm). A gap in the open (a wall just beyond the tip) is not enclosed, and a post the peg
// runs into is longer than a knob: the peg ends there, not free.
double knobBeyond(const AreaModel& am, Eigen::Vector3d tip, const Eigen::Vector3d& a, const Eigen::Vector3d& side,
                  double half, double max_thickness) {
  constexpr double kStep = 2e-4;
  const Eigen::Vector3d up = a.cross(side).normalized();
  const double knob = 3 * half + 0.002;
  double beyond = 0;
  while (beyond < max_thickness) {
    const double s = ray(am, tip, a, max_thickness - beyond);
    if (s >= max_thickness - beyond) break;
    const Eigen::Vector3d mid = tip + 0.5 * s * a;
    for (const Eigen::Vector3d& d : {side, Eigen::Vector3d(-side), up, Eigen::Vector3d(-up)})
      if (ray(am, mid, d, knob) >= knob) return beyond;
    beyond += s + kStep;
    tip += (s + kStep) * a;
  }
  return beyond;
}

}  // namespace

std::vector<Peg> findPegs(const AreaModel& am, const PegParams& p, const StopSignal* stop) {
  // Up-facing triangles narrow enough to lie on a peg's top: each one's smallest altitude is at
  // most the peg's width (a table's, a board's, a book's big triangles are not probed).
  std::vector<int> tops;
  for (size_t i = 0; i < am.triangles.size(); ++i) {
    if (std::abs(am.triangle_normals[i].z) <= 0.5) continue;
    const auto& f = am.triangles[i];
    const V3 a = am.vertices[f[0]], b = am.vertices[f[1]], c = am.vertices[f[2]];
    const double twice_area = norm(cross(b - a, c - a));
    const double longest = std::max({norm(b - a), norm(c - b), norm(a - c)});
    if (longest > 0 && twice_area / longest <= p.max_thickness) tops.push_back(static_cast<int>(i));
  }
  const size_t stride = std::max<size_t>(1, (tops.size() + p.max_samples - 1) / p.max_samples);
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  constexpr double kEps = 1e-4;
  std::vector<Peg> found;
  for (size_t s = 0; s < tops.size(); s += stride) {
    pollStop(stop, s / stride, 256);
    const auto& f = am.triangles[tops[s]];
    const Eigen::Vector3d top = toEigen((1.0 / 3) * (am.vertices[f[0]] + am.vertices[f[1]] + am.vertices[f[2]]));
    // A top with room above it, a thin part under it, and room below that.
    if (!roomBelowInGrid(am, top, p)) continue;
    if (ray(am, top + kEps * up, up, p.min_free_above) < p.min_free_above) continue;
    const double t = ray(am, top - kEps * up, -up, p.max_thickness);
    if (t >= p.max_thickness || t < 1e-3) continue;
    if (ray(am, top - (t + 2 * kEps) * up, -up, p.min_free_below) < p.min_free_below) continue;
    Eigen::Vector3d c = top - (kEps + 0.5 * t) * up;
    // The axis: the horizontal direction the part is longest in, then its slope in that plane.
    // Every 30 degrees first: one of those is within 15 degrees of across a peg, where its span
    // is under 1.04 times its width; a slab (a book overhanging the one below) is wide every way.
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
    double longest = 0, narrowest = kInf;
    for (const int k : {0, 2, 4, 6, 8, 10, 1, 3, 5, 7, 9, 11}) {
      if (k == 1 && narrowest > 1.04 * p.max_thickness) break;
      const double a = M_PI * k / 12;
      const Eigen::Vector3d d(std::cos(a), std::sin(a), 0);
      const double len = span(am, c, d).total();
      narrowest = std::min(narrowest, len);
      if (len > longest) longest = len, axis = d;
    }
    if (narrowest > 1.04 * p.max_thickness) continue;
    const Eigen::Vector3d side = up.cross(axis).normalized();
    Span across = span(am, c, side);
    const double width = across.total();
    if (width > p.max_thickness) continue;  // a board, a table top: wide
    // Onto the axis across the peg: a faceted peg's top triangle lies off to one side, and
    // samples off it by different amounts along the peg would skew the axis fitted through them
    // (below), whose span then leaves the peg through its side long before its tip.
    c += 0.5 * (across.ahead - across.behind) * side;
    across.ahead = across.behind = 0.5 * width;
    // Free all round: beside it at its middle (room for a loop's side), and below it beside its
    // bottom on both sides (the rim of a wall, a cover's edge, a scan's crease have more of the
    // area right below one side).
    bool free_round = t >= p.min_thickness;
    for (const double s : {1.0, -1.0}) {
      if (!free_round) break;
      const double out = (s > 0 ? across.ahead : across.behind) + 2 * kEps;
      free_round = ray(am, c + out * s * side, s * side, p.min_free_side) >= p.min_free_side &&
                   ray(am, c + (out + 0.002) * s * side - 0.5 * t * up, -up, p.min_free_below) >= p.min_free_below;
    }
    if (!free_round) continue;
    // Its slope in 10 degree steps at every 30 degrees of azimuth (a steep arm's horizontal
    // spans are all short, and the longest of them need not lie along it), then azimuth and
    // slope in 2.5 degree steps about the best: off the axis by d, a ray leaves a peg of half
    // width w through its side after w / sin d.
    double azimuth = std::atan2(axis.y(), axis.x());
    auto direction = [&](double az, double el) {
      return Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    };
    double slope = 0;
    const int slopes = static_cast<int>(p.max_slope_deg / 10);
    for (int i = 0; i < 12; ++i)
      for (int k = -slopes; k <= slopes; ++k) {
        if (k == 0) continue;  // the horizontal ones are measured
        const double az = M_PI * i / 12;  // a span runs both ways: half a turn covers them
        const double len = span(am, c, direction(az, k * 10.0 * M_PI / 180)).total();
        if (len > longest + 1e-6) longest = len, slope = k * 10.0 * M_PI / 180, azimuth = az;
      }
    double best_az = azimuth, best_el = slope;
    const double fine = 2.5 * M_PI / 180;
    for (int i = -4; i <= 4; ++i)
      for (int j = -4; j <= 4; ++j) {
        const double el = slope + j * fine;
        if (std::abs(el) > p.max_slope_deg * M_PI / 180 + 1e-9) continue;
        const double len = span(am, c, direction(azimuth + i * fine, el)).total();
        if (len > longest + 1e-6) longest = len, best_az = azimuth + i * fine, best_el = el;
      }
    axis = direction(best_az, best_el);
    // A top lies along the peg's side: an end face (a cap of an arm rising past 30 degrees faces
    // up enough to be probed) is not one, and its samples would make a peg pointing back.
    if (std::abs(toEigen(am.triangle_normals[tops[s]]).dot(axis)) > 0.5) continue;
    const double half = 0.5 * std::max(t, width);
    if (longest < 5.0 * half) continue;  // a knob, not a peg
    // As thin a third of the way from either end (a corner of a board is thin near its tip only).
    const Span sp = span(am, c, axis);
    bool thin_along = true;
    for (const double f : {1.0 / 3, 2.0 / 3}) {
      const Eigen::Vector3d q = c + (f * sp.total() - sp.behind) * axis;
      thin_along = thin_along && span(am, q, side).total() <= p.max_thickness && span(am, q, up).total() <= p.max_thickness;
    }
    if (!thin_along) continue;
    // Its free end: beyond it nothing along the axis for min_tip_free.
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d a = sign * axis;
      double to_tip = sign > 0 ? sp.ahead : sp.behind;
      const double to_base = sign > 0 ? sp.behind : sp.ahead;
      to_tip += knobBeyond(am, c + (to_tip + 2 * kEps) * a, a, side, half, p.max_thickness);
      const Eigen::Vector3d tip = c + (to_tip + 2 * kEps) * a;
      // Free at both ends (a loose bar; a cup hook's arm, whose stem beyond one end is as thin
      // as it): both, and the threading sweep finds which end a loop gets on by.
      if (ray(am, tip, a, p.min_tip_free) < p.min_tip_free) continue;
      found.push_back(Peg{c, a, half, to_tip, to_base});
    }
  }
  // One per peg: samples on one axis line (within a peg's thickness) with axes within 20
  // degrees are one peg; the sample nearest its middle stands for it.
  // The axis of a peg sampled at points a few centimetres apart is their line (the rays' longest
  // span leans off the axis towards the corners of its end faces).
  std::vector<Peg> pegs;
  std::vector<char> used(found.size(), 0);
  for (size_t i = 0; i < found.size(); ++i) {
    if (used[i]) continue;
    Peg best = found[i];
    std::vector<Eigen::Vector3d> on_axis;
    auto middle = [](const Peg& g) { return std::min(g.to_tip, g.to_base); };
    for (size_t j = i; j < found.size(); ++j) {
      const Peg& g = found[j];
      const Eigen::Vector3d off = g.point - found[i].point;
      if (used[j] || (off - off.dot(found[i].axis) * found[i].axis).norm() > 2 * std::max(found[i].half_width, g.half_width) + 0.002 ||
          found[i].axis.dot(g.axis) < std::cos(20 * M_PI / 180))
        continue;
      used[j] = 1;
      on_axis.push_back(g.point);
      if (middle(g) > middle(best) + 1e-9) best = g;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& q : on_axis) mean += q;
    mean /= on_axis.size();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& q : on_axis) cov += (q - mean) * (q - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    Eigen::Vector3d fitted = eig.eigenvectors().col(2);
    const double spread = std::sqrt(std::max(0.0, eig.eigenvalues()(2) / on_axis.size()));
    if (spread > 2 * best.half_width && std::abs(fitted.dot(best.axis)) > std::cos(20 * M_PI / 180)) {
      if (fitted.dot(best.axis) < 0) fitted = -fitted;
      const Span sp = span(am, best.point, fitted);
      const Eigen::Vector3d side = Eigen::Vector3d::UnitZ().cross(fitted).normalized();
      best.axis = fitted;
      best.to_tip = sp.ahead + knobBeyond(am, best.point + (sp.ahead + 2 * kEps) * fitted, fitted, side,
                                          best.half_width, p.max_thickness);
      best.to_base = sp.behind;
    }
    pegs.push_back(best);
  }
  return pegs;
}

}  // namespace place_planner
