// The fuzz targets' bodies, shared by the libFuzzer binaries (fuzz_main.cpp, scripts/fuzz) and
// the gtest that replays the seed corpus and every past finding (test_fuzz_regressions.cpp).
// Each takes any bytes and returns normally; an input the code refuses in the documented way
// (MeshError, std::invalid_argument naming a field) is a normal return. A broken promise of
// the API (a mesh with an index out of range, a candidate with a NaN pose, ...) throws
// Violation, which libFuzzer reports as a crash and the gtest as a failure.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "place_planner/model/mesh.h"

namespace place_planner {
namespace fuzz {

struct Violation : std::logic_error {
  using std::logic_error::logic_error;
};

[[noreturn]] void violated(const std::string& what);  // throws Violation

// What mesh.h promises of a built mesh (indices in range, unit normals, finite properties).
void checkMesh(const Mesh& m);

// Reads values off the front of the input; past its end every value is 0 (so any length works).
class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  uint16_t u16() { return static_cast<uint16_t>(byte() | byte() << 8); }
  // In [lo, hi], 256 steps.
  double range(double lo, double hi) { return lo + (hi - lo) * byte() / 255.0; }
  int intIn(int lo, int hi) { return lo + static_cast<int>(u16() % static_cast<unsigned>(hi - lo + 1)); }
  bool flag() { return byte() & 1; }
  uint32_t u32() { return static_cast<uint32_t>(u16()) | static_cast<uint32_t>(u16()) << 16; }
  // Up to n bytes (fewer at the end of the input).
  std::string take(size_t n) {
    n = std::min(n, size_ - pos_);
    const std::string s(reinterpret_cast<const char*>(data_) + pos_, n);
    pos_ += n;
    return s;
  }
  std::string rest() {
    const std::string s(reinterpret_cast<const char*>(data_) + pos_, size_ - pos_);
    pos_ = size_;
    return s;
  }

 private:
  const uint8_t* data_;
  size_t size_, pos_ = 0;
};

// The whole input is a PLY file (header and data; the seeds are ASCII, mutations reach binary).
void plyText(const uint8_t* data, size_t size);
// The first bytes choose a binary PLY header (endianness, property types, counts); the rest is
// the data after end_header.
void plyBinary(const uint8_t* data, size_t size);
void obj(const uint8_t* data, size_t size);
void stl(const uint8_t* data, size_t size);
// A small object and area built from the bytes, random parameters, Planner::plan with a 200 ms
// budget on one thread; checks the result's promises (ranking, outcome, finite poses, ...).
void planner(const uint8_t* data, size_t size);

// Bugs found by fuzzing in code this suite does not fix are stepped around (so that fuzzing
// goes on to other bugs) while this is true, the default; the DISABLED_ replays of
// test_fuzz_regressions.cpp turn it off. Each workaround names its bug in fuzz_targets.cpp.
bool& skipKnownBugs();

#ifdef PP_FUZZ_WITH_ROS
// The node's PolygonMesh conversion (src/node/conversions.cpp fromMsg), on a message built from
// the bytes (any cloud layout, fields, polygons); a mesh it accepts goes back through toMsg.
// In fuzz_conversions.cpp: built only where ROS is (the catkin build, scripts/fuzz).
void polygonMesh(const uint8_t* data, size_t size);
// The shape_msgs/Mesh conversion (MoveIt's mesh type): raw float64 vertices, any indices.
void shapeMesh(const uint8_t* data, size_t size);
#endif

// The target of that name ("ply_text", "ply_binary", "obj", "stl", "planner", and
// "polygon_mesh" where ROS is), or nullptr.
using Target = void (*)(const uint8_t*, size_t);
Target targetByName(const std::string& name);

}  // namespace fuzz
}  // namespace place_planner
