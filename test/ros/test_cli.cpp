// place_planner_cli as a script sees it: the exit code, the last line of stdout ("outcome: ..."),
// the error line on stderr, and the JSON file (parsed, never matched as text). Runs the built
// binary (PP_CLI_BINARY) on built-in scenes and on a steep slope written to a temporary PLY file.
#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "place_planner/infra/cuda_backend.h"
#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/scenes.h"

namespace place_planner {
namespace {

using nlohmann::json;

struct CliRun {
  int code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
  std::string last_line;
};

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A fresh directory of this test process.
std::string tempDir(const std::string& name) {
  const std::string d = "/tmp/pp_cli_test_" + std::to_string(getpid()) + "_" + name;
  mkdir(d.c_str(), 0755);
  return d;
}

std::vector<std::string> listDir(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") names.push_back(n);
    }
    closedir(d);
  }
  return names;
}

// Runs the CLI with exactly these arguments (no shell: any bytes may be in a path), under
// `timeout 120`. `shell_script` (optional) is a bash script that runs the command line "$@".
// From the principal axis unless args say otherwise: the cube then rests on a face whatever the
// auto mode's order (these tests are about codes, lines and files, not start orientations).
CliRun cli(std::vector<std::string> args, const std::string& shell_script = "") {
  bool has_orientation = false;
  for (const auto& a : args) has_orientation |= a == "--orientation" || a == "--help";
  if (!has_orientation) args.insert(args.end(), {"--orientation", "principal_axis"});
  std::vector<std::string> argv;
  if (!shell_script.empty()) argv = {"/bin/bash", "-c", shell_script, "bash"};
  argv.insert(argv.end(), {"timeout", "120", PP_CLI_BINARY});
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);

  char out_name[] = "/tmp/pp_cli_out_XXXXXX";
  char err_name[] = "/tmp/pp_cli_err_XXXXXX";
  const int out_fd = mkstemp(out_name), err_fd = mkstemp(err_name);
  CliRun r;
  EXPECT_GE(out_fd, 0);
  EXPECT_GE(err_fd, 0);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out_fd, 1);
    dup2(err_fd, 2);
    execvp(cargv[0], cargv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  close(out_fd);
  close(err_fd);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = readFile(out_name);
  r.err = readFile(err_name);
  std::remove(out_name);
  std::remove(err_name);
  std::istringstream is(r.out);
  for (std::string line; std::getline(is, line);) {
    if (!line.empty()) r.last_line = line;
  }
  return r;
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::string tempPath(const std::string& name) {
  return "/tmp/pp_cli_test_" + std::to_string(getpid()) + "_" + name;
}

// A 1 x 1 m plane tilted 40 degrees: with mu = 0.05 (tan 40 = 0.84) nothing can rest on it.
std::string steepSlope() {
  static const std::string path = [] {
    const std::string p = tempPath("slope40.ply");
    saveMeshPly(scenes::plane(1.0, 1.0, 40.0), p);
    return p;
  }();
  return path;
}

const std::vector<std::string> kCubeOnTable = {"--object", "builtin:cube", "--area", "builtin:table"};

std::vector<std::string> cubeOnTable(const std::vector<std::string>& more) {
  std::vector<std::string> a = kCubeOnTable;
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

// --verify-engines both: each checked candidate simulated in Bullet and in MuJoCo, each engine's
// verdict in the JSON (a cube on its face stays in both); by default Bullet alone.
TEST(PlacePlannerCli, VerifyInBothEnginesReportsEachVerdict) {
  const CliRun r = cli(cubeOnTable({"--verify", "1", "--verify-engines", "both", "--json", "-"}));
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(json::accept(r.out)) << r.out.substr(0, 200);
  const json best = json::parse(r.out).at("candidates").at(0).at("physics");
  EXPECT_TRUE(best.at("checked").get<bool>());
  EXPECT_TRUE(best.at("bullet").at("checked").get<bool>());
  EXPECT_TRUE(best.at("mujoco").at("checked").get<bool>());
  EXPECT_TRUE(best.at("bullet").at("stayed").get<bool>());
  EXPECT_TRUE(best.at("mujoco").at("stayed").get<bool>());
  EXPECT_LT(best.at("mujoco").at("moved_m").get<double>(), 0.01);
  EXPECT_TRUE(best.at("stayed").get<bool>());
  EXPECT_TRUE(contains(r.err, "physics (Bullet and MuJoCo): 1 of 1 checked, 1 stayed")) << r.err;
  EXPECT_TRUE(contains(r.err, "Bullet kept 1, MuJoCo kept 1 of 1")) << r.err;
  // Bullet alone (the default): MuJoCo not asked.
  const CliRun b = cli(cubeOnTable({"--verify", "1", "--json", "-"}));
  ASSERT_TRUE(json::accept(b.out)) << b.out.substr(0, 200);
  const json only = json::parse(b.out).at("candidates").at(0).at("physics");
  EXPECT_TRUE(only.at("bullet").at("checked").get<bool>());
  EXPECT_FALSE(only.at("mujoco").at("checked").get<bool>());
}

TEST(PlacePlannerCli, StablePoseExitsZeroWithOutcomeLineAndVerifiedTopTwo) {
  const std::string path = tempPath("cube_table.json");
  const CliRun r = cli(cubeOnTable({"--verify", "2", "--json", path}));
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(startsWith(r.last_line, "outcome: stable (")) << r.last_line;
  EXPECT_TRUE(contains(r.out, "physics")) << "no physics column";
  EXPECT_TRUE(contains(r.out, "robust")) << "no robustness column";
  const json j = json::parse(readFile(path));
  std::remove(path.c_str());
  EXPECT_EQ(j.at("outcome"), "stable");
  EXPECT_EQ(j.at("object"), "builtin:cube");
  EXPECT_EQ(j.at("gravity"), json::array({0.0, 0.0, -1.0}));
  const json& k = j.at("candidates");
  ASSERT_GE(k.size(), 2u) << "the cube on the table has at least two stable candidates";
  EXPECT_GT(j.at("stable_candidates").get<int>(), 0);
  // The trees' statistics: poses evaluated, none cut while tilting (a cube lands on a face).
  EXPECT_GT(j.at("tree_nodes").get<long>(), 0);
  EXPECT_EQ(j.at("trees_without_rest").get<int>(), 0);
  EXPECT_EQ(j.at("roll_bottoms").get<int>(), 0);
  EXPECT_EQ(j.at("trees_fallen").get<int>(), 0) << "released over the table, no cube goes over its edge";
  // In rank order: the best two were simulated and a cube resting on a face of the table
  // stays put; the third (if any) was not simulated.
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(k[i].at("physics").at("checked").get<bool>()) << "candidate " << i + 1;
    EXPECT_TRUE(k[i].at("physics").at("stayed").get<bool>()) << "candidate " << i + 1;
    EXPECT_EQ(k[i].at("orientation_xyzw").size(), 4u);
    EXPECT_EQ(k[i].at("position").size(), 3u);
  }
  if (k.size() > 2) EXPECT_FALSE(k[2].at("physics").at("checked").get<bool>());
}

TEST(PlacePlannerCli, NothingStableOnSteepSlopeExitsOne) {
  const CliRun r = cli({"--object", "builtin:cube", "--area", steepSlope(), "--friction", "0.05"});
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_TRUE(startsWith(r.last_line, "outcome: no_stable_pose")) << r.last_line;
}

// The slope again, with a fine grid of floor points that cannot be searched in 0.01 ms: the
// budget runs out with nothing stable.
TEST(PlacePlannerCli, TimeoutWithNothingStableExitsThree) {
  const CliRun r = cli({"--object", "builtin:cube", "--area", steepSlope(), "--friction", "0.05", "--spacing",
                        "0.01", "--budget-ms", "0.01"});
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_TRUE(startsWith(r.last_line, "outcome: timed_out (")) << r.last_line;
}

// 1 cm floor points on the table (thousands: seconds of search); the first stable pose comes
// within milliseconds, so 300 ms end with a partial answer.
TEST(PlacePlannerCli, TimeoutWithStableIsPartialAndExitsZero) {
  const CliRun r = cli(cubeOnTable({"--spacing", "0.01", "--budget-ms", "300"}));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(startsWith(r.last_line, "outcome: timed_out_partial (")) << r.last_line;
  EXPECT_TRUE(contains(r.out, "\npartial answer: ")) << r.out;
}

// Whatever a tiny budget leaves, the code and the line agree: 0 with a partial answer or 3.
TEST(PlacePlannerCli, TinyBudgetIsPartialOrTimedOutNeverElse) {
  const CliRun r = cli(cubeOnTable({"--budget-ms", "1"}));
  if (r.code == 0) {
    EXPECT_TRUE(startsWith(r.last_line, "outcome: timed_out_partial (")) << r.last_line;
  } else {
    EXPECT_EQ(r.code, 3) << r.out;
    EXPECT_TRUE(startsWith(r.last_line, "outcome: timed_out (")) << r.last_line;
  }
}

// Each bad input exits 2 with "outcome: bad_input" last and an error line naming what is wrong.
TEST(PlacePlannerCli, BadInputExitsTwoNamingTheFlag) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {cubeOnTable({"--friction", "abc"}), "--friction"},
      {cubeOnTable({"--friction", "nan"}), "--friction"},
      {cubeOnTable({"--robust-shift", "1.0"}), "--robust-shift"},  // out of range (validate)
      {cubeOnTable({"--spacing", "0"}), "--spacing"},
      {cubeOnTable({"--gravity", "0,0,0"}), "--gravity"},
      {cubeOnTable({"--gravity", "1,2"}), "--gravity"},
      {cubeOnTable({"--approach", "x,y,z"}), "--approach"},
      {cubeOnTable({"--orientation", "upside_down"}), "--orientation"},
      {cubeOnTable({"--backend", "quantum"}), "--backend"},
      {cubeOnTable({"--verify", "-1"}), "--verify"},
      {cubeOnTable({"--verify", "1", "--verify-engines", "havok"}), "--verify-engines"},
      {cubeOnTable({"--no-such-option", "1"}), "--no-such-option"},
      {{"--object", "builtin:cube"}, "--area"},
      {{"--object", "builtin:nothing", "--area", "builtin:table"}, "--object"},
      {{"--object", "builtin:cube", "--area", "/nonexistent/area.ply"}, "/nonexistent/area.ply"},
  };
  for (const auto& [args, named] : cases) {
    const CliRun r = cli(args);
    std::string line;
    for (const auto& a : args) line += a + " ";
    EXPECT_EQ(r.code, 2) << line << "\n" << r.out;
    EXPECT_EQ(r.last_line, "outcome: bad_input") << line;
    EXPECT_TRUE(contains(r.err, "error: ")) << line << ": " << r.err;
    EXPECT_TRUE(contains(r.err, named)) << line << ": the error does not name " << named << ": " << r.err;
  }
}

// Integer options take integers: no rounding of 2.5, no wrap-around of 10^11, named in the error.
TEST(PlacePlannerCli, BadIntegerNamesTheFlag) {
  for (const std::string flag : {"--max-rotations", "--max-resting-faces", "--max-candidates", "--threads", "--verify"}) {
    for (const std::string value : {"2.5", "99999999999", "3x", "abc"}) {
      const CliRun r = cli(cubeOnTable({flag, value}));
      EXPECT_EQ(r.code, 2) << flag << " " << value << "\n" << r.out;
      EXPECT_EQ(r.last_line, "outcome: bad_input") << flag << " " << value;
      EXPECT_TRUE(contains(r.err, flag)) << flag << " " << value << ": " << r.err;
    }
  }
}

TEST(PlacePlannerCli, EveryOptionIsAccepted) {
  const std::string path = tempPath("all_options.json");
  const CliRun r = cli(cubeOnTable({"--gravity", "0,0,-2", "--approach", "0,0,-1", "--friction", "0.5", "--spacing",
                                    "0.2", "--max-rotations", "4", "--orientation", "auto", "--max-resting-faces", "3",
                                    "--robust-shift", "0.002", "--robust-tilt-deg", "2", "--robust-com-offset", "0.02",
                                    "--robust-min-share", "0.9", "--budget-ms", "20000", "--max-candidates", "3",
                                    "--threads", "1", "--backend", "cpu", "--verify", "1", "--json", path}));
  // Accepted (not 2); whether the auto start finds the cube's faces is the core's business.
  EXPECT_TRUE(r.code == 0 || r.code == 1) << r.out << r.err;
  EXPECT_TRUE(startsWith(r.last_line, r.code == 0 ? "outcome: stable (" : "outcome: no_stable_pose")) << r.last_line;
  EXPECT_TRUE(contains(r.out, "orientation auto")) << r.out;
  const json j = json::parse(readFile(path));
  std::remove(path.c_str());
  EXPECT_EQ(j.at("backend"), "cpu");
  EXPECT_LE(j.at("candidates").size(), 3u) << "--max-candidates 3";
  EXPECT_EQ(j.at("gravity"), json::array({0.0, 0.0, -2.0})) << "as given, the planner normalises";

  const CliRun no_robust = cli(cubeOnTable({"--no-robust-check", "--gravity", "auto"}));
  EXPECT_EQ(no_robust.code, 0) << no_robust.out << no_robust.err;
  // The table's top faces up: gravity straight down (the signs of the zeros vary).
  EXPECT_TRUE(contains(no_robust.out, "gravity (auto): (")) << no_robust.out;
  EXPECT_TRUE(contains(no_robust.out, ".000, -1.000), the largest flat region")) << no_robust.out;
  // Not checked: the robustness column says so.
  EXPECT_FALSE(contains(no_robust.out, "/12")) << no_robust.out;
}

TEST(PlacePlannerCli, HelpListsEveryOptionAndTheExitCodes) {
  const CliRun r = cli({"--help"});
  EXPECT_EQ(r.code, 0);
  for (const std::string flag :
       {"--object", "--area", "--gravity", "--approach", "--friction", "--spacing", "--max-rotations", "--orientation",
        "--max-resting-faces", "--robust-shift", "--robust-tilt-deg", "--robust-com-offset", "--robust-min-share", "--robust-min-share-hanging",
        "--no-robust-check", "--budget-ms", "--max-candidates", "--threads", "--backend", "--verify", "--json"}) {
    EXPECT_TRUE(contains(r.out, flag)) << flag;
  }
  for (const std::string code : {"  0  stable", "  1  the search completed", "  2  bad input", "  3  the budget",
                                 "  4  planned, but the --json"}) {
    EXPECT_TRUE(contains(r.out, code)) << code << "\n" << r.out;
  }
}

// gpu means cuda: never a silent fall-back to the CPU.
TEST(PlacePlannerCli, BackendGpuIsCudaOrAnError) {
  std::string why;
  const bool have_cuda = cuda::available(&why);
  for (const std::string name : {"gpu", "cuda"}) {
    const std::string path = tempPath("backend.json");
    const CliRun r = cli(cubeOnTable({"--backend", name, "--no-robust-check", "--json", path}));
    if (have_cuda) {
      EXPECT_EQ(r.code, 0) << r.err;
      EXPECT_EQ(json::parse(readFile(path)).at("backend"), "cuda");
    } else {
      EXPECT_EQ(r.code, 2) << name << ": " << r.out;
      EXPECT_TRUE(contains(r.err, "--backend " + name + ": the CUDA backend is unavailable")) << r.err;
      EXPECT_FALSE(contains(r.out, "CPU backend")) << "planned on the CPU anyway";
    }
    std::remove(path.c_str());
  }
}

// Six processes write one path at once while this test reads it: every read is a whole JSON
// document (the old file or a new one), never a prefix, and no temporary file is left.
TEST(PlacePlannerCli, ConcurrentWritesToOneJsonPathAlwaysLeaveValidJson) {
  const std::string dir = tempDir("concurrent");
  const std::string path = dir + "/out.json";
  std::atomic<bool> done{false};
  int reads = 0, broken = 0;
  std::string broken_sample;
  std::thread reader([&] {
    while (!done) {
      std::ifstream in(path, std::ios::binary);
      if (in) {
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ++reads;
        if (!json::accept(text)) {
          ++broken;
          broken_sample = text.substr(0, 120) + " ... (" + std::to_string(text.size()) + " bytes)";
        }
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  std::vector<std::thread> writers;
  std::vector<CliRun> runs(6);
  for (int i = 0; i < 6; ++i) {
    writers.emplace_back([&, i] {
      runs[i] = cli(cubeOnTable({"--no-robust-check", "--threads", "1", "--max-candidates", std::to_string(i + 3),
                                 "--json", path}));
    });
  }
  for (auto& w : writers) w.join();
  done = true;
  reader.join();
  for (const auto& r : runs) EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(broken, 0) << broken << " of " << reads << " reads were not valid JSON, e.g. " << broken_sample;
  EXPECT_GT(reads, 0);
  const json j = json::parse(readFile(path));
  EXPECT_EQ(j.at("outcome"), "stable");
  EXPECT_EQ(listDir(dir), std::vector<std::string>{"out.json"}) << "temporary files left behind";
  std::remove(path.c_str());
  rmdir(dir.c_str());
}

// A destination that cannot be written is bad input, found before any planning.
TEST(PlacePlannerCli, UnwritableJsonPathExitsTwoBeforePlanning) {
  const std::string dir = tempDir("unwritable");
  for (const std::string path : {std::string("/nonexistent/dir/out.json"), dir}) {
    const CliRun r = cli(cubeOnTable({"--json", path}));
    EXPECT_EQ(r.code, 2) << path << ": " << r.out;
    EXPECT_EQ(r.last_line, "outcome: bad_input") << path;
    EXPECT_TRUE(contains(r.err, "--json")) << r.err;
    EXPECT_TRUE(contains(r.err, path)) << r.err;
    EXPECT_FALSE(contains(r.out, "floor points")) << "it planned first: " << r.out;
  }
  rmdir(dir.c_str());
}

// A write that fails after planning (the disk fills: here a 1 KiB file size limit, EFBIG) exits
// 4 with "outcome: output_error"; the file that was there is left whole, and no temporary file.
TEST(PlacePlannerCli, WriteFailureExitsFourAndKeepsTheOldFile) {
  const std::string dir = tempDir("full");
  const std::string path = dir + "/out.json";
  const std::string old_text = "{\"old\": true}\n";
  std::ofstream(path) << old_text;
  // SIGXFSZ ignored, so the write returns EFBIG instead of killing the process; the limit only
  // for the CLI, whose stdout goes through cat to the (unlimited) capture file.
  const CliRun r = cli(cubeOnTable({"--no-robust-check", "--json", path}),
                       "trap '' XFSZ; (ulimit -f 1; exec \"$@\") | cat; exit ${PIPESTATUS[0]}");
  EXPECT_EQ(r.code, 4) << r.out << r.err;
  EXPECT_EQ(r.last_line, "outcome: output_error");
  EXPECT_TRUE(contains(r.err, "cannot write " + path)) << r.err;
  EXPECT_TRUE(contains(r.out, "floor points")) << "the plan ran and was reported: " << r.out;
  EXPECT_EQ(readFile(path), old_text);
  EXPECT_EQ(listDir(dir), std::vector<std::string>{"out.json"}) << "temporary files left behind";
  std::remove(path.c_str());
  rmdir(dir.c_str());
}

// The output-file rules (infra/output_file.h) as a user meets them: a device, a FIFO, a symlink,
// "-" and a directory given to --json each end as documented, never replaced by a regular file.
TEST(PlacePlannerCli, JsonToACharacterDeviceWritesInPlace) {
  const std::string dir = tempDir("device");
  const std::string null_dev = dir + "/null", full_dev = dir + "/full";
  // Private copies of /dev/null (1,3) and /dev/full (1,7): the real ones are never risked.
  if (mknod(null_dev.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0 ||
      mknod(full_dev.c_str(), S_IFCHR | 0666, makedev(1, 7)) != 0) {
    rmdir(dir.c_str());
    GTEST_SKIP() << "mknod needs root (CAP_MKNOD): " << std::strerror(errno);
  }
  const CliRun ok = cli(cubeOnTable({"--no-robust-check", "--json", null_dev}));
  EXPECT_EQ(ok.code, 0) << ok.err;
  const CliRun full = cli(cubeOnTable({"--no-robust-check", "--json", full_dev}));
  EXPECT_EQ(full.code, 4) << full.err;
  EXPECT_EQ(full.last_line, "outcome: output_error");
  EXPECT_TRUE(contains(full.err, "No space left on device")) << full.err;
  for (const std::string& d : {null_dev, full_dev}) {
    struct stat st;
    ASSERT_EQ(lstat(d.c_str(), &st), 0) << d;
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << d << " is no longer a character device";
    std::remove(d.c_str());
  }
  EXPECT_TRUE(listDir(dir).empty()) << "temporary files left behind";
  rmdir(dir.c_str());
}

TEST(PlacePlannerCli, JsonToAFifoReachesItsReader) {
  const std::string dir = tempDir("fifo");
  const std::string fifo = dir + "/answer";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  std::string got;
  std::thread reader([&] { got = readFile(fifo); });  // opens (blocks) until the CLI writes
  const CliRun r = cli(cubeOnTable({"--no-robust-check", "--json", fifo}));
  reader.join();
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(json::accept(got)) << "the reader got: " << got.substr(0, 200);
  EXPECT_EQ(json::parse(got).at("outcome"), "stable");
  struct stat st;
  ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO was replaced";
  std::remove(fifo.c_str());
  EXPECT_TRUE(listDir(dir).empty()) << "temporary files left behind";
  rmdir(dir.c_str());
}

TEST(PlacePlannerCli, JsonThroughASymlinkReplacesItsTarget) {
  const std::string dir = tempDir("symlink");
  mkdir((dir + "/results").c_str(), 0755);
  const std::string target = dir + "/results/run1.json", link = dir + "/out.json";
  std::ofstream(target) << "{\"old\": true}\n";
  ASSERT_EQ(symlink("results/run1.json", link.c_str()), 0);
  const CliRun r = cli(cubeOnTable({"--no-robust-check", "--json", link}));
  EXPECT_EQ(r.code, 0) << r.err;
  struct stat st;
  ASSERT_EQ(lstat(link.c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode)) << "the link was replaced by a file";
  const json j = json::parse(readFile(target));
  EXPECT_EQ(j.at("outcome"), "stable") << "the target keeps the old answer";
  EXPECT_EQ(listDir(dir + "/results"), std::vector<std::string>{"run1.json"}) << "temporary files left";
  std::remove(link.c_str());
  std::remove(target.c_str());
  rmdir((dir + "/results").c_str());
  rmdir(dir.c_str());
}

TEST(PlacePlannerCli, JsonDashGoesToStdoutAndTheReportToStderr) {
  const CliRun r = cli(cubeOnTable({"--no-robust-check", "--json", "-"}));
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(json::accept(r.out)) << "stdout is not the JSON alone: " << r.out.substr(0, 200);
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("outcome"), "stable");
  EXPECT_GT(j.at("candidates").size(), 0u);
  EXPECT_TRUE(contains(r.err, "outcome: stable")) << r.err;
  EXPECT_TRUE(contains(r.err, "floor points")) << r.err;
}

// --placement: a ring on the wall of pegs hangs, and the JSON and the table say so; standing
// only, it does not; an unknown kind is bad input naming the option.
TEST(PlacePlannerCli, PlacementHangingIsChosenAndReported) {
  const CliRun r = cli({"--object", "builtin:ring", "--area", "builtin:peg_wall", "--placement", "hanging", "--threads",
                        "2", "--json", "-"});
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(json::accept(r.out)) << r.out.substr(0, 200);
  const json j = json::parse(r.out);
  ASSERT_GT(j.at("candidates").size(), 0u);
  EXPECT_EQ(j.at("candidates")[0].at("kind"), "hanging");
  EXPECT_EQ(j.at("candidates")[0].at("start"), "loop_on_peg");
  EXPECT_TRUE(contains(r.err, "hanging: 6 pegs on the area, 1 loops of the object")) << r.err;
  // Its roots are the threaded starts, all searched; the floor points are not.
  const int starts = j.at("hanging_starts");
  EXPECT_GT(starts, 0);
  EXPECT_EQ(j.at("hanging_starts_done"), starts);
  EXPECT_TRUE(contains(r.err, "floor points not searched")) << r.err;
  EXPECT_TRUE(contains(r.err, "threaded starts (" + std::to_string(starts) + " searched)")) << r.err;
  const CliRun standing = cli({"--object", "builtin:ring", "--area", "builtin:peg_wall", "--placement", "standing",
                               "--threads", "2", "--json", "-"});
  ASSERT_TRUE(json::accept(standing.out)) << standing.out.substr(0, 200);
  for (const json& c : json::parse(standing.out).at("candidates")) EXPECT_EQ(c.at("kind"), "standing");
  const CliRun bad = cli(cubeOnTable({"--placement", "dangling"}));
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.out + bad.err, "--placement")) << bad.out << bad.err;
}

// Without a GPU `auto` plans on the CPU: named once in the times block, no warning; -v says why.
TEST(PlacePlannerCli, CpuBackendIsNamedOnceAndNotAWarning) {
  std::string why;
  if (cuda::available(&why)) GTEST_SKIP() << "a GPU is usable here: auto plans on CUDA";
  const CliRun r = cli(cubeOnTable({"--no-robust-check"}));
  EXPECT_EQ(r.code, 0) << r.err;
  size_t n = 0;
  for (size_t at = r.out.find("CPU backend"); at != std::string::npos; at = r.out.find("CPU backend", at + 1)) ++n;
  EXPECT_EQ(n, 1u) << r.out;
  EXPECT_FALSE(contains(r.err, "GPU")) << r.err;
  EXPECT_FALSE(contains(r.err, "warning")) << r.err;
  const CliRun v = cli(cubeOnTable({"--no-robust-check", "-v"}));
  EXPECT_EQ(v.code, 0) << v.err;
  EXPECT_TRUE(contains(v.err, "backend auto: the CPU")) << v.err;
}

// Progress on standard error while a plan runs longer than a second, only when it is a terminal
// (under script(1) here); piped, standard error stays clean.
TEST(PlacePlannerCli, ProgressOnATerminalOnlyForLongPlans) {
  if (access("/usr/bin/script", X_OK) != 0) GTEST_SKIP() << "script(1) (bsdutils) is not installed: no pseudo-terminal";
  // About 3 s on one thread: the default search over 5000 floor points.
  const std::vector<std::string> slow = {"--object", "builtin:mug", "--area", "builtin:table", "--spacing", "0.01",
                                         "--threads", "1", "--orientation", "auto"};
  const CliRun tty = cli(slow, "exec script -qec \"$(printf '%q ' \"$@\")\" /dev/null");
  EXPECT_EQ(tty.code, 0) << tty.out;
  EXPECT_TRUE(contains(tty.out, "planning: floor points")) << tty.out.substr(0, 400);
  EXPECT_TRUE(contains(tty.out, "stable so far")) << tty.out.substr(0, 400);
  const CliRun piped = cli(slow);
  EXPECT_EQ(piped.code, 0) << piped.err;
  EXPECT_FALSE(contains(piped.err, "planning:")) << piped.err;
}

// Paths are bytes: quotes, backslashes and control characters are escaped; bytes that are not
// UTF-8 become U+FFFD. The file always parses.
TEST(PlacePlannerCli, JsonEscapesOddStrings) {
  const std::string dir = tempDir("odd names");
  const std::string quoted = dir + "/cu\"be\\ \t'x'.ply";
  const std::string latin1 = dir + "/w\xfcrfel.ply";  // ISO 8859-1, not UTF-8
  saveMeshPly(scenes::box(0.05, 0.05, 0.05), quoted);
  saveMeshPly(scenes::box(0.05, 0.05, 0.05), latin1);
  const std::string path = dir + "/out.json";
  CliRun r = cli({"--object", quoted, "--area", "builtin:table", "--no-robust-check", "--json", path});
  EXPECT_EQ(r.code, 0) << r.err;
  json j = json::parse(readFile(path));
  EXPECT_EQ(j.at("object"), quoted);
  r = cli({"--object", latin1, "--area", "builtin:table", "--no-robust-check", "--json", path});
  EXPECT_EQ(r.code, 0) << r.err;
  j = json::parse(readFile(path));
  EXPECT_EQ(j.at("object"), dir + "/w\xef\xbf\xbdrfel.ply");
  for (const auto& p : {quoted, latin1, path}) std::remove(p.c_str());
  rmdir(dir.c_str());
}

// A two-finger gripper of boxes, written for the test: palm frame F at the palm's inner face,
// z towards the fingertips (5 cm), fingers closing along y.
std::string boxGripperUrdf() {
  static const std::string path = [] {
    const std::string p = tempPath("gripper.urdf");
    std::ofstream(p) << R"(<robot name="g">
  <link name="palm"><collision><origin xyz="0 0 -0.01"/><geometry><box size="0.04 0.13 0.02"/></geometry></collision></link>
  <link name="finger"><collision><origin xyz="0 0.004 0.025"/><geometry><box size="0.02 0.008 0.05"/></geometry></collision></link>
  <joint name="finger_joint" type="prismatic"><parent link="palm"/><child link="finger"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.06" effort="1" velocity="1"/></joint>
</robot>)";
    return p;
  }();
  return path;
}

TEST(PlacePlannerCli, GripperFlagsGivePlaceLocationFieldsAndABlockingGraspNoStablePose) {
  const std::string path = tempPath("gripper.json");
  // The built-in cube (10 cm, base at z = 0) held from above: F 1 cm over its top, z down.
  const std::vector<std::string> gripper = {"--urdf", boxGripperUrdf(), "--gripper-links", "palm,finger",
                                            "--gripper-joint", "finger_joint=0.055"};
  std::vector<std::string> args = cubeOnTable(gripper);
  args.insert(args.end(), {"--grasp", "0,0,0.11,1,0,0,0", "--max-candidates", "3", "--json", path});
  const CliRun r = cli(args);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const json j = json::parse(readFile(path));
  std::remove(path.c_str());
  ASSERT_FALSE(j.at("candidates").empty());
  for (const json& c : j.at("candidates")) {
    const json& p = c.at("placement");
    EXPECT_TRUE(p.at("checked").get<bool>());
    EXPECT_EQ(p.at("blocked"), "");
    ASSERT_TRUE(p.contains("gripper_pose")) << "a grasp gives the gripper's pose";
    EXPECT_GE(p.at("gripper_clearance").get<double>(), 0.001);
    // Straight approach from 10 cm above: pre-place = goal - 0.1 * direction (0, 0, -1).
    EXPECT_TRUE(p.at("straight_approach").get<bool>());
    EXPECT_NEAR(p.at("pre_place").at("position")[2].get<double>() - c.at("position")[2].get<double>(), 0.1, 1e-9);
    EXPECT_GE(p.at("approach").at("free_distance").get<double>(), p.at("approach").at("min_distance").get<double>());
    EXPECT_GE(p.at("retreat_in_gripper_frame").at("free_distance").get<double>(), 0.03);
  }
  // Fingertips 2 cm below the cube's base: every pose with the gripper from above collides.
  std::vector<std::string> blocked = cubeOnTable(gripper);
  blocked.insert(blocked.end(), {"--grasp", "0,0,0.03,1,0,0,0"});
  const CliRun b = cli(blocked);
  EXPECT_EQ(b.code, 1) << b.out << b.err;
  EXPECT_TRUE(startsWith(b.last_line, "outcome: no_stable_pose")) << b.last_line;
  EXPECT_TRUE(contains(b.err, "gripper")) << b.err;
  // The gripper flags go together, and a bad link is named.
  EXPECT_EQ(cli(cubeOnTable({"--urdf", boxGripperUrdf(), "--grasp", "0,0,0.11,1,0,0,0"})).code, 2);
  const CliRun bad = cli(cubeOnTable({"--urdf", boxGripperUrdf(), "--gripper-links", "palm,thumb", "--grasp",
                                      "0,0,0.11,1,0,0,0"}));
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.err, "no link 'thumb'")) << bad.err;
}

TEST(PlacePlannerCli, MillimetreMeshIsBadInputNamingTheUnitAndLimitsAreFlags) {
  const std::string mm = tempPath("cube_mm.ply");
  saveMeshPly(transformed(scenes::byName("cube"), 1000.0 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()), mm);
  const CliRun r = cli({"--object", mm, "--area", "builtin:table"});
  std::remove(mm.c_str());
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_TRUE(contains(r.err, "max_object_size")) << r.err;
  EXPECT_TRUE(contains(r.err, "millimetres")) << r.err;
  const CliRun limits = cli(cubeOnTable({"--max-triangles", "1000", "--max-floor-points", "50", "--max-tree-nodes",
                                         "100000", "--max-model-mb", "500", "--max-object-size", "1",
                                         "--max-area-size", "10", "--budget-s", "20", "--rank-order", "lowest"}));
  EXPECT_EQ(limits.code, 0) << limits.out << limits.err;
  const CliRun bad = cli(cubeOnTable({"--max-floor-points", "0"}));
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.err, "--max-floor-points")) << bad.err;
}

}  // namespace
}  // namespace place_planner

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const int rc = RUN_ALL_TESTS();
  std::remove(place_planner::steepSlope().c_str());
  return rc;
}
