#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/output_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

namespace place_planner {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

[[noreturn]] void fail(const std::string& name, const std::string& what) {
  throw MeshError(name + ": " + what);
}

// Longer polygons are not a mesh a scanner writes; the cap also bounds the work per list.
constexpr double kMaxListLength = 1e6;

// A whole number that fits an int (a list length, a vertex index), else false. Read values
// arrive as doubles; casting one out of range to int is undefined, so it is checked first.
bool toInt(double v, int* out) {
  if (!(v >= INT_MIN && v <= INT_MAX) || v != std::floor(v)) return false;
  *out = static_cast<int>(v);
  return true;
}

// Reads the next line (without "\n" or "\r\n") at `pos`; false at the end of `bytes`.
bool nextLine(const std::string& bytes, size_t* pos, std::string* line) {
  if (*pos >= bytes.size()) return false;
  size_t end = bytes.find('\n', *pos);
  if (end == std::string::npos) end = bytes.size();
  line->assign(bytes, *pos, end - *pos);
  *pos = std::min(end + 1, bytes.size());
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return true;
}

// ---------------------------------------------------------------------------------------- PLY
enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

PlyType plyType(const std::string& t, const std::string& name) {
  static const std::map<std::string, PlyType> m = {
      {"char", PlyType::I8},    {"int8", PlyType::I8},     {"uchar", PlyType::U8},
      {"uint8", PlyType::U8},   {"short", PlyType::I16},   {"int16", PlyType::I16},
      {"ushort", PlyType::U16}, {"uint16", PlyType::U16},  {"int", PlyType::I32},
      {"int32", PlyType::I32},  {"uint", PlyType::U32},    {"uint32", PlyType::U32},
      {"float", PlyType::F32},  {"float32", PlyType::F32}, {"double", PlyType::F64},
      {"float64", PlyType::F64}};
  auto it = m.find(t);
  if (it == m.end()) fail(name, "unknown PLY property type '" + t + "'");
  return it->second;
}

size_t plySize(PlyType t) {
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
  // Bytes one element takes at least: binary (each scalar, each list's length) and ASCII (a
  // character and a separator per value). Bounds what a header's count may reserve.
  size_t minBytes(bool ascii) const {
    size_t n = 0;
    for (const auto& p : props) n += ascii ? 2 : plySize(p.is_list ? p.count_type : p.type);
    return n;
  }
};

class BinReader {
 public:
  BinReader(const std::string& bytes, size_t* pos, bool big_endian, const std::string& name)
      : bytes_(bytes), pos_(pos), swap_(big_endian), name_(name) {}
  double read(PlyType t) {
    unsigned char b[8];
    const size_t n = plySize(t);
    if (bytes_.size() - *pos_ < n) fail(name_, "unexpected end of binary PLY data");
    std::memcpy(b, bytes_.data() + *pos_, n);
    *pos_ += n;
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
  const std::string& bytes_;
  size_t* pos_;
  bool swap_;
  const std::string& name_;
};

Mesh parsePly(const std::string& bytes, const std::string& name) {
  size_t pos = 0;
  std::string line;
  if (!nextLine(bytes, &pos, &line) || line.rfind("ply", 0) != 0) fail(name, "not a PLY file (missing 'ply' magic)");
  std::string format;
  std::vector<PlyElement> elements;
  bool header_ended = false;
  while (!header_ended && nextLine(bytes, &pos, &line)) {
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "format") {
      ls >> format;
    } else if (kw == "element") {
      PlyElement e;
      std::string count;
      ls >> e.name >> count;
      unsigned long long n = 0;
      const auto r = std::from_chars(count.data(), count.data() + count.size(), n);
      if (count.empty() || r.ec != std::errc() || r.ptr != count.data() + count.size())
        fail(name, "PLY element '" + e.name + "' has a bad count '" + count + "'");
      e.count = static_cast<size_t>(n);
      elements.push_back(e);
    } else if (kw == "property") {
      if (elements.empty()) fail(name, "PLY property before any element");
      PlyProperty p;
      std::string t;
      ls >> t;
      if (t == "list") {
        std::string ct, it;
        ls >> ct >> it >> p.name;
        p.is_list = true;
        p.count_type = plyType(ct, name);
        p.type = plyType(it, name);
      } else {
        p.type = plyType(t, name);
        ls >> p.name;
      }
      elements.back().props.push_back(p);
    } else if (kw == "end_header") {
      header_ended = true;
    }
  }
  if (!header_ended) fail(name, "PLY header has no end_header");
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    fail(name, "unsupported PLY format '" + format + "'");
  const bool ascii = format == "ascii";
  BinReader bin(bytes, &pos, format == "binary_big_endian", name);

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
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0)) fail(name, "PLY vertex element lacks x, y or z");
    // A binary element without properties takes no bytes: nothing to read, whatever its count
    // (looping over a count of 10^18 would never end).
    if (!ascii && e.props.empty()) continue;
    // Reserve no more than the bytes left can hold: a header may claim any count.
    const size_t fits = (bytes.size() - pos) / std::max<size_t>(1, e.minBytes(ascii));
    if (is_vertex) verts.reserve(verts.size() + std::min(e.count, fits));
    if (is_face) faces.reserve(faces.size() + std::min(e.count, fits));
    std::istringstream ls;
    for (size_t i = 0; i < e.count; ++i) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      std::vector<int> poly;
      if (ascii) {
        if (!nextLine(bytes, &pos, &line))
          fail(name, "unexpected end of ASCII PLY data in element '" + e.name + "'");
        ls.clear();
        ls.str(line);
      }
      auto next = [&](PlyType t) -> double {
        if (!ascii) return bin.read(t);
        double v;
        if (!(ls >> v)) fail(name, "malformed ASCII PLY line in element '" + e.name + "' " + std::to_string(i));
        return v;
      };
      for (size_t k = 0; k < e.props.size(); ++k) {
        const auto& pr = e.props[k];
        if (pr.is_list) {
          int cnt = 0;
          if (!toInt(next(pr.count_type), &cnt) || cnt < 0 || cnt > kMaxListLength)
            fail(name, "bad list length in element '" + e.name + "' " + std::to_string(i));
          for (int j = 0; j < cnt; ++j) {
            const double v = next(pr.type);
            if (static_cast<int>(k) != iface) continue;
            int idx = 0;
            if (!toInt(v, &idx))
              fail(name, "face " + std::to_string(i) + " has a vertex index that is not an int");
            poly.push_back(idx);
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
  return buildMesh(verts, faces, name);
}

// ---------------------------------------------------------------------------------------- OBJ
Mesh parseObj(const std::string& bytes, const std::string& name) {
  std::vector<Eigen::Vector3d> verts;
  std::vector<std::vector<int>> faces;
  std::string line;
  size_t pos = 0, lineno = 0;
  while (nextLine(bytes, &pos, &line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "v") {
      Eigen::Vector3d p;
      if (!(ls >> p.x() >> p.y() >> p.z())) fail(name, "line " + std::to_string(lineno) + ": malformed vertex");
      verts.push_back(p);
    } else if (kw == "f") {
      std::vector<int> poly;
      std::string tok;
      while (ls >> tok) {
        // "v", "v/vt", "v//vn" or "v/vt/vn": the position index is the first number.
        const size_t end = std::min(tok.find('/'), tok.size());
        int idx = 0;
        const auto r = std::from_chars(tok.data(), tok.data() + end, idx);
        if (r.ec != std::errc() || r.ptr != tok.data() + end || idx == 0)
          fail(name, "line " + std::to_string(lineno) + ": bad vertex index '" + tok + "'");
        // 1-based; negative indices count back from the last vertex read (-1: the last).
        poly.push_back(idx > 0 ? idx - 1 : static_cast<int>(verts.size()) + idx);
      }
      faces.push_back(std::move(poly));
    }
  }
  return buildMesh(verts, faces, name);
}

// ---------------------------------------------------------------------------------------- STL
Mesh parseStl(const std::string& data, const std::string& name) {
  const size_t size = data.size();
  std::vector<Eigen::Vector3d> corners;
  uint32_t n = 0;
  if (size >= 84) std::memcpy(&n, data.data() + 80, 4);
  if (size >= 84 && size == 84 + 50ull * n) {
    corners.reserve(3ull * n);
    for (uint32_t i = 0; i < n; ++i) {
      const char* f = data.data() + 84 + 50ull * i + 12;
      for (int k = 0; k < 3; ++k) {
        float c[3];
        std::memcpy(c, f + 12 * k, 12);
        corners.emplace_back(c[0], c[1], c[2]);
      }
    }
  } else {
    std::istringstream ls(data);
    std::string tok;
    while (ls >> tok) {
      if (tok == "vertex") {
        Eigen::Vector3d p;
        if (!(ls >> p.x() >> p.y() >> p.z())) fail(name, "malformed ASCII STL vertex");
        corners.push_back(p);
      }
    }
    if (corners.size() % 3 != 0) fail(name, "ASCII STL facet without 3 vertices");
  }
  // The merge below orders coordinates: a NaN would break the map's ordering, so refuse it here
  // (buildMesh would refuse it later anyway).
  for (size_t i = 0; i < corners.size(); ++i) {
    if (!corners[i].allFinite())
      fail(name, "facet " + std::to_string(i / 3) + " has a non-finite coordinate");
  }
  // STL repeats vertices per facet: merge identical coordinates so edges are shared.
  std::map<std::tuple<double, double, double>, int> ids;
  std::vector<Eigen::Vector3d> verts;
  std::vector<std::vector<int>> faces;
  faces.reserve(corners.size() / 3);
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
  return buildMesh(verts, faces, name);
}

}  // namespace

Mesh parseMesh(const std::string& bytes, MeshFormat format, const std::string& name) {
  switch (format) {
    case MeshFormat::kPly: return parsePly(bytes, name);
    case MeshFormat::kObj: return parseObj(bytes, name);
    case MeshFormat::kStl: return parseStl(bytes, name);
  }
  fail(name, "unknown mesh format");
}

Mesh loadMesh(const std::string& path) {
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : lower(path.substr(dot + 1));
  MeshFormat format;
  if (ext == "ply") {
    format = MeshFormat::kPly;
  } else if (ext == "obj") {
    format = MeshFormat::kObj;
  } else if (ext == "stl") {
    format = MeshFormat::kStl;
  } else {
    fail(path, "unsupported mesh format '" + ext + "' (use .ply, .obj or .stl)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) fail(path, "read error");
  return parseMesh(bytes.str(), format, path);
}

void saveMeshPly(const Mesh& mesh, const std::string& path, bool binary) {
  // Built in memory, then written by the output-file rules (output_file.h).
  std::ostringstream out(std::ios::binary);
  out.precision(std::numeric_limits<double>::max_digits10);  // ASCII: the doubles exactly
  // A list length of a byte holds 255: longer patches (a cylinder's cap of 256 sides) need more.
  size_t longest = 0;
  for (const auto& p : mesh.patches) longest = std::max(longest, p.size());
  const bool wide = longest > 255;
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
      << "element vertex " << mesh.vertices.size() << "\nproperty float x\nproperty float y\n"
      << "property float z\nelement face " << mesh.patches.size() << "\nproperty list "
      << (wide ? "uint" : "uchar") << " int vertex_indices\nend_header\n";
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
      if (wide) {
        const uint32_t c = static_cast<uint32_t>(p.size());
        out.write(reinterpret_cast<const char*>(&c), 4);
      } else {
        const unsigned char c = static_cast<unsigned char>(p.size());
        out.write(reinterpret_cast<const char*>(&c), 1);
      }
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
  try {
    writeOutputFile(path, out.str());
  } catch (const std::runtime_error& e) {
    fail(path, e.what());
  }
}

}  // namespace place_planner
