#pragma once
// g with patches laid on the surface instead of the image (PhotoConsistencyOptions::surface_patch).
// The thesis's patch is (2h+1)² whole pixels around the projection in every view, so a view at an
// angle θ to the normal covers 1/cos θ more surface along its foreshortened axis than a frontal one,
// and on a curved surface the views' patches then disagree even at the true surface. Here every view
// samples the same (2h+1)² points of the vertex's tangent plane, spaced by a multiple of the finest
// visible view's pixel footprint: a grazing view reads them closer together along its
// foreshortened axis (bilinear, at any spacing).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

//! The points of a laid-out patch are padded to a multiple of this (the floats of the widest
//! register of the photo kernel's builds), so that every build reads them in whole registers.
inline constexpr int kSurfacePatchLanes = 16;

//! Where the surface patch of one vertex falls in each of its views: per view the pixel offsets of
//! the (2h+1)² tangent-plane points from the projection of the vertex, rows of the tangent grid
//! in order. Laid out once per vertex; the gradient's samples (within e_min/2 of the vertex) reuse
//! it, shifted with their own projection.
struct SurfacePatchLayout {
  int half_patch = 2;
  int points = 25;                   //!< (2h+1)²
  int padded_points = 32;            //!< points rounded up to kSurfacePatchLanes
  std::vector<std::uint16_t> views;  //!< the views laid out (those with the vertex in front)
  std::vector<float> du, dv;         //!< per laid-out view, padded_points offsets in pixels (padding: the last point's)
  std::vector<float> bounds;         //!< per laid-out view: the offsets' smallest du, largest du, smallest dv, largest dv
};

//! The tangent frame of the patch: unit t₁ = N × (x or y axis, whichever is farther from N),
//! t₂ = N × t₁.
void surface_patch_frame(const Eigen::Vector3d& N, Eigen::Vector3d& t1, Eigen::Vector3d& t2);

//! Lays out the surface patch of the point \p X with outward unit normal \p N over \p view_ids:
//! points X + d·(a·t₁ + b·t₂), a, b = −h..h, with (t₁, t₂) a tangent frame and d
//! \p spacing_in_pixels times the smallest depth / focal length over the views with X in front.
//! A view with X behind it, or where a point does not project (e.g. N undefined), is left out.
void layout_surface_patch(const Eigen::Vector3d& X, const Eigen::Vector3d& N, std::span<const std::uint16_t> view_ids,
                          const std::vector<PhotoView>& views, int half_patch, double spacing_in_pixels,
                          SurfacePatchLayout& layout);

//! g at \p X (near the laid-out point) with the laid-out patch: the same variance as
//! photo_consistency() over the patch's bilinear samples; a view whose patch leaves the image
//! (with its bilinear support) does not count, the points' positions taken in float relative to
//! the projection's pixel, (u − ⌊u⌋) + du (within about 1e-6 pixel of u + du). Runs the photo kernel's build
//! (detail::active_photo_kernel()); the float sums on shifted data of SPEC §3.
PhotoValue surface_patch_consistency(const Eigen::Vector3d& X, const SurfacePatchLayout& layout,
                                     const std::vector<PhotoView>& views);

//! The gradient stage's 6·half + 1 samples of g with the laid-out patch, in the slots of
//! for_each_gradient_sample(X, spacing, half, ...): each the same bits as
//! surface_patch_consistency() at that sample (when g(X) is undefined, only samples[0] is
//! certain to be written). In the AVX-512 build the samples run across the lanes, one 5×5-pixel
//! window per point and view (stages/flow/surface_patch_samples_body.inc); the other builds, and
//! that one where some view spreads the samples over 3 pixels or more, evaluate them one by one.
void surface_patch_samples(const Eigen::Vector3d& X, double spacing, int half, const SurfacePatchLayout& layout,
                           const std::vector<PhotoView>& views, std::span<PhotoValue> samples);

namespace detail {
//! Starts loading into the cache the image rows that the surface patches of a point \p X near the
//! laid-out one read (with its samples), so that evaluating there next does not wait for memory.
void prefetch_surface_patches(const Eigen::Vector3d& X, const SurfacePatchLayout& layout,
                              const std::vector<PhotoView>& views);
}  // namespace detail

//! Whether g at the surface point \p X with outward unit normal \p N over \p view_ids lays its
//! patch on the surface (options.surface_patch): always with On, never with Off or normalize, and
//! with Oblique when one of the views is farther than options.surface_patch_angle_degrees from N.
bool uses_surface_patch(const Eigen::Vector3d& X, const Eigen::Vector3d& N, std::span<const std::uint16_t> view_ids,
                        const std::vector<PhotoView>& views, const PhotoConsistencyOptions& options);

//! g at the surface point \p X with outward unit normal \p N as the options say: the surface
//! patch (laid out in \p layout, reused between calls) where uses_surface_patch(), else
//! photo_consistency().
PhotoValue photo_consistency_at_surface(const Eigen::Vector3d& X, const Eigen::Vector3d& N,
                                        std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                        const PhotoConsistencyOptions& options, SurfacePatchLayout& layout);
//! The same, with the surface patch read from \p surface_views (the same cameras in the same
//! order, other photographs: the refinement's blurred views serve the image patches only, see
//! DenoiseOptions).
PhotoValue photo_consistency_at_surface(const Eigen::Vector3d& X, const Eigen::Vector3d& N,
                                        std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                        const std::vector<PhotoView>& surface_views,
                                        const PhotoConsistencyOptions& options, SurfacePatchLayout& layout);

}  // namespace mvflow
