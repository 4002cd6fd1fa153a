// The photo-consistency slice: its cross-section against the analytic circle, and its g valley
// along the true surface of a rendered synthetic scene.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

#include "engine/model/primitives.h"
#include "engine/model/surface_query.h"
#include "stages/eval/photo_slice.h"
#include "stages/synth/synth_scene.h"

namespace mvflow {
namespace {

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

TEST(PlaneCrossSection, IsACircleOnASphere) {
  const Mesh sphere = build_mesh(make_icosphere(2.0, 4), "sphere");
  const double z = 0.7;
  const auto segments = plane_cross_section(sphere.topology, 2, z);
  double length = 0;
  const double circle = std::sqrt(4.0 - z * z);
  for (const auto& s : segments) {
    length += (s[1] - s[0]).norm();
    for (const auto& p : s) {
      EXPECT_NEAR(p.z(), z, 1e-12);
      // Points lie on the faces, inside the sphere by at most the tessellation sag (< 1 %).
      EXPECT_LE(std::hypot(p.x(), p.y()), circle + 1e-12);
      EXPECT_GE(std::hypot(p.x(), p.y()), 0.99 * circle);
    }
  }
  EXPECT_NEAR(length, 2 * std::numbers::pi * circle, 0.01 * 2 * std::numbers::pi * circle);
}

// Median g on the true surface and 0.1–0.2 radii outside it, on a horizontal slice of a rendered
// bumpy sphere, with the thesis's image patches or with surface patches.
std::pair<double, double> valley_of_g(SurfacePatchUse surface_patch) {
  SynthOptions options;
  options.rig.views = 8;
  options.rig.width = 200;
  options.rig.height = 150;
  options.init.vertices = 200;
  BuiltinShapeOptions shape;
  shape.level = 4;
  const IndexedMesh truth = make_builtin_object("bumpy-sphere", shape);
  const SynthScene scene = make_synth_scene(truth, nullptr, options);
  std::vector<Camera> cameras;
  std::vector<const Image*> images;
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    cameras.push_back(scene.views[i].camera);
    images.push_back(&scene.images[i]);
  }
  const auto views = make_photo_views(cameras, images);
  const Mesh mesh = build_mesh(truth, "truth");
  PhotoSliceOptions slice_options;
  slice_options.axis = 1;  // horizontal plane, where the ring of cameras is
  slice_options.resolution = 120;
  slice_options.photo.surface_patch = surface_patch;
  const PhotoSlice slice = compute_photo_slice(mesh.topology, views, slice_options);
  EXPECT_FALSE(slice.cross_section.empty());

  const SurfaceQuery surface(truth);
  std::vector<double> on_surface, outside;
  for (int j = 0; j < slice.height; ++j)
    for (int i = 0; i < slice.width; ++i) {
      const double g = slice.at(i, j);
      if (std::isnan(g)) continue;
      const Eigen::Vector3d X = slice.point(i, j);
      const ClosestPoint nearest = surface.closest_point(X);
      const bool is_outside = (X - scene.centre).norm() > (nearest.point - scene.centre).norm();
      if (nearest.distance < 0.5 * slice.step) on_surface.push_back(g);
      if (is_outside && nearest.distance > 0.1 * scene.radius && nearest.distance < 0.2 * scene.radius)
        outside.push_back(g);
    }
  EXPECT_GT(on_surface.size(), 50u);
  EXPECT_GT(outside.size(), 50u);
  if (on_surface.empty() || outside.empty()) return {0.0, 0.0};
  return {median(on_surface), median(outside)};
}

TEST(PhotoSlice, ValleyOfGAlongTheTrueSurface) {
  const auto [on, off] = valley_of_g(SurfacePatchUse::Off);
  std::printf("[measured] median g on the surface %.4g, 0.1–0.2 radii outside %.4g (ratio %.3g)\n", on, off, on / off);
  EXPECT_LT(on, 0.5 * off);
}

TEST(PhotoSlice, ValleyOfGAlongTheTrueSurfaceWithSurfacePatches) {
  // Each point's patch lies on the tangent plane of the nearest vertex of the true mesh.
  const auto [on, off] = valley_of_g(SurfacePatchUse::On);
  std::printf("[measured] surface patches: median g on the surface %.4g, 0.1–0.2 radii outside %.4g (ratio %.3g)\n",
              on, off, on / off);
  EXPECT_GT(off, 0.0);
  EXPECT_LT(on, 0.5 * off);
}

}  // namespace
}  // namespace mvflow
