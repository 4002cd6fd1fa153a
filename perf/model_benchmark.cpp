// Throughput of the data-model primitives the photo-consistency stage is built on: projecting a
// point through a camera and bilinear sampling of a 5×5 patch.

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>

#include "engine/model/camera.h"
#include "engine/model/image.h"

namespace {

mvflow::Camera benchmark_camera(mvflow::Distortion distortion = {}) {
  Eigen::Matrix3d K;
  K << 1000, 0, 959.5, 0, 1000, 539.5, 0, 0, 1;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return {K, R, Eigen::Vector3d(0, 0, 3), 1920, 1080, distortion};
}

std::vector<Eigen::Vector3d> random_points(std::size_t count) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-0.5, 0.5);
  std::vector<Eigen::Vector3d> points(count);
  for (auto& p : points) p = {coordinate(random), coordinate(random), coordinate(random)};
  return points;
}

void BM_Project(benchmark::State& state) {
  const mvflow::Camera camera = state.range(0) ? benchmark_camera({mvflow::DistortionModel::Radial, {-0.1, 0.01, 0, 0}})
                                               : benchmark_camera();
  const auto points = random_points(4096);
  for (auto _ : state)
    for (const auto& p : points) benchmark::DoNotOptimize(camera.project(p));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(points.size()));
  state.SetLabel(state.range(0) ? "radial distortion" : "pinhole");
}
BENCHMARK(BM_Project)->Arg(0)->Arg(1);

void BM_Patch5x5Bilinear(benchmark::State& state) {
  mvflow::Image image(1920, 1080);
  std::mt19937 random(3);
  std::uniform_real_distribution<float> value(0, 1);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) image.set_pixel(x, y, {value(random), value(random), value(random)});
  std::uniform_real_distribution<double> u(2, 1916), v(2, 1076);
  std::vector<Eigen::Vector2d> centres(4096);
  for (auto& c : centres) c = {u(random), v(random)};
  for (auto _ : state)
    for (const auto& c : centres) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) sum += image.sample_bilinear(c.x() + dx, c.y() + dy);
      benchmark::DoNotOptimize(sum);
    }
  // Patch-pixel reads: 25 bilinear samples of 4 pixels each.
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(centres.size()) * 25);
  state.SetLabel("items = bilinear samples");
}
BENCHMARK(BM_Patch5x5Bilinear);

}  // namespace

BENCHMARK_MAIN();
