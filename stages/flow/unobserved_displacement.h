#pragma once
// The regions the photographs do not constrain move with the observed surface around them
// (README, "Defaults and differences"). A vertex seen only at grazing angles, occluded or outside
// every image has no reliable speed, so such a region would keep the initial surface's error
// while its observed border converges. Here the displacement of the observed vertices from the
// surface the flow started on (their signed distance to it) is spread over the rest
// by the cotangent Laplace equation (a harmonic interpolation: it stays between its boundary
// values, so the noise of the observed border is averaged, never amplified), and every such
// vertex is placed at its starting position moved by that amount along its starting normal.
// A sphere offset by a constant comes back to the sphere exactly, whatever the region's size.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

//! When the unobserved vertices follow the observed surface.
enum class UnobservedSpread {
  Off,   //!< never (the thesis, §5.3.3: such vertices move only by smoothing and regularization)
  On,    //!< always
  Auto,  //!< all of them when the silhouette rims are fitted (fits_rims), else the hardly observed
};

struct UnobservedDisplacementOptions {
  //! Move the unobserved vertices with the observed surface each time the flow has converged at
  //! a resolution that is then refined (not after the finest: the flow there has the last word;
  //! README, "Weakly seen regions"; with RefinementSchedule::EveryIteration at the end of the
  //! run). Auto (the default): every poorly observed vertex where the rims are fitted (the
  //! silhouettes observe the rims too, so an unseen region is anchored all round; it lowered the
  //! held-out error of both photograph sets), and only the hardly observed ones
  //! (hardly_observed_fraction) where they are not: on textured backgrounds a weakly seen
  //! region the flow did move (a bumpy object's underside) is better left to the flow.
  UnobservedSpread spread = UnobservedSpread::Auto;
  //! Auto without fitted rims: a poorly observed vertex is moved only if it had a speed in at
  //! most this fraction of the iterations at its resolution. 0.25: better than not spreading on
  //! 13 of 15 textured scenes, and than 0, 0.1 and 0.5 (README, "Weakly seen regions"). [0, 1].
  double hardly_observed_fraction = 0.25;
  //! The same fraction at the first resolution's convergence (the coarsest mesh, before its
  //! first refinement): there the surface is still far from where the views put it, and a
  //! weakly seen region placed with the observed one at once need not be carried by its few
  //! grazing views through every level. 0.75: on the fifteen textured scenes 0.971× the error of
  //! 0.25 (better by > 3 % on 8, worse on none; 0.5: 0.982, 0.9: 0.970 with the bumpy sphere
  //! +3.4 %, 1: 0.946 with it +19.5 %), and on six scenes used for no choice 0.986× (README,
  //! "Weakly seen regions"). [0, 1].
  double first_hardly_observed_fraction = 0.75;
  //! At the end of the run (after the finest resolution), the poorly observed vertices that were
  //! observed in no iteration of that resolution (no speed, or implausibly high g with their ring
  //! in every one: implausible_g_ratio) follow the observed surface too, and stay: the
  //! flow never moved them there, so the spread cannot undo what it recovered, and without it
  //! such a region keeps the error of the last coarser level while its observed border goes on
  //! converging. Auto: where the rims are not fitted. In session 21 (the default until session
  //! 38) on the fifteen textured scenes 0.987× the error (better on 10, by > 3 % on 4; worse by at
  //! most 3.5 %, the grazing rig 100 % complete); with the rims fitted, on the photographs,
  //! held-out gain against the hull −27.15 → −27.21 % (dino) and −15.00 → −14.68 % (temple), so
  //! not there. Off (the default since session 38): with the flow of sessions 24–37 (surface
  //! patches at oblique vertices, far vertices, implausible g) the end spread costs more than it
  //! recovers: over the 32 synthetic scenes, three runs each, off gives 0.981× the error (better
  //! by > 3 % on 9, worse on 2), the accurate preset 0.999×, eight small rigs 1.011×; the
  //! photographs' runs fit the rims, so auto never spread there (README, "Weakly seen regions").
  //! Needs spread on or auto.
  UnobservedSpread spread_unmoved = UnobservedSpread::Off;
  //! A vertex counts as observed (in the last iteration, and in each iteration counted for
  //! hardly_observed_fraction) when it has a speed and one of the views it uses lies within this
  //! angle of its normal (degrees, in (0, 90]). 90: every vertex with a speed.
  double observed_angle_degrees = 90.0;
  //! The observed set is shrunk by this many vertex rings before it is followed (a vertex stays
  //! observed only if its whole one ring is, ring by ring): the ragged border of the observed
  //! region and isolated "observed" vertices inside an unobserved one are the least reliable
  //! (on a sphere whose cap is seen only at grazing angles, 0 rings left spikes of 0.03 in the
  //! cap, 2 or more pulled it in; README, "Quality"). ≥ 0.
  int erode_rings = 1;
  //! A vertex whose g exceeds this many times the median g of the vertices with a speed, and
  //! every one of whose neighbours with a speed does too, counts as not observed in that
  //! iteration: a region whose patches agree in no view (the background or an occluder shows
  //! through: no surface there to follow), which the flow leaves only by creeping (t2's peanut
  //! waist, top and bottom, 0.1 outside the truth with g 2000–2600× the median). A single such vertex
  //! amid ordinary ones (a grazing spot on a sphere) stays observed (one whose neighbours all lack
  //! a speed is not: its ring is unobserved already): without the neighbour
  //! condition (at 300×) the bumpy sphere lost 16 %. 1000: over 32 scenes × 3 runs 0.979× the
  //! error (t2 0.660, w4 0.776), issue 12's item 5 on all 36 sphere runs, the longest run 137
  //! iterations; 300: 0.969× but item 5 on 35, one run at the budget and 6 scenes worse by > 3 %
  //! (README, "Weakly seen regions"). The refiner does not apply it where the rims are fitted to
  //! silhouettes (a dark background, or mask files): they hold the outline there (dino's
  //! held-out gain −30.9 → −30.2 % with it, the temple's unchanged). 0 turns it off (the thesis
  //! preset); else > 1.
  double implausible_g_ratio = 1000.0;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! One flag per vertex: 1 when the last iteration gave it a speed (kSpeedDefined), it is not
//! one of implausible_g_vertices(mesh, fields, options.implausible_g_ratio) and, with
//! options.observed_angle_degrees < 90, one of the views in fields.visible(v) lies within that
//! angle of fields.normal[v]; 0 otherwise.
//! \throw Error if the options are invalid or the fields are not sized for the mesh.
std::vector<std::uint8_t> observed_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views,
                                            const VertexFields& fields,
                                            const UnobservedDisplacementOptions& options);
//! The same into \p observed (resized to the vertex count), so that a caller counting every
//! iteration reuses one buffer.
void observed_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views, const VertexFields& fields,
                       const UnobservedDisplacementOptions& options, std::vector<std::uint8_t>& observed);

//! One flag per vertex: 1 when the vertex has a speed (kSpeedDefined) and g above \p ratio times the
//! median g of the vertices with a speed, and so has every neighbour with a speed
//! (UnobservedDisplacementOptions::implausible_g_ratio); all 0 when \p ratio is 0 or that median is 0.
//! \throw Error if the fields are not sized for the mesh.
std::vector<std::uint8_t> implausible_g_vertices(const TriMesh& mesh, const VertexFields& fields, double ratio);

//! One flag per vertex: 1 unless observed_vertices() flags it (a speed, not implausibly high g,
//! with options.observed_angle_degrees < 90 a view within that angle of its normal), and the
//! same holds for every vertex within options.erode_rings
//! rings of it. A vertex with \p on_silhouette[v] != 0 (when given) counts as observed too, and
//! is not eroded: the silhouettes fix it (a rim the rims are fitted to), whatever the photo term
//! says. Without it the spread moved a temple's unseen base and changed its outline in the
//! held-out views (held-out gain −13.6 % → −11.1 %; README, "Weakly seen regions").
//! \throw Error if the options are invalid or the fields are not sized for the mesh.
std::vector<std::uint8_t> poorly_observed_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views,
                                                   const VertexFields& fields,
                                                   const UnobservedDisplacementOptions& options,
                                                   std::span<const std::uint8_t> on_silhouette = {});

//! Clears in \p poor every vertex that had a speed in more than \p fraction × \p iterations of
//! the last \p iterations iterations (\p speed_iterations[v] of them; one count per vertex).
//! \throw Error if the sizes differ.
void keep_hardly_observed(std::vector<std::uint8_t>& poor, std::span<const std::uint32_t> speed_iterations,
                          int iterations, double fraction);

struct DisplacementResult {
  std::size_t moved_vertices = 0;    //!< free vertices placed by the interpolation
  std::size_t skipped_vertices = 0;  //!< free vertices in regions with no fixed neighbour
};

//! For the vertices with \p free[v] != 0 (boundary vertices excepted): with R the \p reference
//! positions, N_R the area-weighted vertex normals of the mesh's faces at those positions and
//! d_j = (P_j − R_j)·N_R,j at the other vertices, solves Σ_j w_ij (d_j − d_i) = 0 at every free i
//! (w_ij the cotangent weights of the reference surface, on which d lives, clamped into
//! [0.01, 1000] so the system is positive definite) and sets P_i = R_i + d_i·N_R,i. A connected free region with no fixed
//! neighbour (nothing observed to follow) is left as it is and counted as skipped. Serial and
//! deterministic (one sparse Cholesky solve).
//! \param mesh      The surface, positions of free vertices modified; topology unchanged.
//! \param reference One position per vertex: where the flow started.
//! \param free      One flag per vertex.
//! \pre \p mesh has no deleted elements (ids contiguous).
//! \throw Error if a size differs from #V or the solve fails.
DisplacementResult spread_displacement(TriMesh& mesh, std::span<const Eigen::Vector3d> reference,
                                       std::span<const std::uint8_t> free);

//! Appends the reference positions of the vertices an adaptive refinement added (RefinementResult
//! ::parents): each the midpoint of its split edge's references, as the vertex itself is of the
//! edge's positions.
//! \throw Error if a parent is not an existing reference.
void extend_reference(std::vector<Eigen::Vector3d>& reference,
                      std::span<const std::array<std::uint32_t, 2>> parents);

}  // namespace mvflow
