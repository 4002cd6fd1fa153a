#pragma once
// The held-out-view error (SPEC §8): how well a mesh predicts a photograph that neither its
// refinement nor its colouring saw — the way to judge a reconstruction on real photographs that
// have no ground-truth geometry. For each held-out view: cast the pixel rays of its camera into
// the mesh (Embree), colour each hit point from the views that are not held out
// (stages/eval/point_colouring.h), and compare with the photograph inside the union of the rendered
// and the real silhouette: mean absolute error, PSNR, and the fraction of the union where the two
// silhouettes disagree.
//
// Pixels whose surface point no colouring view sees ("unseen") have no predicted colour: they are
// counted and reported, left out of MAE and PSNR, and still count in the silhouette comparison
// (the mesh's shape is known there, only its colour is not).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "engine/model/image.h"
#include "engine/model/mesh.h"
#include "engine/model/scene.h"
#include "engine/model/surface_query.h"
#include "stages/flow/photo_views.h"
#include "stages/eval/point_colouring.h"
#include "stages/flow/silhouette.h"

namespace mvflow {

struct HeldoutOptions {
  //! N: N×N rays per pixel of the held-out camera, averaged (1..8). 2 anti-aliases the silhouette
  //! edges as a photograph's are (and as `mvflow render` and `mvflow synth` do by default).
  int supersample = 2;
  //! The rendered value where a ray misses the mesh, RGB on [0,1]: the photographs' background
  //! (black, as in the Middlebury sets and `mvflow synth --background black`).
  Eigen::Vector3f background{0.0f, 0.0f, 0.0f};
  //! Which views colour a surface point (grazing angle, occlusion-ray offset).
  PointColouringOptions colouring;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! One held-out view rendered from the mesh. Pixel (x, y) is index y·width + x.
struct HeldoutRendering {
  //! The prediction: per pixel the mean over its rays of the surface point's colour (rays that
  //! miss give the background); background at unseen pixels.
  Image image;
  //! Rendered silhouette: at least half of the pixel's rays hit the mesh.
  Mask silhouette;
  //! 1 where at least half of the pixel's rays hit a point that no colouring view sees (such
  //! pixels lie inside the silhouette), 0 elsewhere.
  std::vector<std::uint8_t> unseen;
};

//! Pixel counts and error sums of one comparison. They add up over views, so the metrics over
//! several views are pooled over all their pixels.
struct HeldoutMetrics {
  std::size_t union_pixels = 0;        //!< in the rendered or the real silhouette
  std::size_t disagreeing_pixels = 0;  //!< in exactly one of the two (XOR)
  std::size_t unseen_pixels = 0;       //!< in the union, with no predicted colour: not scored
  std::size_t scored_pixels = 0;       //!< union minus unseen: where MAE and PSNR are measured
  double sum_absolute = 0.0;           //!< Σ over scored pixels and the 3 channels of |rendered − real|
  double sum_squared = 0.0;            //!< Σ over scored pixels and the 3 channels of (rendered − real)²

  //! Mean absolute error on [0,1] values, over scored pixels and channels; NaN without scored pixels.
  double mae() const;
  //! Mean squared error, likewise.
  double mse() const;
  //! 10·log10(1 / mse) in dB (peak value 1); +inf when the images agree exactly, NaN without scored pixels.
  double psnr() const;
  //! disagreeing / union: 0 = the silhouettes agree, 1 = they do not overlap; 0 when both are empty.
  double silhouette_disagreement() const;
  HeldoutMetrics& operator+=(const HeldoutMetrics& other);
};

//! Compares \p rendering with \p photograph inside the union of \p rendering.silhouette and
//! \p real_silhouette. Sums in pixel order (deterministic).
//! \throw Error when the sizes differ.
HeldoutMetrics compare_with_photograph(const HeldoutRendering& rendering, const Image& photograph,
                                       const Mask& real_silhouette);

//! Renders a mesh into held-out views, colouring it from the scene's other views only.
//! Holds the BVH and the colouring views, so several held-out views share them.
class HeldoutRenderer {
 public:
  //! \p held_out: 0-based view indices; none of them ever colours the mesh. Decodes the images of
  //! the other views. \p scene and \p mesh must outlive the renderer.
  //! \throw InputError when a held-out index is out of range (naming it and the view count),
  //! listed twice, the list is empty, no view is left to colour with, the mesh is empty or has a
  //! non-finite coordinate, or the options are invalid.
  HeldoutRenderer(const Scene& scene, const Mesh& mesh, std::vector<int> held_out,
                  const HeldoutOptions& options = {});

  //! Renders held-out view \p view (parallel over rows; the result does not depend on the
  //! thread count). \throw Error when \p view is not one of the held-out views.
  HeldoutRendering render(int view) const;

  const std::vector<int>& held_out() const { return held_out_; }
  //! The scene indices of the views that colour the mesh, ascending.
  const std::vector<int>& colouring_views() const { return colouring_indices_; }

 private:
  const Scene& scene_;
  std::vector<int> held_out_;
  HeldoutOptions options_;
  IndexedMesh flat_;
  std::vector<Eigen::Vector3d> face_normals_;  //!< unit, from the corner order (zero if degenerate)
  double mean_edge_ = 0.0;
  SurfaceQuery surface_;
  std::vector<int> colouring_indices_;
  std::vector<PhotoView> colouring_views_;
};

//! The side-by-side picture of one held-out view: photograph | rendering | error map.
//! Unseen pixels are magenta in the rendering and the error map. The error map is black outside
//! the union of the silhouettes; inside, the mean absolute channel error e goes from dark blue
//! (e = 0) through red (e = error_scale/2) to yellow (e ≥ error_scale).
//! \throw Error when the sizes differ or error_scale ≤ 0.
Image heldout_panel(const Image& photograph, const HeldoutRendering& rendering, const Mask& real_silhouette,
                    double error_scale = 0.25);

}  // namespace mvflow
