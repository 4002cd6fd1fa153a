#pragma once
// Renders a mesh into a camera with Embree, shaded or with its vertex colours: what
// `mvflow render` shows a user. (The held-out-view error renders its own way: each ray's hit is
// coloured from the other photographs, stages/eval/heldout_error.h.)

#include <cstdint>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "engine/model/mesh.h"

namespace mvflow {

enum class MeshShading {
  Shaded,   //!< grey Lambertian shading with a light at the camera (shape only)
  Coloured  //!< the mesh's per-vertex colours, interpolated (needs Mesh::colors)
};

struct MeshRenderOptions {
  MeshShading shading = MeshShading::Shaded;
  int supersample = 2;                               //!< N×N rays per pixel (anti-aliasing)
  Eigen::Vector3f background{0.0f, 0.0f, 0.0f};
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

struct MeshRendering {
  Image image;
  std::vector<float> coverage;  //!< per pixel, the fraction of its rays that hit the mesh
};

//! Renders \p mesh as seen by \p camera (parallel over rows; the result does not depend on the
//! thread count). \throw InputError for Coloured without colours, or invalid options.
MeshRendering render_mesh(const Mesh& mesh, const Camera& camera, const MeshRenderOptions& options = {});

}  // namespace mvflow
