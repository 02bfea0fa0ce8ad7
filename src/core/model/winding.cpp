#include "place_planner/model/winding.h"

#include <Eigen/Geometry>
#include <algorithm>

namespace place_planner {
namespace {

// A piece whose area-weighted normal is under this share of its area is closed (woundInwards).
constexpr double kClosedNormalShare = 0.1;

uint64_t edgeKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b);
}

}  // namespace

const EdgeUses::Use* EdgeUses::find(int a, int b) const {
  const auto it = std::lower_bound(keys.begin(), keys.end(), edgeKey(a, b));
  return it != keys.end() && *it == edgeKey(a, b) ? &uses[it - keys.begin()] : nullptr;
}

EdgeUses edgeUses(const Mesh& mesh, const StopSignal* stop) {
  std::vector<std::pair<uint64_t, int>> sides;  // key, triangle * 2 + forward
  sides.reserve(3 * mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    pollStop(stop, t, 1u << 14);
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      sides.emplace_back(edgeKey(a, b), static_cast<int>(2 * t + (a < b)));
    }
  }
  std::sort(sides.begin(), sides.end());
  if (stop) stop->throwIfRequested();
  EdgeUses e;
  for (const auto& sd : sides) {
    if (e.keys.empty() || e.keys.back() != sd.first) e.keys.push_back(sd.first), e.uses.emplace_back();
    EdgeUses::Use& u = e.uses.back();
    if (u.count < 2) u.tris[u.count] = sd.second / 2;
    ++u.count;
    u.forward += sd.second % 2;
  }
  return e;
}

MeshPieces meshPieces(const Mesh& mesh, const EdgeUses& uses) {
  MeshPieces m;
  m.piece.resize(mesh.triangles.size());
  for (size_t t = 0; t < m.piece.size(); ++t) m.piece[t] = static_cast<int>(t);
  auto find = [&](int t) {
    while (m.piece[t] != t) t = m.piece[t] = m.piece[m.piece[t]];
    return t;
  };
  for (const EdgeUses::Use& u : uses.uses)
    if (u.count == 2) m.piece[find(u.tris[0])] = find(u.tris[1]);
  for (size_t t = 0; t < m.piece.size(); ++t) m.piece[t] = find(static_cast<int>(t));
  m.pieces.resize(mesh.triangles.size());
  for (const EdgeUses::Use& u : uses.uses) {
    MeshPieces::Piece& p = m.pieces[m.piece[u.tris[0]]];
    ++p.edges;
    p.border += u.count == 1;
    if (u.count == 2 && u.forward != 1) p.consistent = false;
  }
  const Eigen::Vector3d o = mesh.properties.center_of_mass;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d a = mesh.vertices[tri[0]] - o, b = mesh.vertices[tri[1]] - o, c = mesh.vertices[tri[2]] - o;
    MeshPieces::Piece& p = m.pieces[m.piece[t]];
    p.volume += a.dot(b.cross(c));
    const Eigen::Vector3d n2 = (b - a).cross(c - a);  // twice the area along the normal
    p.area += 0.5 * n2.norm();
    p.normal_area += 0.5 * n2;
  }
  return m;
}

int MeshPieces::solidSide(int triangle) const {
  const Piece& p = pieces[piece[triangle]];
  if (!p.consistent || p.border > 0.02 * p.edges) return 0;
  return (p.volume > 0) - (p.volume < 0);
}

bool woundInwards(const Mesh& mesh, const Eigen::Vector3d& up, double min_share, const StopSignal* stop) {
  return woundInwards(mesh, edgeUses(mesh, stop), up, min_share);
}

bool woundInwards(const Mesh& mesh, const EdgeUses& uses, const Eigen::Vector3d& up, double min_share) {
  const MeshPieces mp = meshPieces(mesh, uses);
  const Eigen::Vector3d u = up.norm() > 0 ? Eigen::Vector3d(up.normalized()) : Eigen::Vector3d::Zero();
  // One decision for the whole mesh, so that a cavity (a closed piece wound inwards inside a
  // solid, as a signed-distance reconstruction leaves them) stays one.
  double closed_area = 0, closed_volume = 0, open_area = 0, open_up = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (mp.piece[t] != static_cast<int>(t)) continue;  // each piece once, at its root
    const MeshPieces::Piece& p = mp.pieces[t];
    if (!p.consistent) continue;
    // Closed: its normals cancel (the divergence theorem: the area-weighted normal of a closed
    // surface is zero). A sheet of a scan with few border edges is not (featureEdges' 2 % rule
    // takes a 20,000-triangle scan of a table top for a solid).
    if (p.normal_area.norm() < kClosedNormalShare * p.area) {
      closed_area += p.area;
      closed_volume += p.volume;
    } else {
      open_area += p.area;
      open_up += p.normal_area.dot(u);
    }
  }
  if (closed_area >= open_area && closed_area > 0) return closed_volume < 0;
  return open_up < -min_share * open_area;
}

Mesh reversedWinding(const Mesh& mesh) {
  Mesh out = mesh;
  for (auto& t : out.triangles) std::swap(t[1], t[2]);
  for (auto& p : out.patches) std::reverse(p.begin(), p.end());
  for (auto& n : out.patch_normals) n = -n;
  return out;
}

}  // namespace place_planner
