// Mesh files: PLY (ASCII, binary little/big endian), OBJ, STL (ASCII and binary).
// Our own small readers rather than PCL or assimp: the core stays ROS- and PCL-free and fast to
// build (PCL's io headers cost tens of seconds per translation unit), and the three formats
// need only vertex positions and faces. The readers are fuzzed (test/fuzz, scripts/fuzz): any
// byte string gives a Mesh or a MeshError, never a crash, a hang or an allocation the input
// cannot pay for (counts in a header are checked against the bytes that follow).
#pragma once
#include <string>

#include "place_planner/model/mesh.h"

namespace place_planner {

enum class MeshFormat { kPly, kObj, kStl };

// Loads and validates (buildMesh). The format follows the extension (.ply, .obj, .stl, any
// case). Throws MeshError naming the file and the problem.
Mesh loadMesh(const std::string& path);

// The same readers on a file's contents in memory; `name` prefixes every error message (the
// path, for loadMesh). PLY: ASCII or binary per its header; STL: binary when the size matches
// its triangle count, else ASCII.
Mesh parseMesh(const std::string& bytes, MeshFormat format, const std::string& name = "mesh");

// Writes an ASCII or binary little-endian PLY of the patches.
void saveMeshPly(const Mesh& mesh, const std::string& path, bool binary = true);

}  // namespace place_planner
