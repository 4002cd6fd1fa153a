#pragma once
// A whole synthetic scene in memory: ground truth, cameras, rendered photographs, initial mesh
// and bounding box. Writing it to a folder is the CLI's job (tools/synth_command.cpp).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/model/bounding_box.h"
#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "engine/model/mesh.h"
#include "engine/model/scene.h"
#include "stages/flow/silhouette.h"
#include "stages/synth/synth_cameras.h"
#include "stages/synth/synth_initial_mesh.h"
#include "stages/synth/synth_objects.h"
#include "stages/synth/synth_render.h"

namespace mvflow {

enum class AlbedoKind {
  Auto,  //!< the mesh's UV texture when it has one, else a solid texture
  Uv,    //!< the mesh's UV texture (an error without one)
  Solid  //!< a procedural solid texture
};

struct SynthOptions {
  std::uint64_t seed = 1;    //!< every random choice derives from it (textures, noise, init)
  AlbedoKind albedo = AlbedoKind::Auto;
  double feature_size = 0.2;  //!< solid texture: size of the largest blobs, × the object radius
  int octaves = 3;            //!< solid texture: noise octaves
  double background_radius = 20.0;  //!< far sphere, × the object radius (raised to enclose the cameras)
  double bbox_margin = 0.05;  //!< bbox.txt: the truth's box grown by this × its diagonal on every side
  RenderOptions render;       //!< render.seed is derived from seed
  RigOptions rig;
  InitialMeshOptions init;    //!< init.seed is derived from seed
  bool masks = false;         //!< also the truth's exact silhouettes (SynthScene::silhouettes)
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! The names of the built-in objects, for help texts: "bumpy-sphere", "peanut".
const std::vector<std::string>& builtin_object_names();
//! True when \p name is a built-in object.
bool is_builtin_object(const std::string& name);
//! The built-in object \p name, centred at the origin with radius about 1.
//! \throw InputError for an unknown name.
IndexedMesh make_builtin_object(const std::string& name, const BuiltinShapeOptions& options);

struct SynthScene {
  IndexedMesh truth;           //!< the ground truth (as given: centred, unit-ish)
  IndexedMesh initial;         //!< the initial mesh
  std::vector<View> views;     //!< named view_000.png, ...
  std::vector<Image> images;   //!< one per view, float RGB (8-bit quantization happens on writing)
  BoundingBox bounding_box;    //!< around the truth, with the margin
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  //!< what the cameras look at
  double radius = 1.0;         //!< largest distance of a truth vertex from the centre
  bool uv_albedo = false;      //!< whether the UV texture was used
  //! With SynthOptions::masks: the truth's exact silhouette per view (a pixel is object when the
  //! ray through its centre meets the truth, whatever the background and the texture).
  std::vector<Mask> silhouettes;
};

//! Renders the scene of \p truth (a closed mesh, ideally centred at the origin). \p uv_texture
//! is the mesh's texture image, or null. \throw InputError for invalid options, a mesh that is
//! not closed and manifold (initial mesh), or `Uv` albedo without texture.
SynthScene make_synth_scene(const IndexedMesh& truth, std::shared_ptr<const Image> uv_texture,
                            const SynthOptions& options);


//! The renderer make_synth_scene uses, exposed for tests and tools that render more views.
SynthRenderer make_synth_renderer(const IndexedMesh& truth, std::shared_ptr<const Image> uv_texture,
                                  const SynthOptions& options, const Eigen::Vector3d& centre, double radius,
                                  bool* uv_albedo = nullptr);

}  // namespace mvflow
