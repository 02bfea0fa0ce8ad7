#include <dirent.h>

#include <fstream>
#include <random>
#include <regex>

#include "place_planner/infra/backend.h"
#include "place_planner/config.h"
#include "place_planner/infra/cuda_backend.h"
#include "place_planner/kernels/transform_vertices.h"
#include "test_helpers.h"

using namespace place_planner;

namespace {
std::vector<std::string> listFiles(const std::string& dir) {
  std::vector<std::string> out;
  DIR* d = opendir(dir.c_str());
  if (!d) return out;
  while (dirent* e = readdir(d)) {
    const std::string n = e->d_name;
    if (n == "." || n == "..") continue;
    const std::string p = dir + "/" + n;
    if (e->d_type == DT_DIR) {
      for (auto& s : listFiles(p)) out.push_back(s);
    } else {
      out.push_back(p);
    }
  }
  closedir(d);
  return out;
}
}  // namespace

// The core library must stay ROS-free (grid_map style): no ROS, PCL or OpenCV include.
TEST(Foundation, CoreIsRosFree) {
  const std::regex forbidden(R"(#\s*include\s*[<"](ros/|pcl|opencv|tf2|actionlib|sensor_msgs|geometry_msgs|visualization_msgs|bullet|btBullet))");
  int files = 0;
  for (const std::string dir : {"/src/core", "/include/place_planner", "/cuda"}) {
    for (const auto& path : listFiles(std::string(PP_SOURCE_DIR) + dir)) {
      if (path.find("/include/place_planner/ros/") != std::string::npos) continue;  // adapter headers
      std::ifstream in(path);
      std::string line;
      int lineno = 0;
      while (std::getline(in, line)) {
        ++lineno;
        EXPECT_FALSE(std::regex_search(line, forbidden)) << path << ":" << lineno << ": " << line;
      }
      ++files;
    }
  }
  EXPECT_GT(files, 10);
}

TEST(Foundation, TransformVerticesCpuMatchesEigen) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.1, -0.2, 0.3);
  Rigid T;
  for (int i = 0; i < 9; ++i) T.R[i] = R(i / 3, i % 3);
  T.t = v3(t.x(), t.y(), t.z());
  std::vector<V3> in(1000), out(1000);
  for (auto& p : in) p = v3(u(rng), u(rng), u(rng));
  transformVerticesCpu(T, in.data(), out.data(), in.size(), 2);
  for (size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector3d e = R * Eigen::Vector3d(in[i].x, in[i].y, in[i].z) + t;
    EXPECT_NEAR(out[i].x, e.x(), 1e-12);
    EXPECT_NEAR(out[i].y, e.y(), 1e-12);
    EXPECT_NEAR(out[i].z, e.z(), 1e-12);
  }
}

// nvblox style: the GPU result equals the CPU one. Needs a GPU; skipped with the reason otherwise.
TEST(Foundation, TransformVerticesCudaMatchesCpu) {
  std::string why;
  if (!cuda::available(&why)) GTEST_SKIP() << "no usable GPU: " << why;
  Rigid T{{0, -1, 0, 1, 0, 0, 0, 0, 1}, v3(1, 2, 3)};
  std::vector<V3> in(4096), gpu(4096), cpu(4096);
  for (size_t i = 0; i < in.size(); ++i) in[i] = v3(i * 0.001, -double(i), 0.5);
  cuda::transformVertices(T, in.data(), gpu.data(), in.size());
  transformVerticesCpu(T, in.data(), cpu.data(), in.size(), 1);
  for (size_t i = 0; i < in.size(); ++i) EXPECT_NEAR(norm(gpu[i] - cpu[i]), 0.0, 1e-12);
}

TEST(Foundation, RotateAboutIsCounterClockwise) {
  // Rotating (1,0,0) by +90 deg about +z through the origin gives (0,1,0).
  const V3 p = rotateAbout(v3(1, 0, 0), v3(0, 0, 0), v3(0, 0, 1), M_PI / 2);
  EXPECT_NEAR(p.x, 0, 1e-12);
  EXPECT_NEAR(p.y, 1, 1e-12);
  const V3 q = rotateAbout(v3(2, 0, 5), v3(1, 0, 0), v3(0, 0, 1), M_PI);
  EXPECT_NEAR(q.x, 0, 1e-12);
  EXPECT_NEAR(q.z, 5, 1e-12);
}

TEST(Config, DefaultsAreValidAndBadFieldsAreNamed) {
  PlannerConfig c;
  EXPECT_NO_THROW(validate(c));
  EXPECT_DOUBLE_EQ(c.friction, 0.2);
  EXPECT_DOUBLE_EQ(c.floor_point_spacing, 0.09);
  EXPECT_EQ(c.max_rotations, 5);
  auto expectField = [](PlannerConfig c, const std::string& field) {
    try {
      validate(c);
      ADD_FAILURE() << field << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind(field + " =", 0), 0u) << e.what();
    }
  };
  c.friction = -0.1;
  expectField(c, "friction");
  c = PlannerConfig();
  c.floor_point_spacing = 0;
  expectField(c, "floor_point_spacing");
  c = PlannerConfig();
  c.gravity = Eigen::Vector3d::Zero();
  expectField(c, "gravity");
  c = PlannerConfig();
  c.max_rotations = -1;
  expectField(c, "max_rotations");
  EXPECT_EQ(orientationModeFromString("all_axes"), OrientationMode::kAllAxes);
  EXPECT_THROW(orientationModeFromString("upright"), std::invalid_argument);
}

