// Far vertices (stages/flow/far_vertices.h): which vertices read the half-resolution
// photographs, against a brute-force reading of the rule on a unit icosphere seen by one camera.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/error.h"
#include "engine/model/image.h"
#include "engine/model/option_check.h"
#include "stages/flow/far_vertices.h"
#include "stages/flow/normals.h"
#include "stages_meshes.h"

namespace mvflow {
namespace {

using test::all_vertices;
using test::icosphere;

// One camera on the +z axis, 5 units out, looking at the origin.
Camera camera_on_z() {
  Eigen::Matrix3d K;
  K << 100, 0, 31.5, 0, 100, 23.5, 0, 0, 1;
  Eigen::Matrix3d R;  // world to camera: x stays, y and z flip (det +1)
  R << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  return Camera(K, R, -R * Eigen::Vector3d(0, 0, 5), 64, 48);
}

// A unit icosphere whose every vertex has g = 1e-4 and sees the one camera, and its normals.
struct SphereCase {
  TriMesh mesh = icosphere(1.0, 2);
  std::vector<Camera> cameras{camera_on_z()};
  std::vector<Image> images{Image(64, 48)};
  std::vector<PhotoView> views = make_photo_views(cameras, {&images[0]});
  VertexFields fields;

  SphereCase() {
    fields.resize(mesh.n_vertices(), views.size());
    compute_normals(mesh, all_vertices(mesh), fields);
    for (std::size_t v = 0; v < fields.size(); ++v) {
      fields.defined[v] = kPhotoDefined;
      fields.photo_consistency[v] = 1e-4;
      fields.visible_views[v * fields.view_capacity] = 0;
      fields.visible_count[v] = 1;
    }
  }
  // The angle between v's normal and the direction to the camera, in degrees.
  double view_angle(std::size_t v) const {
    const Eigen::Vector3d X = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
    return std::acos(std::clamp(fields.normal[v].dot((cameras[0].centre() - X).normalized()), -1.0, 1.0)) * 180 /
           std::numbers::pi;
  }
  // The vertex whose view angle is closest to \p degrees.
  std::size_t vertex_at_angle(double degrees) const {
    std::size_t best = 0;
    for (std::size_t v = 1; v < fields.size(); ++v)
      if (std::abs(view_angle(v) - degrees) < std::abs(view_angle(best) - degrees)) best = v;
    return best;
  }
};

// The rule written out: the median of the near vertices' g by a full sort.
std::vector<std::uint8_t> brute_force(const SphereCase& s, const FarVertexOptions& o, std::vector<std::uint8_t> far) {
  std::vector<double> near_g;
  for (std::size_t v = 0; v < s.fields.size(); ++v)
    if ((s.fields.defined[v] & kPhotoDefined) && !far[v]) near_g.push_back(s.fields.photo_consistency[v]);
  std::sort(near_g.begin(), near_g.end());
  const std::size_t n = near_g.size();
  const double median = n % 2 == 1 ? near_g[n / 2] : 0.5 * (near_g[n / 2 - 1] + near_g[n / 2]);
  for (std::size_t v = 0; v < s.fields.size(); ++v) {
    if (!(s.fields.defined[v] & kPhotoDefined)) continue;
    const double g = s.fields.photo_consistency[v];
    if (far[v])
      far[v] = g < o.release * o.g_ratio * median ? 0 : 1;
    else
      far[v] = g > o.g_ratio * median && s.view_angle(v) <= o.view_angle_degrees ? 1 : 0;
  }
  return far;
}

TEST(FarVertices, OptionsAreChecked) {
  EXPECT_NO_THROW(FarVertexOptions{}.check());
  EXPECT_NO_THROW((FarVertexOptions{.g_ratio = 0.0}).check());
  EXPECT_FALSE((FarVertexOptions{.g_ratio = 0.0}).enabled());
  EXPECT_THROW((FarVertexOptions{.g_ratio = 0.5}).check(), OptionError);
  EXPECT_THROW((FarVertexOptions{.g_ratio = -1.0}).check(), OptionError);
  EXPECT_THROW((FarVertexOptions{.view_angle_degrees = 0.0}).check(), OptionError);
  EXPECT_THROW((FarVertexOptions{.view_angle_degrees = 91.0}).check(), OptionError);
  EXPECT_THROW((FarVertexOptions{.release = 0.0}).check(), OptionError);
  EXPECT_THROW((FarVertexOptions{.release = 1.5}).check(), OptionError);
}

TEST(FarVertices, AHighGSeenFrontallyGoesFarAndComesBackBelowTheRelease) {
  SphereCase s;
  const FarVertexOptions options;  // 300 × the median, within 60°, released below a quarter of that
  const std::size_t front = s.vertex_at_angle(0.0), oblique = s.vertex_at_angle(45.0);
  const std::size_t grazing = s.vertex_at_angle(80.0), undefined = s.vertex_at_angle(30.0);
  ASSERT_LT(s.view_angle(oblique), 60.0);
  ASSERT_GT(s.view_angle(grazing), 60.0);
  s.fields.photo_consistency[front] = s.fields.photo_consistency[oblique] = s.fields.photo_consistency[grazing] = 1.0;
  s.fields.photo_consistency[undefined] = 1.0;
  s.fields.defined[undefined] = 0;  // g not defined: the flag stays as it was

  std::vector<std::uint8_t> far;
  EXPECT_EQ(update_far_vertices(s.mesh, s.views, s.fields, options, far), 2u);
  EXPECT_EQ(far, brute_force(s, options, std::vector<std::uint8_t>(s.fields.size(), 0)));
  EXPECT_EQ(far[front], 1);
  EXPECT_EQ(far[oblique], 1);
  EXPECT_EQ(far[grazing], 0);    // a grazing cap: high g at the true surface too
  EXPECT_EQ(far[undefined], 0);

  // Between the release (0.25 × 300 × 1e-4 = 0.0075) and the threshold (0.03) a far vertex stays far.
  s.fields.photo_consistency[front] = 0.02;
  s.fields.photo_consistency[oblique] = 0.005;
  const std::vector<std::uint8_t> expected = brute_force(s, options, far);
  EXPECT_EQ(update_far_vertices(s.mesh, s.views, s.fields, options, far), 1u);
  EXPECT_EQ(far, expected);
  EXPECT_EQ(far[front], 1);
  EXPECT_EQ(far[oblique], 0);

  // An undefined g keeps a far flag too.
  s.fields.defined[front] = 0;
  s.fields.photo_consistency[front] = 0.0;
  EXPECT_EQ(update_far_vertices(s.mesh, s.views, s.fields, options, far), 1u);
  EXPECT_EQ(far[front], 1);
}

TEST(FarVertices, TheMedianIsTakenOverTheNearVerticesOnly) {
  SphereCase s;
  FarVertexOptions options;
  options.g_ratio = 3.0;
  options.view_angle_degrees = 90.0;
  // g rises geometrically with the vertex id, so the median of all and of the near ones differ.
  for (std::size_t v = 0; v < s.fields.size(); ++v) s.fields.photo_consistency[v] = 1e-4 * std::pow(1.05, static_cast<double>(v));
  std::vector<std::uint8_t> far;
  update_far_vertices(s.mesh, s.views, s.fields, options, far);
  std::size_t count = 0;
  for (std::size_t round = 0; round < 3; ++round) {
    const std::vector<std::uint8_t> expected = brute_force(s, options, far);
    count = update_far_vertices(s.mesh, s.views, s.fields, options, far);
    EXPECT_EQ(far, expected) << round;
  }
  EXPECT_GT(count, 0u);
  EXPECT_LT(count, s.fields.size());
}

TEST(FarVertices, AZeroMedianMakesNoVertexFar) {
  SphereCase s;
  for (double& g : s.fields.photo_consistency) g = 0.0;  // every patch agrees exactly
  s.fields.photo_consistency[s.vertex_at_angle(0.0)] = 1.0;
  std::vector<std::uint8_t> far;
  EXPECT_EQ(update_far_vertices(s.mesh, s.views, s.fields, FarVertexOptions{}, far), 0u);
}

TEST(FarVertices, NoVertexWithGLeavesTheFlagsAsTheyAre) {
  SphereCase s;
  for (std::uint8_t& bits : s.fields.defined) bits = 0;
  std::vector<std::uint8_t> far(s.fields.size(), 0);
  far[3] = 1;
  EXPECT_EQ(update_far_vertices(s.mesh, s.views, s.fields, FarVertexOptions{}, far), 1u);
  EXPECT_EQ(far[3], 1);
  std::vector<std::uint8_t> wrong_size(2, 1);
  EXPECT_EQ(update_far_vertices(s.mesh, s.views, s.fields, FarVertexOptions{}, wrong_size), 0u);
  EXPECT_EQ(wrong_size.size(), s.fields.size());
}

}  // namespace
}  // namespace mvflow
