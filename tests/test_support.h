#pragma once
// Small helpers shared by the tests: scratch folders and meshes built in code.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <fstream>
#include <numbers>
#include <string>

#include "engine/model/mesh.h"

namespace mvflow::test {

//! A fresh, empty folder for one test, removed at the end of the test.
class ScratchFolder {
 public:
  ScratchFolder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    // The process id too: two checkouts' suites may run at once on one machine.
    path_ = std::filesystem::temp_directory_path() / (std::string("mvflow-") + info->test_suite_name() + "-" +
                                                      info->name() + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

//! What running the mvflow program printed (stdout and stderr together) and its exit code.
struct CommandResult {
  int exit_code = -1;
  std::string output;
};

//! Runs `ENVIRONMENT mvflow ARGUMENTS` (the binary this build made; ENVIRONMENT as NAME=VALUE
//! words for the shell) and waits for it.
inline CommandResult run_mvflow_with_environment(const std::string& environment, const std::string& arguments) {
  const std::string command = environment + " " + std::string(MVFLOW_BINARY) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe)) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

//! Runs `mvflow ARGUMENTS` (the binary this build made) and waits for it.
inline CommandResult run_mvflow(const std::string& arguments) { return run_mvflow_with_environment("", arguments); }

//! Möller–Trumbore in double: where the ray origin + t·direction (t > 0) meets triangle (a, b, c),
//! in units of |direction|; the independent reference for Embree's answers.
inline std::optional<double> ray_triangle_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                              const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                              const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-15) return std::nullopt;
  const Eigen::Vector3d s = origin - a;
  const double u = s.dot(p) / det;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = direction.dot(q) / det;
  const double t = e2.dot(q) / det;
  if (u < 0 || v < 0 || u + v > 1 || t <= 0) return std::nullopt;
  return t;
}

//! The regular octahedron with vertices at ±1 on the axes, faces counter-clockwise from outside.
inline IndexedMesh octahedron() {
  IndexedMesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}

//! A torus (radii 2 and 1) of n×m quads split into triangles: closed, genus 1.
inline IndexedMesh torus(int n, int m) {
  IndexedMesh mesh;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double a = 2 * std::numbers::pi * i / n, b = 2 * std::numbers::pi * j / m;
      mesh.positions.emplace_back((2 + std::cos(b)) * std::cos(a), (2 + std::cos(b)) * std::sin(a), std::sin(b));
    }
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(((i + n) % n) * m + (j + m) % m); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return mesh;
}

}  // namespace mvflow::test
