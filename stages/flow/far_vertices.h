#pragma once
// Far vertices: at the first resolution, a vertex whose g is hundreds of times the median g (the
// surface there is still far from where the views agree) reads its patches from the photographs
// at half resolution, whose patches span twice the surface and are blurred, until it comes near
// (README, "Far vertices on half-resolution images").
//
// Why: on the peanut-shaped scenes the initial mesh spans the waist 2.5–10 edges outside the
// true surface. There g is 500–2000× the median and ∇g·N, taken over 1/40 of an edge, is noise
// that flips sign from one iteration to the next, so the waist creeps in for 100 iterations and
// stops short (a crease where g·H balances ∇g·N; t2's completeness 95.9 %). Half-resolution
// patches see the same surface point over twice the distance, so g's basin is twice as wide
// there, while every other vertex keeps the full-resolution patches: coarse images for all
// (`--image-levels 1`) helped the waist too but cost the temple photographs 13 points of
// held-out gain, and made every vertex converge on blurred images first.
//
// The half-resolution images are made from the photographs as given, not from their blurred copies
// (DenoiseOptions): the 2×2 average already halves the noise, and on the noisy t3 sphere the
// blurred copies' halves left the mean error 10 % higher.
//
// A vertex that no view sees within view_angle of its normal is never made far: a grazing cap
// has a high g at the true surface too (foreshortened patches), and half-resolution images only
// blur it further.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

struct FarVertexOptions {
  //! A vertex becomes far when its g exceeds this multiple of the median g of the vertices that
  //! are not far; > 1, or 0: never (the thesis preset). 300: over the 32 synthetic scenes of
  //! tools/quality_scenes.sh (three runs each) 100 / 300 / 1000 gave 0.952 / 0.954 / 0.981 the
  //! error without far vertices, better by > 3 % on 14 / 17 / 11 scenes, issue 12's item 5 on 34 /
  //! 35 / 35 of 36 sphere runs (a build that halved the blurred copies of noisy photographs; as
  //! landed, 300 gave 0.953, 15 better, 36 / 36; README, "Far vertices on half-resolution images").
  double g_ratio = 300.0;
  //! ... and one of its visible views lies within this angle of its normal (degrees); in (0, 90].
  //! 60: without it (first resolution, 300×) 0.952× the error but issue 12's item 5 on 33 of 36
  //! sphere runs (u6's cap, completeness 99.990–99.998 %); 45° gave 0.974× (README, "Far vertices").
  double view_angle_degrees = 60.0;
  //! A far vertex is near again when its g, on the half-resolution images, falls below release ×
  //! g_ratio × the median; in (0, 1]. 0.25: a blurred patch's g is lower than a sharp one's, so
  //! without the margin a vertex would switch images every iteration.
  double release = 0.25;

  bool enabled() const { return g_ratio > 0.0; }
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Updates the far flags of every vertex from this iteration's g (fields.photo_consistency where
//! kPhotoDefined): with m the median g over the vertices with g that are not far, a vertex that
//! is not far becomes far when g > g_ratio·m and one of its visible views (fields.visible, the
//! camera centres of \p views) lies within view_angle_degrees of its normal; a far vertex is
//! near again when g < release·g_ratio·m; while m ≤ 0 (every near vertex's patches agree
//! exactly) no vertex becomes far. Vertices without g keep their flag. Serial and in id order:
//! the flags do not depend on the blocking or the thread count.
//! \param far #V flags (1 = far), resized to #V with zeros when its size differs.
//! \return the number of far vertices after the update (those kept when no vertex has g).
//! \throw Error if the fields are not sized for the mesh.
std::size_t update_far_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views, const VertexFields& fields,
                                const FarVertexOptions& options, std::vector<std::uint8_t>& far);

}  // namespace mvflow
