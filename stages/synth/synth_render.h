#pragma once
// Renders synthetic photographs of a textured triangle mesh: Embree primary rays, N×N
// supersampling, Lambertian shading under one directional light (plus an optional specular
// lobe), a far textured background sphere, Gaussian pixel noise. Rows render in parallel and
// the result does not depend on the number of threads.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "engine/model/mesh.h"
#include "engine/model/surface_query.h"
#include "stages/synth/synth_texture.h"

namespace mvflow {

enum class BackgroundKind {
  Textured,  //!< a far sphere with its own solid texture (default: like real, cluttered backgrounds)
  Black
};

struct RenderOptions {
  int supersample = 2;       //!< N: N×N primary rays per pixel, averaged (1..8)
  double ambient = 0.35;     //!< light reaching every point, as a fraction of the albedo (≥ 0)
  double diffuse = 0.65;     //!< weight of the directional light's Lambertian term (≥ 0)
  Eigen::Vector3d light = Eigen::Vector3d(0.35, 0.8, 0.5);  //!< direction towards the light (any length > 0)
  bool smooth_shading = true;  //!< shading normal: interpolated vertex normals, else the face normal
  double specular = 0.0;     //!< weight of a white Blinn–Phong lobe: 0 = purely Lambertian (0..1)
  double shininess = 40.0;   //!< Blinn–Phong exponent (1..10000)
  double noise = 0.0;        //!< σ of Gaussian noise added to every channel, on [0,1] values (0..1)
  std::uint64_t seed = 1;    //!< seeds the noise; per view and row, so threads do not matter
  BackgroundKind background = BackgroundKind::Textured;
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! The surface's colour: a solid texture, or the mesh's UV texture when \p uv_texture is set
//! (then the mesh must carry texcoords).
struct SurfaceAlbedo {
  std::shared_ptr<const SolidTexture> solid;
  std::shared_ptr<const Image> uv_texture;
};

//! The far background sphere (ignored when RenderOptions::background is Black).
struct BackgroundSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 20.0;  //!< must enclose every camera
  std::shared_ptr<const SolidTexture> texture;
};

//! Holds the BVH and the shading normals; render() may run for many views in turn.
class SynthRenderer {
 public:
  //! \throw InputError when the options are invalid or the albedo does not fit the mesh.
  SynthRenderer(const IndexedMesh& mesh, SurfaceAlbedo albedo, BackgroundSphere background, RenderOptions options);

  //! The photograph seen by \p camera; \p view_index seeds its noise. Values in [0,1] before
  //! noise; noise may push them outside (8-bit output clamps).
  Image render(const Camera& camera, std::size_t view_index) const;

  //! The noise-free radiance leaving surface point (face, barycentric) towards \p eye.
  Eigen::Vector3f shade(std::uint32_t face, const Eigen::Vector2d& barycentric, const Eigen::Vector3d& eye) const;

  const SurfaceQuery& surface() const { return query_; }

 private:
  IndexedMesh mesh_;
  SurfaceAlbedo albedo_;
  BackgroundSphere background_;
  RenderOptions options_;
  Eigen::Vector3d light_;
  std::vector<Eigen::Vector3d> vertex_normals_;
  std::vector<Eigen::Vector3d> face_normals_;
  SurfaceQuery query_;

  Eigen::Vector3f trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  void render_rows(const Camera& camera, std::size_t view_index, int first, int last, Image& image) const;
};

//! Area-weighted unit vertex normals of \p mesh (zero for isolated vertices).
std::vector<Eigen::Vector3d> vertex_normals(const IndexedMesh& mesh);

}  // namespace mvflow
