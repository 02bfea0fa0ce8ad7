// Which way a mesh is wound (beyond the paper). A reconstruction's winding is a convention
// (marching cubes and mesh tools differ), but the models read the solid side from it: the
// sphere model's normals, the contact normals' sides (sphereContact), the valley edges of a
// solid (featureEdges). Wound inwards, the rack planned worse than wound outwards (the mug on
// `dish_rack`: one stable pose against four) and a looped mug hung on no rack, so both meshes
// are wound outwards before they are modelled: the area in buildAreaModel (by gravity), the
// object in the planner (by its volume). Frame: the mesh's own.
// The pieces (connected by shared edges) and their edge uses serve featureEdges too.
#pragma once
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "place_planner/infra/stop_signal.h"
#include "place_planner/model/mesh.h"

namespace place_planner {

// Each undirected edge of the triangles with the (first two) triangles on it: sorted keys and
// their uses (a map is ten times slower on big scans).
struct EdgeUses {
  struct Use {
    int tris[2] = {-1, -1};
    int count = 0;
    int forward = 0;  // triangles traversing it from the lower index to the higher
  };
  std::vector<uint64_t> keys;
  std::vector<Use> uses;
  const Use* find(int a, int b) const;
};
EdgeUses edgeUses(const Mesh& mesh, const StopSignal* stop = nullptr);

// Connected pieces: triangles joined by edges that two triangles share.
struct MeshPieces {
  struct Piece {
    int edges = 0, border = 0;  // its edges, those on one triangle only
    bool consistent = true;     // every shared edge traversed once each way
    double volume = 0;          // signed, about the mesh's centre of mass (6 x the volume)
    double area = 0;            // m^2
    Eigen::Vector3d normal_area = Eigen::Vector3d::Zero();  // sum of area x unit normal
  };
  std::vector<int> piece;      // per triangle: its piece's root triangle
  std::vector<Piece> pieces;   // at each piece's root triangle
  // +1 where the triangle's piece is a consistently wound, (nearly) closed solid (under 2 %
  // border edges) wound outwards, -1 wound inwards, 0 an open sheet or scan (no inside).
  int solidSide(int triangle) const;
};
MeshPieces meshPieces(const Mesh& mesh, const EdgeUses& uses);

// Whether the mesh is wound inwards, as a whole. Where most of its consistently wound surface
// lies on closed pieces (whose area-weighted normal is under a tenth of their area: zero on a
// closed surface, about the area on a sheet), by their total signed volume (negative: inwards;
// a cavity inside a solid keeps its inward winding); where most lies on open pieces (a scan, a
// sheet), by their area-weighted normal, which points along -up by more than min_share of their
// area (a scan seen from above faces up; one that faces neither way, a wall, is not judged).
// `up` zero: open pieces are never judged inwards (an object's scan has no up).
bool woundInwards(const Mesh& mesh, const Eigen::Vector3d& up, double min_share = 0.05,
                  const StopSignal* stop = nullptr);
// The same with the mesh's edge uses known already.
bool woundInwards(const Mesh& mesh, const EdgeUses& uses, const Eigen::Vector3d& up, double min_share = 0.05);

// The same surface with every triangle and patch wound the other way (normals reversed).
Mesh reversedWinding(const Mesh& mesh);

}  // namespace place_planner
