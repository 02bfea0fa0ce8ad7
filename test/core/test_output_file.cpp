// The output-file rules (infra/output_file.h), on the library calls every writer of the project
// uses: regular files replaced whole, symlinks followed, FIFOs written in place, directories
// refused, a failing producer leaving the destination as it was.
#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "place_planner/infra/output_file.h"

using namespace place_planner;

namespace {

std::string dirFor(const std::string& name) {
  const std::string d = "/tmp/pp_output_file_" + std::to_string(getpid()) + "_" + name;
  mkdir(d.c_str(), 0755);
  return d;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int entries(const std::string& dir) {
  int n = 0;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d)) n += std::string(e->d_name) != "." && std::string(e->d_name) != "..";
    closedir(d);
  }
  return n;
}

}  // namespace

TEST(OutputFile, NewAndRegularFilesAreReplacedWhole) {
  const std::string dir = dirFor("regular");
  const std::string path = dir + "/a.csv";
  writeOutputFile(path, "one\n");
  EXPECT_EQ(slurp(path), "one\n");
  chmod(path.c_str(), 0640);
  writeOutputFile(path, "two\n");
  EXPECT_EQ(slurp(path), "two\n");
  struct stat st;
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u) << "the replaced file's mode is kept";
  EXPECT_EQ(entries(dir), 1) << "a temporary file was left";
  std::remove(path.c_str());
  rmdir(dir.c_str());
}

TEST(OutputFile, ASymlinkIsFollowedAndStaysALink) {
  const std::string dir = dirFor("link");
  mkdir((dir + "/sub").c_str(), 0755);
  const std::string target = dir + "/sub/t.json", link = dir + "/l.json", link2 = dir + "/l2.json";
  writeOutputFile(target, "old");
  ASSERT_EQ(symlink("sub/t.json", link.c_str()), 0);
  ASSERT_EQ(symlink("l.json", link2.c_str()), 0);  // a chain of two
  EXPECT_EQ(resolveOutput(link2).path, dir + "/sub/t.json");
  writeOutputFile(link2, "new");
  EXPECT_EQ(slurp(target), "new");
  struct stat st;
  ASSERT_EQ(lstat(link.c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode));
  ASSERT_EQ(lstat(link2.c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode));
  // A dangling link: its target is created.
  std::remove(target.c_str());
  writeOutputFile(link, "again");
  EXPECT_EQ(slurp(target), "again");
  EXPECT_EQ(entries(dir + "/sub"), 1);
  std::remove(target.c_str());
  std::remove(link.c_str());
  std::remove(link2.c_str());
  rmdir((dir + "/sub").c_str());
  rmdir(dir.c_str());
}

TEST(OutputFile, AFifoIsWrittenInPlace) {
  const std::string dir = dirFor("fifo");
  const std::string fifo = dir + "/p";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(resolveOutput(fifo).kind, OutputTarget::Kind::kInPlace);
  std::string got;
  std::thread reader([&] { got = slurp(fifo); });
  writeOutputFile(fifo, "through the pipe");
  reader.join();
  EXPECT_EQ(got, "through the pipe");
  struct stat st;
  ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  std::remove(fifo.c_str());
  rmdir(dir.c_str());
}

TEST(OutputFile, DevicesAreWrittenInPlaceAndErrorsReported) {
  EXPECT_EQ(resolveOutput("/dev/null").kind, OutputTarget::Kind::kInPlace);
  struct stat before, after;
  ASSERT_EQ(stat("/dev/null", &before), 0);
  writeOutputFile("/dev/null", "nothing");
  ASSERT_EQ(stat("/dev/null", &after), 0);
  EXPECT_TRUE(S_ISCHR(after.st_mode));
  EXPECT_EQ(before.st_ino, after.st_ino);
  struct stat full;
  if (stat("/dev/full", &full) == 0 && S_ISCHR(full.st_mode)) {
    try {
      writeOutputFile("/dev/full", "x");
      ADD_FAILURE() << "a write to /dev/full did not fail";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
    }
    ASSERT_EQ(stat("/dev/full", &after), 0);
    EXPECT_TRUE(S_ISCHR(after.st_mode)) << "/dev/full was replaced";
  }
  EXPECT_EQ(resolveOutput("-").kind, OutputTarget::Kind::kStdout);
}

TEST(OutputFile, DirectoriesAndMissingFoldersAreRefused) {
  const std::string dir = dirFor("dir");
  EXPECT_THROW(resolveOutput(dir), std::runtime_error);
  EXPECT_THROW(writeOutputFile(dir + "/no/such/folder/x.csv", "x"), std::runtime_error);
  struct stat st;
  ASSERT_EQ(stat(dir.c_str(), &st), 0);
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  rmdir(dir.c_str());
}

TEST(OutputFile, AProducerWritesBesideTheTargetAndAFailureLeavesItAsItWas) {
  const std::string dir = dirFor("produce");
  const std::string path = dir + "/plot.png";
  writeOutputFile(path, "old");
  std::string seen;
  produceOutputFile(path, [&](const std::string& temp) {
    seen = temp;
    std::ofstream(temp) << "made by a library";
  });
  EXPECT_EQ(seen.substr(seen.size() - 4), ".png") << "the extension (the format) is kept: " << seen;
  EXPECT_EQ(seen.rfind(dir, 0), 0u) << "not beside the target: " << seen;
  EXPECT_EQ(slurp(path), "made by a library");
  EXPECT_THROW(produceOutputFile(path, [](const std::string& temp) {
                 std::ofstream(temp) << "half";
                 throw std::runtime_error("encoder failed");
               }),
               std::runtime_error);
  EXPECT_EQ(slurp(path), "made by a library");
  EXPECT_EQ(entries(dir), 1) << "a temporary file was left";
  std::remove(path.c_str());
  rmdir(dir.c_str());
}
