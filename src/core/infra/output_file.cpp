// The output-file rules of infra/output_file.h.
#include "place_planner/infra/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace place_planner {
namespace {

std::runtime_error failure(const std::string& what, const std::string& path, int err) {
  return std::runtime_error(what + " " + path + ": " + std::strerror(err));
}

std::string dirOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string extensionOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return path.substr(dot);
}

// 0, or the errno of the write that failed.
int writeAll(int fd, const std::string& bytes) {
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : EIO;
    done += static_cast<size_t>(n);
  }
  return 0;
}

// A new file in `dir` named after `path`, created 0600 by mkstemps; `temp` receives its name.
int makeTemp(const std::string& path, std::string* temp) {
  const std::string ext = extensionOf(path);
  std::string name = path + ".tmp.XXXXXX" + ext;
  std::vector<char> buf(name.begin(), name.end());
  buf.push_back('\0');
  const int fd = mkstemps(buf.data(), static_cast<int>(ext.size()));
  if (fd < 0) throw failure("cannot create a file beside", path, errno);
  *temp = buf.data();
  return fd;
}

// The mode a plain open(O_CREAT) would give (0666 less the umask), or the replaced file's own.
mode_t modeFor(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode)) return st.st_mode & 07777;
  const mode_t mask = umask(0);
  umask(mask);
  return 0666 & ~mask;
}

// Renames the finished temporary file over `path`; removes it on failure.
void commit(const std::string& temp, const std::string& path) {
  int err = 0;
  if (chmod(temp.c_str(), modeFor(path)) != 0) err = errno;
  if (!err && rename(temp.c_str(), path.c_str()) != 0) err = errno;
  if (!err) return;
  unlink(temp.c_str());
  throw failure("cannot replace", path, err);
}

void writeInPlace(const OutputTarget& t, const std::string& bytes) {
  if (t.kind == OutputTarget::Kind::kStdout) {
    std::fflush(stdout);
    return writeOutputFd(STDOUT_FILENO, bytes, "standard output");
  }
  // No O_CREAT, no O_TRUNC: the device, FIFO or socket stays what it is.
  const int fd = open(t.path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) throw failure("cannot open", t.path, errno);
  int err = writeAll(fd, bytes);
  if (close(fd) != 0 && !err) err = errno;
  if (err) throw failure("cannot write", t.path, err);
}

}  // namespace

void writeOutputFd(int fd, const std::string& bytes, const std::string& name) {
  if (const int err = writeAll(fd, bytes)) throw failure("cannot write", name, err);
}

OutputTarget resolveOutput(const std::string& path) {
  OutputTarget t;
  if (path == "-") {
    t.kind = OutputTarget::Kind::kStdout;
    t.path = "-";
    return t;
  }
  if (path.empty()) throw std::runtime_error("empty output path");
  std::string p = path;
  for (int depth = 0; depth <= 40; ++depth) {
    struct stat st;
    if (lstat(p.c_str(), &st) != 0) {
      if (errno != ENOENT) throw failure("cannot inspect", p, errno);
      struct stat dst;
      const std::string dir = dirOf(p);
      if (stat(dir.c_str(), &dst) != 0 || !S_ISDIR(dst.st_mode))
        throw std::runtime_error("cannot write " + path + ": directory " + dir + " does not exist");
      t.kind = OutputTarget::Kind::kReplace;
      t.path = p;
      return t;
    }
    if (S_ISLNK(st.st_mode)) {
      std::vector<char> buf(static_cast<size_t>(st.st_size > 0 ? st.st_size : 4095) + 1);
      const ssize_t n = readlink(p.c_str(), buf.data(), buf.size() - 1);
      if (n < 0) throw failure("cannot read the link", p, errno);
      const std::string target(buf.data(), static_cast<size_t>(n));
      p = !target.empty() && target[0] == '/' ? target : dirOf(p) + "/" + target;
      continue;
    }
    if (S_ISDIR(st.st_mode)) throw std::runtime_error("cannot write " + path + ": it is a directory");
    if (S_ISBLK(st.st_mode))
      throw std::runtime_error("cannot write " + path + ": it is a block device (refused: a disk is never an output)");
    t.kind = S_ISREG(st.st_mode) ? OutputTarget::Kind::kReplace : OutputTarget::Kind::kInPlace;
    t.path = p;
    return t;
  }
  throw std::runtime_error("cannot write " + path + ": more than 40 symbolic links");
}

void writeOutputFile(const std::string& path, const std::string& bytes) {
  const OutputTarget t = resolveOutput(path);
  if (t.kind != OutputTarget::Kind::kReplace) return writeInPlace(t, bytes);
  std::string temp;
  const int fd = makeTemp(t.path, &temp);
  int err = writeAll(fd, bytes);
  if (!err && fsync(fd) != 0) err = errno;
  if (close(fd) != 0 && !err) err = errno;
  if (err) {
    unlink(temp.c_str());
    throw failure("cannot write", t.path, err);
  }
  commit(temp, t.path);
}

void produceOutputFile(const std::string& path, const std::function<void(const std::string&)>& produce) {
  const OutputTarget t = resolveOutput(path);
  // The temporary file sits beside the final target (for "-" or a device: beside nothing
  // there, so in the system's temporary directory).
  const std::string beside = t.kind == OutputTarget::Kind::kReplace
                                 ? t.path
                                 : std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") +
                                       "/place_planner_output" + extensionOf(path);
  std::string temp;
  close(makeTemp(beside, &temp));
  try {
    produce(temp);
  } catch (...) {
    unlink(temp.c_str());
    throw;
  }
  if (t.kind == OutputTarget::Kind::kReplace) return commit(temp, t.path);
  std::ifstream in(temp, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  unlink(temp.c_str());
  writeInPlace(t, bytes.str());
}

}  // namespace place_planner
