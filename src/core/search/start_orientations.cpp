// Start orientations (start_orientations.h): resting faces, held, principal axis, area turns.
#include "place_planner/search/start_orientations.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "place_planner/search/pre_orientation.h"
#include "place_planner/search/resting_faces.h"

namespace place_planner {
namespace {

// Resting facets must hold against a tilt well beyond the release tilt.
constexpr double kMinRestingTipDeg = 10.0;
constexpr double kDistinctDeg = 8.0;
// Up-facing surface tilted less than this is level: a round object does not roll off it.
constexpr double kLevelDeg = 2.0;

// Angle about z of the object's longest horizontal extent (2D principal axis of its vertices
// in G) and its elongation (ratio of the two spreads).
std::pair<double, double> horizontalAxis(const Mesh& object, const Eigen::Matrix3d& R) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& v : object.vertices) mean += (R * v).head<2>();
  mean /= std::max<size_t>(1, object.vertices.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& v : object.vertices) {
    const Eigen::Vector2d d = (R * v).head<2>() - mean;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  const Eigen::Vector2d a = es.eigenvectors().col(1);
  const double ratio = std::sqrt(std::max(es.eigenvalues()(1), 0.0) / std::max(es.eigenvalues()(0), 1e-18));
  return {std::atan2(a.y(), a.x()), ratio};
}

// The smallest rotation taking unit a onto unit b; for opposite vectors (a face up that must
// face down) a half turn about the horizontal axis `about` defines, so that the answer does
// not depend on the frame the object was given in.
Eigen::Matrix3d minimalTurn(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& about) {
  if (a.dot(b) > -1 + 1e-9) return Eigen::Quaterniond::FromTwoVectors(a, b).toRotationMatrix();
  Eigen::Vector3d axis = about - about.dot(a) * a;
  if (axis.norm() < 1e-6) axis = a.unitOrthogonal();
  return Eigen::AngleAxisd(M_PI, axis.normalized()).toRotationMatrix();
}

// The dominant direction about gravity, modulo 90 degrees, of the horizontal part of the normals
// of the area's triangles that `counts` selects, each weighted by its area times that part's
// length; empty when they cover under 2 % of the area or no direction holds a third of them.
template <typename Counts>
std::optional<double> dominantDirection(const AreaModel& area, Counts counts) {
  // Directions modulo 90 degrees as angles 4 phi on a circle, so 89.9 and 0.1 degrees agree.
  constexpr int kBins = 18;  // 5 degrees each over [0, 90)
  double hist[kBins] = {0}, total = 0, all = 0, covered = 0;
  std::vector<std::pair<double, double>> dirs;  // (4 phi, weight)
  for (size_t t = 0; t < area.triangles.size(); ++t) {
    const auto& tri = area.triangles[t];
    const V3 a = area.vertices[tri[0]], b = area.vertices[tri[1]], c = area.vertices[tri[2]];
    const double A = 0.5 * norm(cross(b - a, c - a));
    all += A;
    const V3 n = area.triangle_normals[t];
    if (!counts(n)) continue;
    const double w = A * std::hypot(n.x, n.y);
    const double phi4 = std::fmod(4 * std::atan2(n.y, n.x) + 16 * M_PI, 2 * M_PI);
    hist[std::min(kBins - 1, static_cast<int>(phi4 / (2 * M_PI) * kBins))] += w;
    dirs.emplace_back(phi4, w);
    total += w;
    covered += A;
  }
  if (covered < 0.02 * all || total <= 0) return std::nullopt;
  int best = 0;
  for (int i = 1; i < kBins; ++i)
    if (hist[i] + hist[(i + 1) % kBins] > hist[best] + hist[(best + 1) % kBins]) best = i;
  if (hist[best] + hist[(best + 1) % kBins] < total / 3) return std::nullopt;
  // The peak's direction: the circular mean of the directions within 10 degrees (of phi) of it.
  const double centre = (best + 1) * (2 * M_PI / kBins);
  double sx = 0, sy = 0;
  for (const auto& [phi4, w] : dirs)
    if (std::cos(phi4 - centre) > std::cos(4 * 10 * M_PI / 180)) {
      sx += w * std::cos(phi4);
      sy += w * std::sin(phi4);
    }
  return std::fmod(std::atan2(sy, sx) + 2 * M_PI, 2 * M_PI) / 4;
}

}  // namespace

std::optional<double> areaWallDirection(const AreaModel& area) {
  return dominantDirection(area, [](const V3& n) { return std::abs(n.z) <= 0.3; });
}

std::optional<double> areaSlopeDirection(const AreaModel& area) {
  const double level = std::cos(kLevelDeg * M_PI / 180);
  // |n.z|: a scan's faces may be wound either way (the direction is modulo 90 degrees anyway).
  return dominantDirection(area, [level](const V3& n) { return std::abs(n.z) > 0.3 && std::abs(n.z) < level; });
}

std::vector<StartOrientation> startOrientations(const Mesh& object, const Eigen::Matrix3d& R_held_G,
                                                const Eigen::Vector3d& d_vis_G,
                                                const AreaModel& area, const PlannerConfig& config,
                                                const StopSignal* stop) {
  std::vector<StartOrientation> out;
  auto add = [&](const Eigen::Matrix3d& R, StartKind kind) {
    for (const auto& s : out)
      if (rotationAngle(s.R_GO, R) < kDistinctDeg * M_PI / 180.0) return;
    out.push_back({R, kind});
  };
  if (config.orientation != OrientationMode::kAuto) {
    const StartKind kind = config.orientation == OrientationMode::kKeep ? StartKind::kHeld
                           : config.orientation == OrientationMode::kPrincipalAxis ? StartKind::kPrincipalAxis
                                                                                   : StartKind::kAxis;
    for (const auto& R : preOrientations(object.properties, R_held_G, d_vis_G, config.orientation))
      out.push_back({R, kind});
    return out;
  }
  // Resting faces (best margin first): the facet's outward normal along d_vis, by the smallest
  // turn from the held orientation (the least re-orientation of the held object).
  const double min_tip = std::max(kMinRestingTipDeg, config.min_tipping_angle_deg) * M_PI / 180.0;
  std::vector<Eigen::Matrix3d> resting;
  // Best margin first; faces as good as each other (within 0.1 degrees: a box's opposite
  // faces) in order of the turn they need from the held orientation.
  std::vector<RestingFace> faces = restingFaces(object, min_tip, 4.0, stop);
  auto turn = [&](const RestingFace& f) { return std::acos(std::clamp((R_held_G * f.normal_O).dot(d_vis_G.normalized()), -1.0, 1.0)); };
  std::stable_sort(faces.begin(), faces.end(), [&](const RestingFace& a, const RestingFace& b) {
    const long ta = std::lround(a.tipping_angle / 1.7e-3), tb = std::lround(b.tipping_angle / 1.7e-3);
    if (ta != tb) return ta > tb;
    return turn(a) < turn(b);
  });
  for (const RestingFace& f : faces) {
    if (static_cast<int>(resting.size()) >= config.max_resting_faces) break;
    const Eigen::Vector3d n_G = R_held_G * f.normal_O;
    // Opposite faces flip about the object's k1 (k2 when k1 is the face normal), held.
    const Eigen::Vector3d k = std::abs(f.normal_O.dot(object.properties.k1())) < 0.9 ? object.properties.k1()
                                                                                     : Eigen::Vector3d(object.properties.principal_axes.col(1));
    resting.push_back(minimalTurn(n_G, d_vis_G.normalized(), R_held_G * k) * R_held_G);
  }
  for (const auto& R : resting) add(R, StartKind::kRestingFace);
  add(R_held_G, StartKind::kHeld);
  const auto pa = preOrientations(object.properties, R_held_G, d_vis_G, OrientationMode::kPrincipalAxis);
  add(pa.front(), StartKind::kPrincipalAxis);
  // Turns about d_vis toward the area's walls (slots, dividers) and along and across its
  // slopes' fall lines (a long round object lies along a ramp, not across it, where it rolls):
  // for the best resting face and the principal axis.
  std::vector<Eigen::Matrix3d> bases;
  if (!resting.empty()) bases.push_back(resting.front());
  bases.push_back(pa.front());
  for (const auto& dir : {areaWallDirection(area), areaSlopeDirection(area)}) {
    if (!dir) continue;
    for (const auto& R : bases) {
      const auto [phi, ratio] = horizontalAxis(object, R);
      if (ratio < 1.3) continue;  // round in plan view: a turn changes nothing
      for (double target : {*dir, *dir + M_PI / 2}) {
        const Eigen::Matrix3d turn = Eigen::AngleAxisd(target - phi, -d_vis_G.normalized()).toRotationMatrix();
        add(turn * R, StartKind::kAreaTurn);
      }
    }
  }
  return out;
}

}  // namespace place_planner
