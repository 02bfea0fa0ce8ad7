// The release pose levelled on its support (level_release.h).
#include "place_planner/manipulation/level_release.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace place_planner {
namespace {

struct Plane {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// Weighted least-squares plane of points (the smallest principal direction of their spread).
Plane fitPlane(const std::vector<Eigen::Vector3d>& p, const std::vector<double>& w) {
  Plane f;
  double total = 0;
  for (size_t i = 0; i < p.size(); ++i) f.centroid += w[i] * p[i], total += w[i];
  f.centroid /= total;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < p.size(); ++i) cov += w[i] * (p[i] - f.centroid) * (p[i] - f.centroid).transpose();
  f.normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  return f;
}

// Under each of up to 16 of the face's samples (projected along P's normal) where the area's
// scan has a triangle facing along P within 60 degrees, one whose corners lie within `tol` of P
// (at a scan's edge its noise tilts small triangles by 30 degrees and more); at least three in
// four samples so. A sample over no such triangle lies past what the scan saw, or over a wall or
// an edge's side, which nothing rests on (a held-out bottle stood at a table scan's ragged front
// edge: left 2.2 degrees off level, Bullet spun it 15 degrees); one over a triangle that faces up
// but is not P (a rack's floor between peg tops, a step) rules the plane out.
bool flatUnder(const MeshModel& area, const std::vector<Eigen::Vector3d>& samples, const Plane& P, double tol) {
  const double kSteep = std::cos(60.0 * M_PI / 180.0);
  const Eigen::Vector3d u = P.normal.unitOrthogonal(), w = P.normal.cross(u);
  auto in2d = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d((p - P.centroid).dot(u), (p - P.centroid).dot(w)); };
  auto side = [](const Eigen::Vector2d& p, const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
    return (y - x).x() * (p - x).y() - (y - x).y() * (p - x).x();
  };
  const size_t step = std::max<size_t>(1, samples.size() / 16);
  int on_plane = 0, sampled = 0;
  for (size_t s = 0; s < samples.size(); s += step) {
    ++sampled;
    const Eigen::Vector2d q = in2d(samples[s]);
    bool seen = false, under = false;
    for (size_t t = 0; t < area.triangles.size() && !under; ++t) {
      const auto& tri = area.triangles[t];
      const Eigen::Vector3d a = toEigen(area.vertices[tri[0]]), b = toEigen(area.vertices[tri[1]]),
                            c = toEigen(area.vertices[tri[2]]);
      const double along = std::abs(toEigen(area.triangle_normals[t]).dot(P.normal));
      if (along < kSteep) continue;  // a wall or an edge's side: nothing rests on it
      const Eigen::Vector2d A = in2d(a), B = in2d(b), C = in2d(c);
      const double d0 = side(q, A, B), d1 = side(q, B, C), d2 = side(q, C, A);
      if (!((d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0))) continue;
      seen = true;
      under = std::abs((a - P.centroid).dot(P.normal)) <= tol && std::abs((b - P.centroid).dot(P.normal)) <= tol &&
              std::abs((c - P.centroid).dot(P.normal)) <= tol;
    }
    if (seen && !under) return false;
    on_plane += under;
  }
  return 4 * on_plane >= 3 * sampled;
}

// A standing pose's support plane P and its support face, with the face's flatness.
struct SupportFace {
  Plane P;
  std::vector<Eigen::Vector3d> pts;  // samples of the face (G)
  std::vector<double> area;          // ... their weights
  double flatness = 0;               // |sum of area-weighted normals| / the face's area; 1: flat
};

std::optional<SupportFace> supportFace(const Mesh& object_O, const Eigen::Isometry3d& X_GO,
                                       const std::vector<Eigen::Vector3d>& contacts_G,
                                       const std::vector<Eigen::Vector3d>& normals_G,
                                       const LevelReleaseParams& params) {
  if (contacts_G.size() < 3 || params.band <= 0) return std::nullopt;
  // The support plane P: the contacts on one plane facing up, each pushing along it.
  const Plane P = [&] {
    Plane f = fitPlane(contacts_G, std::vector<double>(contacts_G.size(), 1.0));
    if (f.normal.z() < 0) f.normal = -f.normal;
    return f;
  }();
  if (P.normal.z() < std::cos(M_PI / 4)) return std::nullopt;
  for (size_t i = 0; i < contacts_G.size(); ++i) {
    if (std::abs((contacts_G[i] - P.centroid).dot(P.normal)) > params.contact_tol) return std::nullopt;
    if (i < normals_G.size() && normals_G[i].dot(P.normal) < std::cos(M_PI / 4)) return std::nullopt;
  }
  // The support face: triangles facing P, within `band` of the object's lowest point over P,
  // sampled at their centroids, weighted by area.
  double lowest = 1e300;
  std::vector<Eigen::Vector3d> v(object_O.vertices.size());
  for (size_t i = 0; i < v.size(); ++i) {
    v[i] = X_GO * object_O.vertices[i];
    lowest = std::min(lowest, (v[i] - P.centroid).dot(P.normal));
  }
  const double facing = std::cos(params.facing_deg * M_PI / 180.0);
  std::vector<size_t> face;
  for (size_t i = 0; i < object_O.triangles.size(); ++i) {
    const auto& t = object_O.triangles[i];
    const Eigen::Vector3d a = v[t[0]], b = v[t[1]], c = v[t[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() <= 0 || n.normalized().dot(-P.normal) < facing) continue;
    if (((a + b + c) / 3.0 - P.centroid).dot(P.normal) - lowest > params.band) continue;
    face.push_back(i);
  }
  std::vector<Eigen::Vector3d> pts;
  std::vector<double> area;
  double face_area = 0;
  // Each triangle at its centroid, by its area; a face of under three triangles (a coarse
  // mesh's flat face) at its corners.
  for (size_t i : face) {
    const auto& t = object_O.triangles[i];
    const Eigen::Vector3d a = v[t[0]], b = v[t[1]], c = v[t[2]];
    const double A = 0.5 * (b - a).cross(c - a).norm();
    face_area += A;
    if (face.size() >= 3) {
      pts.push_back((a + b + c) / 3.0);
      area.push_back(A);
    } else {
      for (const Eigen::Vector3d& p : {a, b, c}) pts.push_back(p), area.push_back(A / 3);
    }
  }
  if (pts.size() < 3 || face_area < params.min_face_area) return std::nullopt;
  // A flat face: its triangles' normals, weighed by area, add up to at least cos 15 degrees of
  // their area (a lying rod's strip is curved: 0.96 for the marker's scan; a bottle's bulged
  // bottom 0.98). On a curved face the turn would be a roll.
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  for (size_t i : face) {
    const auto& t = object_O.triangles[i];
    normal_sum += 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
  }
  return SupportFace{P, pts, area, normal_sum.norm() / face_area};
}

}  // namespace

std::optional<Eigen::Isometry3d> levelingTurn(const Mesh& object_O, const Eigen::Isometry3d& X_GO,
                                              const std::vector<Eigen::Vector3d>& contacts_G,
                                              const std::vector<Eigen::Vector3d>& normals_G,
                                              const LevelReleaseParams& params, const MeshModel* area_G) {
  const std::optional<SupportFace> sf = supportFace(object_O, X_GO, contacts_G, normals_G, params);
  if (!sf || sf->flatness < std::cos(params.max_curve_deg * M_PI / 180.0)) return std::nullopt;
  const Plane& P = sf->P;
  const std::vector<Eigen::Vector3d>& pts = sf->pts;
  Plane F = fitPlane(pts, sf->area);
  if (F.normal.dot(P.normal) < 0) F.normal = -F.normal;
  const double tilt = std::acos(std::clamp(F.normal.dot(P.normal), -1.0, 1.0));
  if (tilt < params.min_tilt_deg * M_PI / 180.0 || tilt > params.max_tilt_deg * M_PI / 180.0) return std::nullopt;
  if (area_G && !flatUnder(*area_G, pts, P, params.area_tol)) return std::nullopt;
  // About the face's centroid: the face turned parallel to P, where it was.
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::Quaterniond::FromTwoVectors(F.normal, P.normal).toRotationMatrix();
  turn.translation() = F.centroid - turn.linear() * F.centroid;
  return turn;
}

bool restsOnCurvedFace(const Mesh& object_O, const Eigen::Isometry3d& X_GO,
                       const std::vector<Eigen::Vector3d>& contacts_G,
                       const std::vector<Eigen::Vector3d>& normals_G, const LevelReleaseParams& params) {
  const std::optional<SupportFace> sf = supportFace(object_O, X_GO, contacts_G, normals_G, params);
  return sf && sf->flatness < std::cos(params.max_curve_deg * M_PI / 180.0);
}

}  // namespace place_planner
