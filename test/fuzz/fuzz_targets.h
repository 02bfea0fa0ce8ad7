// The fuzz targets' bodies, shared by the libFuzzer binaries (fuzz_main.cpp, scripts/fuzz) and
// the gtest that replays the seed corpus and every past finding (test_fuzz_regressions.cpp).
// Each takes any bytes and returns normally; an input the code refuses in the documented way
// (MeshError, std::invalid_argument naming a field) is a normal return. A broken promise of
// the API (a mesh with an index out of range, a candidate with a NaN pose, ...) throws
// Violation, which libFuzzer reports as a crash and the gtest as a failure.
#pragma once
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace place_planner {
namespace fuzz {

struct Violation : std::logic_error {
  using std::logic_error::logic_error;
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

// The target of that name ("ply_text", "ply_binary", "obj", "stl", "planner"), or nullptr.
using Target = void (*)(const uint8_t*, size_t);
Target targetByName(const std::string& name);

}  // namespace fuzz
}  // namespace place_planner
