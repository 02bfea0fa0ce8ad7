// Mesh files: PLY (ASCII, binary little/big endian), OBJ, STL (ASCII and binary).
// Our own small readers rather than PCL or assimp: the core stays ROS- and PCL-free and fast to
// build (PCL's io headers cost tens of seconds per translation unit), and the three formats
// need only vertex positions and faces.
#pragma once
#include <string>

#include "place_planner/mesh.h"

namespace place_planner {

// Loads and validates (buildMesh). Throws MeshError naming the file and the problem.
Mesh loadMesh(const std::string& path);

// Writes an ASCII or binary little-endian PLY of the patches.
void saveMeshPly(const Mesh& mesh, const std::string& path, bool binary = true);

}  // namespace place_planner
