// Mesh rendering against the analytic silhouette of a sphere and known colours.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/primitives.h"
#include "stages/eval/mesh_render.h"

namespace mvflow {
namespace {

Camera camera_on_z(double distance, double focal, int size) {
  Eigen::Matrix3d K;
  K << focal, 0, (size - 1) / 2.0, 0, focal, (size - 1) / 2.0, 0, 0, 1;
  const Eigen::Matrix3d R = Eigen::Vector3d(1, -1, -1).asDiagonal();  // looks down −z, y down
  return Camera(K, R, -R * Eigen::Vector3d(0, 0, distance), size, size);
}

TEST(MeshRender, SilhouetteOfASphereMatchesTheAnalyticDisk) {
  const Mesh sphere = build_mesh(make_icosphere(1.0, 5), "sphere");
  const double distance = 4.0, focal = 100.0;
  const Camera camera = camera_on_z(distance, focal, 160);
  const MeshRendering r = render_mesh(sphere, camera);
  double covered = 0;
  for (float c : r.coverage) covered += c;
  // The visible cone of a sphere: half-angle asin(r/d); its image is a disk of radius f·tan(asin(r/d)).
  const double radius_px = focal * std::tan(std::asin(1.0 / distance));
  const double disk = std::numbers::pi * radius_px * radius_px;
  EXPECT_NEAR(covered, disk, 0.01 * disk);  // tessellation (level 5) and pixel sampling: ≤ 1 %
  // Facing the camera at the centre: full light.
  EXPECT_NEAR(r.image.pixel(80, 80).x(), 1.0f, 0.01f);
  EXPECT_EQ(r.image.pixel(0, 0), Eigen::Vector3f::Zero());  // background
}

TEST(MeshRender, ColouredUsesTheVertexColours) {
  Mesh sphere = build_mesh(make_icosphere(1.0, 3), "sphere");
  sphere.colors.assign(sphere.n_vertices(), Eigen::Vector3f(0.2f, 0.5f, 0.8f));
  MeshRenderOptions options;
  options.shading = MeshShading::Coloured;
  const MeshRendering r = render_mesh(sphere, camera_on_z(4.0, 100.0, 64), options);
  EXPECT_LT((r.image.pixel(32, 32) - Eigen::Vector3f(0.2f, 0.5f, 0.8f)).norm(), 1e-5f);
  sphere.colors.clear();
  EXPECT_THROW(render_mesh(sphere, camera_on_z(4.0, 100.0, 64), options), InputError);
}

}  // namespace
}  // namespace mvflow
