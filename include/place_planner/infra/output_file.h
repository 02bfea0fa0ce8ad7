// Files the project writes (the CLI's JSON, the suite's CSV and plots, the bench, the demo bag):
// one rule for all of them, so that an output path never destroys what it names.
//
//   path                               what happens
//   "-"                                written to standard output
//   a new name, or a regular file      written whole to a temporary file beside it, flushed, then
//                                      renamed over it (atomic: a reader sees old or new, never half)
//   a symlink (any depth)              followed; its final target is replaced as above, in the
//                                      target's directory, so the link stays a link
//   a character device, FIFO, socket   written in place (never replaced): /dev/null, /dev/stdout, a
//                                      named pipe with a reader
//   a directory                        an error, before anything is written
//
// Errors throw std::runtime_error with the path and the system's reason; the path is then as it
// was (a temporary file is removed).
#pragma once

#include <functional>
#include <string>

namespace place_planner {

// Where an output path leads, decided without writing anything.
struct OutputTarget {
  enum class Kind { kStdout, kReplace, kInPlace };
  Kind kind = Kind::kReplace;
  std::string path;  // the path written (a symlink resolved to its final target)
};

// Resolves `path` (see the table above). Throws std::runtime_error for a directory, a dangling
// chain of more than 40 links, or a directory that does not exist.
OutputTarget resolveOutput(const std::string& path);

// Writes `bytes` whole to an open descriptor (retrying short writes); `name` is for the error.
// Throws std::runtime_error.
void writeOutputFd(int fd, const std::string& bytes, const std::string& name);

// Writes `bytes` to `path` by the rules above.
void writeOutputFile(const std::string& path, const std::string& bytes);

// For libraries that write a file by name themselves (OpenCV's imwrite, rosbag): `produce` is
// called with a temporary path in the target's directory (same extension as `path`, so format
// detection by extension still works) and must write the file there; it is then put in place by
// the rules above. A temporary file left by a failing `produce` is removed.
void produceOutputFile(const std::string& path, const std::function<void(const std::string&)>& produce);

}  // namespace place_planner
