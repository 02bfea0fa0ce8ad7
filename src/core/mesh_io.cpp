#include "place_planner/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

namespace place_planner {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MeshError(path + ": " + what);
}

// ---------------------------------------------------------------------------------------- PLY
enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

PlyType plyType(const std::string& t, const std::string& path) {
  static const std::map<std::string, PlyType> m = {
      {"char", PlyType::I8},    {"int8", PlyType::I8},     {"uchar", PlyType::U8},
      {"uint8", PlyType::U8},   {"short", PlyType::I16},   {"int16", PlyType::I16},
      {"ushort", PlyType::U16}, {"uint16", PlyType::U16},  {"int", PlyType::I32},
      {"int32", PlyType::I32},  {"uint", PlyType::U32},    {"uint32", PlyType::U32},
      {"float", PlyType::F32},  {"float32", PlyType::F32}, {"double", PlyType::F64},
      {"float64", PlyType::F64}};
  auto it = m.find(t);
  if (it == m.end()) fail(path, "unknown PLY property type '" + t + "'");
  return it->second;
}

int plySize(PlyType t) {
  switch (t) {
    case PlyType::I8: case PlyType::U8: return 1;
    case PlyType::I16: case PlyType::U16: return 2;
    case PlyType::I32: case PlyType::U32: case PlyType::F32: return 4;
    default: return 8;
  }
}

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::U8, type = PlyType::F32;
};
struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> props;
};

class BinReader {
 public:
  BinReader(std::istream& in, bool big_endian, const std::string& path)
      : in_(in), swap_(big_endian), path_(path) {}
  double read(PlyType t) {
    unsigned char b[8];
    const int n = plySize(t);
    if (!in_.read(reinterpret_cast<char*>(b), n)) fail(path_, "unexpected end of binary PLY data");
    if (swap_) std::reverse(b, b + n);
    switch (t) {
      case PlyType::I8: { int8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::U8: { uint8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::I16: { int16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::U16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::I32: { int32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::U32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::F32: { float v; std::memcpy(&v, b, 4); return v; }
      default: { double v; std::memcpy(&v, b, 8); return v; }
    }
  }

 private:
  std::istream& in_;
  bool swap_;
  const std::string& path_;
};

Mesh loadPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  std::string line;
  std::getline(in, line);
  if (line.rfind("ply", 0) != 0) fail(path, "not a PLY file (missing 'ply' magic)");
  std::string format;
  std::vector<PlyElement> elements;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "format") {
      ls >> format;
    } else if (kw == "element") {
      PlyElement e;
      ls >> e.name >> e.count;
      elements.push_back(e);
    } else if (kw == "property") {
      if (elements.empty()) fail(path, "PLY property before any element");
      PlyProperty p;
      std::string t;
      ls >> t;
      if (t == "list") {
        std::string ct, it;
        ls >> ct >> it >> p.name;
        p.is_list = true;
        p.count_type = plyType(ct, path);
        p.type = plyType(it, path);
      } else {
        p.type = plyType(t, path);
        ls >> p.name;
      }
      elements.back().props.push_back(p);
    } else if (kw == "end_header") {
      break;
    }
  }
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    fail(path, "unsupported PLY format '" + format + "'");
  const bool ascii = format == "ascii";
  BinReader bin(in, format == "binary_big_endian", path);

  std::vector<Eigen::Vector3d> verts;
  std::vector<std::vector<int>> faces;
  for (const auto& e : elements) {
    int ix = -1, iy = -1, iz = -1, iface = -1;
    for (size_t k = 0; k < e.props.size(); ++k) {
      const auto& n = e.props[k].name;
      if (n == "x") ix = static_cast<int>(k);
      if (n == "y") iy = static_cast<int>(k);
      if (n == "z") iz = static_cast<int>(k);
      if (e.props[k].is_list && (n == "vertex_indices" || n == "vertex_index")) iface = static_cast<int>(k);
    }
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0)) fail(path, "PLY vertex element lacks x, y or z");
    if (is_vertex) verts.reserve(e.count);
    if (is_face) faces.reserve(e.count);
    for (size_t i = 0; i < e.count; ++i) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      std::vector<int> poly;
      std::istringstream ls;
      if (ascii) {
        if (!std::getline(in, line)) fail(path, "unexpected end of ASCII PLY data in element '" + e.name + "'");
        ls.str(line);
      }
      auto next = [&](PlyType t) -> double {
        if (!ascii) return bin.read(t);
        double v;
        if (!(ls >> v)) fail(path, "malformed ASCII PLY line in element '" + e.name + "' " + std::to_string(i));
        return v;
      };
      for (size_t k = 0; k < e.props.size(); ++k) {
        const auto& pr = e.props[k];
        if (pr.is_list) {
          const double cnt = next(pr.count_type);
          if (cnt < 0 || cnt > 1e6) fail(path, "bad list length in element '" + e.name + "' " + std::to_string(i));
          for (int j = 0; j < static_cast<int>(cnt); ++j) {
            const double v = next(pr.type);
            if (static_cast<int>(k) == iface) poly.push_back(static_cast<int>(v));
          }
        } else {
          const double v = next(pr.type);
          if (static_cast<int>(k) == ix) p.x() = v;
          if (static_cast<int>(k) == iy) p.y() = v;
          if (static_cast<int>(k) == iz) p.z() = v;
        }
      }
      if (is_vertex) verts.push_back(p);
      if (is_face) faces.push_back(std::move(poly));
    }
  }
  return buildMesh(verts, faces, path);
}

// ---------------------------------------------------------------------------------------- OBJ
Mesh loadObj(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot open file");
  std::vector<Eigen::Vector3d> verts;
  std::vector<std::vector<int>> faces;
  std::string line;
  size_t lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "v") {
      Eigen::Vector3d p;
      if (!(ls >> p.x() >> p.y() >> p.z())) fail(path, "line " + std::to_string(lineno) + ": malformed vertex");
      verts.push_back(p);
    } else if (kw == "f") {
      std::vector<int> poly;
      std::string tok;
      while (ls >> tok) {
        const int idx = std::stoi(tok.substr(0, tok.find('/')));
        // 1-based; negative indices count back from the last vertex read.
        poly.push_back(idx > 0 ? idx - 1 : static_cast<int>(verts.size()) + idx);
      }
      faces.push_back(std::move(poly));
    }
  }
  return buildMesh(verts, faces, path);
}

// ---------------------------------------------------------------------------------------- STL
Mesh loadStl(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) fail(path, "cannot open file");
  const auto size = static_cast<size_t>(in.tellg());
  in.seekg(0);
  std::vector<char> data(size);
  in.read(data.data(), static_cast<std::streamsize>(size));
  std::vector<Eigen::Vector3d> corners;
  uint32_t n = 0;
  if (size >= 84) std::memcpy(&n, data.data() + 80, 4);
  if (size >= 84 && size == 84 + 50ull * n) {
    for (uint32_t i = 0; i < n; ++i) {
      const char* f = data.data() + 84 + 50ull * i + 12;
      for (int k = 0; k < 3; ++k) {
        float c[3];
        std::memcpy(c, f + 12 * k, 12);
        corners.emplace_back(c[0], c[1], c[2]);
      }
    }
  } else {
    std::istringstream ls(std::string(data.begin(), data.end()));
    std::string tok;
    while (ls >> tok) {
      if (tok == "vertex") {
        Eigen::Vector3d p;
        if (!(ls >> p.x() >> p.y() >> p.z())) fail(path, "malformed ASCII STL vertex");
        corners.push_back(p);
      }
    }
    if (corners.size() % 3 != 0) fail(path, "ASCII STL facet without 3 vertices");
  }
  // STL repeats vertices per facet: merge identical coordinates so edges are shared.
  std::map<std::tuple<double, double, double>, int> ids;
  std::vector<Eigen::Vector3d> verts;
  std::vector<std::vector<int>> faces;
  for (size_t i = 0; i < corners.size(); i += 3) {
    std::vector<int> poly;
    for (size_t k = 0; k < 3; ++k) {
      const auto& c = corners[i + k];
      auto it = ids.emplace(std::make_tuple(c.x(), c.y(), c.z()), static_cast<int>(verts.size()));
      if (it.second) verts.push_back(c);
      poly.push_back(it.first->second);
    }
    faces.push_back(poly);
  }
  return buildMesh(verts, faces, path);
}

}  // namespace

Mesh loadMesh(const std::string& path) {
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : lower(path.substr(dot + 1));
  if (ext == "ply") return loadPly(path);
  if (ext == "obj") return loadObj(path);
  if (ext == "stl") return loadStl(path);
  fail(path, "unsupported mesh format '" + ext + "' (use .ply, .obj or .stl)");
}

void saveMeshPly(const Mesh& mesh, const std::string& path, bool binary) {
  std::ofstream out(path, std::ios::binary);
  if (!out) fail(path, "cannot write file");
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
      << "element vertex " << mesh.vertices.size() << "\nproperty float x\nproperty float y\n"
      << "property float z\nelement face " << mesh.patches.size()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : mesh.vertices) {
    if (binary) {
      const float f[3] = {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
      out.write(reinterpret_cast<const char*>(f), sizeof f);
    } else {
      out << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    }
  }
  for (const auto& p : mesh.patches) {
    if (binary) {
      const unsigned char c = static_cast<unsigned char>(p.size());
      out.write(reinterpret_cast<const char*>(&c), 1);
      for (int i : p) {
        const int32_t v = i;
        out.write(reinterpret_cast<const char*>(&v), 4);
      }
    } else {
      out << p.size();
      for (int i : p) out << ' ' << i;
      out << '\n';
    }
  }
}

}  // namespace place_planner
