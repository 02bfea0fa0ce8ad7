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
  // The triangles under a sample: those the line through it along P's normal meets (the area's
  // triangle BVH along a segment across the whole area, every hit visited).
  const Eigen::Vector3d lo = toEigen(area.bounds.lo), hi = toEigen(area.bounds.hi);
  int on_plane = 0, sampled = 0;
  for (size_t s = 0; s < samples.size(); s += step) {
    ++sampled;
    const Eigen::Vector2d q = in2d(samples[s]);
    const double reach = (hi - lo).norm() + (samples[s] - 0.5 * (lo + hi)).norm();
    const Eigen::Vector3d o = samples[s] + reach * P.normal;
    bool seen = false, under = false;
    bvhRay(view(area.triangle_bvh), toV3(o), toV3(-P.normal), 2.0 * reach, [&](int t) {
      if (under) return 0.0;  // decided: nothing more to visit
      const auto& tri = area.triangles[t];
      const Eigen::Vector3d a = toEigen(area.vertices[tri[0]]), b = toEigen(area.vertices[tri[1]]),
                            c = toEigen(area.vertices[tri[2]]);
      const double along = std::abs(toEigen(area.triangle_normals[t]).dot(P.normal));
      if (along < kSteep) return 2.0 * reach;  // a wall or an edge's side: nothing rests on it
      const Eigen::Vector2d A = in2d(a), B = in2d(b), C = in2d(c);
      const double d0 = side(q, A, B), d1 = side(q, B, C), d2 = side(q, C, A);
      if (!((d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0))) return 2.0 * reach;
      seen = true;
      under = std::abs((a - P.centroid).dot(P.normal)) <= tol && std::abs((b - P.centroid).dot(P.normal)) <= tol &&
              std::abs((c - P.centroid).dot(P.normal)) <= tol;
      return under ? 0.0 : 2.0 * reach;
    });
    if (seen && !under) return false;
    on_plane += under;
  }
  return 4 * on_plane >= 3 * sampled;
}

// A standing pose's support plane P and its support face, with the face's flatness.
struct SupportFace {
  Plane P;
  std::vector<Eigen::Vector3d> v;    // the object's vertices (G)
  std::vector<Eigen::Vector3d> pts;  // samples of the face (G)
  std::vector<double> area;          // ... their weights
  double face_area = 0;              // m^2
  double flatness = 0;               // |sum of area-weighted normals| / the face's area; 1: flat
};

// The face of the object (vertices `v`, frame G) cut by a plane of normal `up`: its triangles
// facing against `up` (within facing_deg) within `band` of its lowest point along `up`, sampled
// at their centroids, weighted by area (a face of under three triangles, a coarse mesh's flat
// face, at its corners).
SupportFace faceAbove(const Mesh& object_O, const std::vector<Eigen::Vector3d>& v, const Eigen::Vector3d& up,
                      const LevelReleaseParams& params) {
  double lowest = 1e300;
  for (const Eigen::Vector3d& p : v) lowest = std::min(lowest, p.dot(up));
  const double facing = std::cos(params.facing_deg * M_PI / 180.0);
  std::vector<size_t> face;
  for (size_t i = 0; i < object_O.triangles.size(); ++i) {
    const auto& t = object_O.triangles[i];
    const Eigen::Vector3d a = v[t[0]], b = v[t[1]], c = v[t[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() <= 0 || n.normalized().dot(-up) < facing) continue;
    if (((a + b + c) / 3.0).dot(up) - lowest > params.band) continue;
    face.push_back(i);
  }
  SupportFace f;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  for (size_t i : face) {
    const auto& t = object_O.triangles[i];
    const Eigen::Vector3d a = v[t[0]], b = v[t[1]], c = v[t[2]];
    const Eigen::Vector3d n2 = (b - a).cross(c - a);
    const double A = 0.5 * n2.norm();
    f.face_area += A;
    normal_sum += 0.5 * n2;
    if (face.size() >= 3) {
      f.pts.push_back((a + b + c) / 3.0);
      f.area.push_back(A);
    } else {
      for (const Eigen::Vector3d& p : {a, b, c}) f.pts.push_back(p), f.area.push_back(A / 3);
    }
  }
  // A flat face: its triangles' normals, weighed by area, add up to at least cos 15 degrees of
  // their area (a lying rod's strip is curved: 0.96 for the marker's scan; a bottle's bulged
  // bottom 0.98).
  f.flatness = f.face_area > 0 ? normal_sum.norm() / f.face_area : 0;
  return f;
}

std::vector<Eigen::Vector3d> inG(const Mesh& object_O, const Eigen::Isometry3d& X_GO) {
  std::vector<Eigen::Vector3d> v(object_O.vertices.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = X_GO * object_O.vertices[i];
  return v;
}

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
  // The support face: the object's surface facing P within `band` of its lowest point over P.
  std::vector<Eigen::Vector3d> v = inG(object_O, X_GO);
  SupportFace f = faceAbove(object_O, v, P.normal, params);
  if (f.pts.size() < 3 || f.face_area < params.min_face_area) return std::nullopt;
  f.P = P;
  f.v = std::move(v);
  return f;
}

}  // namespace

std::optional<Eigen::Vector3d> wallAxis(const Mesh& object_O, const std::vector<Eigen::Vector3d>& v_G,
                                        const Eigen::Vector3d& face_n, double face_area) {
  const double kSquare = std::sin(20.0 * M_PI / 180.0);  // |n . face_n| below it: a wall
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  double walls = 0;
  for (const auto& t : object_O.triangles) {
    const Eigen::Vector3d n2 = (v_G[t[1]] - v_G[t[0]]).cross(v_G[t[2]] - v_G[t[0]]);
    const double A2 = n2.norm();
    if (A2 <= 0) continue;
    const Eigen::Vector3d n = n2 / A2;
    if (std::abs(n.dot(face_n)) >= kSquare) continue;
    M += 0.5 * A2 * n * n.transpose();
    walls += 0.5 * A2;
  }
  if (walls <= face_area || walls <= 0) return std::nullopt;
  // The walls' normals' mean square along a line is least along their axis (they add up to 1).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(M / walls);
  const Eigen::Vector3d l = es.eigenvalues();  // ascending
  // Facing two ways at least (a lone wall leaves its axis free in its plane), and square to the
  // axis within 6 degrees r.m.s. (sin^2 6 = 0.011): the held-out bottle's scanned body, 4.4
  // degrees; a stemmed glass's scanned bowl, a warped flare, 10 degrees, whose axis lay 2.4
  // degrees off the true one (a 13 degree bound stood the glass 3 degrees off, turned 10 by Bullet).
  if (l(1) < 0.05 || l(0) > 0.25 * l(1) || l(0) > 0.011) return std::nullopt;
  Eigen::Vector3d a = es.eigenvectors().col(0);
  return a.dot(face_n) < 0 ? Eigen::Vector3d(-a) : a;
}

LevelReleaseParams levelReleaseParams(double scan_noise, bool scanned, bool open) {
  LevelReleaseParams lp;
  lp.band = 3.0 * scan_noise;
  lp.area_tol = 2.0 * scan_noise;
  lp.curved = scanned;
  lp.square_to_walls = scanned && open;
  return lp;
}

std::optional<Eigen::Isometry3d> levelingTurn(const Mesh& object_O, const Eigen::Isometry3d& X_GO,
                                              const std::vector<Eigen::Vector3d>& contacts_G,
                                              const std::vector<Eigen::Vector3d>& normals_G,
                                              const LevelReleaseParams& params, const MeshModel* area_G) {
  const std::optional<SupportFace> sf = supportFace(object_O, X_GO, contacts_G, normals_G, params);
  const bool curved = sf && sf->flatness < std::cos(params.max_curve_deg * M_PI / 180.0);
  if (!sf || (curved && !params.curved)) return std::nullopt;
  const Plane& P = sf->P;
  std::vector<Eigen::Vector3d> pts = sf->pts;
  Plane F = fitPlane(pts, sf->area);
  if (F.normal.dot(P.normal) < 0) F.normal = -F.normal;
  // The face cut again by its own plane, twice: where P is tilted, the band takes a wedge of a
  // curved face (deeper at its low end), whose plane is tilted back by only three quarters of
  // the tilt (a rod lying 2 degrees off along it); cut by F it is a strip of even depth. A flat
  // face is the same cut either way.
  if (curved) {
    for (int i = 0; i < 2; ++i) {
      const SupportFace g = faceAbove(object_O, sf->v, F.normal, params);
      if (g.pts.size() < 3) break;
      Plane G = fitPlane(g.pts, g.area);
      if (G.normal.dot(P.normal) < 0) G.normal = -G.normal;
      F = G;
      pts = g.pts;
    }
  }
  // The face's normal, or the axis of the walls it is square to.
  Eigen::Vector3d n_face = F.normal;
  if (params.square_to_walls) {
    const std::optional<Eigen::Vector3d> axis = wallAxis(object_O, sf->v, F.normal, sf->face_area);
    if (axis && axis->dot(F.normal) >= std::cos(params.max_tilt_deg * M_PI / 180.0)) n_face = *axis;
    else if (params.walls_only) return std::nullopt;
  }
  if (params.walls_only && !params.square_to_walls) return std::nullopt;
  const double tilt = std::acos(std::clamp(n_face.dot(P.normal), -1.0, 1.0));
  if (tilt < params.min_tilt_deg * M_PI / 180.0 || tilt > params.max_tilt_deg * M_PI / 180.0) return std::nullopt;
  if (area_G && !flatUnder(*area_G, pts, P, params.area_tol)) return std::nullopt;
  // About the face's centroid: the face (its walls' axis) turned square to P, where it was.
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::Quaterniond::FromTwoVectors(n_face, P.normal).toRotationMatrix();
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
