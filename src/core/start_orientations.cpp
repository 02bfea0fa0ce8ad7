// Start orientations (start_orientations.h): resting faces, held, principal axis, area turns.
#include "place_planner/start_orientations.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>

#include "place_planner/pre_orientation.h"
#include "place_planner/resting_faces.h"

namespace place_planner {
namespace {

// Resting facets must hold against a tilt well beyond the release tilt.
constexpr double kMinRestingTipDeg = 10.0;
constexpr double kDistinctDeg = 8.0;

double angleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

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

}  // namespace

std::optional<double> areaWallDirection(const AreaModel& area) {
  constexpr int kBins = 18;  // 5 degrees each over [0, 90)
  double hist[kBins] = {0}, total = 0, all = 0;
  for (size_t t = 0; t < area.triangles.size(); ++t) {
    const auto& tri = area.triangles[t];
    const V3 a = area.vertices[tri[0]], b = area.vertices[tri[1]], c = area.vertices[tri[2]];
    const double A = 0.5 * norm(cross(b - a, c - a));
    all += A;
    const V3 n = area.triangle_normals[t];
    if (std::abs(n.z) > 0.3) continue;
    double phi = std::fmod(std::atan2(n.y, n.x) + 4 * M_PI, M_PI / 2);
    hist[std::min(kBins - 1, static_cast<int>(phi / (M_PI / 2) * kBins))] += A;
    total += A;
  }
  if (total < 0.02 * all || total <= 0) return std::nullopt;
  int best = 0;
  for (int i = 1; i < kBins; ++i)
    if (hist[i] + hist[(i + 1) % kBins] > hist[best] + hist[(best + 1) % kBins]) best = i;
  if (hist[best] + hist[(best + 1) % kBins] < total / 3) return std::nullopt;
  return (best + 1) * (M_PI / 2) / kBins;  // the edge between the two bins
}

std::vector<StartOrientation> startOrientations(const Mesh& object, const Eigen::Matrix3d& R_held_G,
                                                const Eigen::Vector3d& d_vis_G,
                                                const AreaModel& area, const PlannerConfig& config) {
  std::vector<StartOrientation> out;
  auto add = [&](const Eigen::Matrix3d& R, StartKind kind) {
    for (const auto& s : out)
      if (angleBetween(s.R_GO, R) < kDistinctDeg * M_PI / 180.0) return;
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
  for (const RestingFace& f : restingFaces(object, min_tip)) {
    if (static_cast<int>(resting.size()) >= config.max_resting_faces) break;
    const Eigen::Vector3d n_G = R_held_G * f.normal_O;
    resting.push_back(Eigen::Quaterniond::FromTwoVectors(n_G, d_vis_G.normalized()).toRotationMatrix() * R_held_G);
  }
  for (const auto& R : resting) add(R, StartKind::kRestingFace);
  add(R_held_G, StartKind::kHeld);
  const auto pa = preOrientations(object.properties, R_held_G, d_vis_G, OrientationMode::kPrincipalAxis);
  add(pa.front(), StartKind::kPrincipalAxis);
  // Turns about d_vis toward the area's walls: for the best resting face and the principal axis.
  if (const auto wall = areaWallDirection(area)) {
    std::vector<Eigen::Matrix3d> bases;
    if (!resting.empty()) bases.push_back(resting.front());
    bases.push_back(pa.front());
    for (const auto& R : bases) {
      const auto [phi, ratio] = horizontalAxis(object, R);
      if (ratio < 1.3) continue;  // round in plan view: a turn changes nothing
      for (double target : {*wall, *wall + M_PI / 2}) {
        const Eigen::Matrix3d turn = Eigen::AngleAxisd(target - phi, -d_vis_G.normalized()).toRotationMatrix();
        add(turn * R, StartKind::kAreaTurn);
      }
    }
  }
  return out;
}

}  // namespace place_planner
