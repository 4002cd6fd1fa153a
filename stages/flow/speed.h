#pragma once
// The speed of the weighted minimal surface flow, its per-block reduction, the CFL time step
// and the forward Euler move (thesis 4.13, 5.3.3; SPEC §3, §4).

#include <cstddef>
#include <limits>
#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/silhouette_constraint.h"

namespace mvflow {

struct SpeedOptions {
  //! Initial (balloon) speed v of thesis eq. 4.13, in 1/world units like H; finite. 0.001
  //! (thesis B.7).
  double velocity = 0.001;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Computes the speed of every vertex in \p vertices (thesis eq. 4.13 with an outward normal):
//!   F = −( g·(v + H) + ∇g·N ) · N,
//! where g = photo_consistency, ∇g = photo_gradient, H = mean_curvature, N = normal. Defined
//! (kSpeedDefined set) only where kPhotoDefined, kGradientDefined, kNormalDefined and
//! kCurvatureDefined are all set and F is finite; elsewhere F = 0 and kSpeedDefined cleared.
//! Writes fields.speed[v] and the kSpeedDefined bit for v in \p vertices only.
//! \param vertices Range of vertex ids, within [0, fields.size()).
//! \param options  Checked with check().
//! \param fields   Inputs and output as above, sized #V.
//! \throw Error if the options are invalid or the range is outside the fields.
void compute_speed(IndexRange vertices, const SpeedOptions& options, VertexFields& fields);

//! What one vertex block contributes to the global reductions of an iteration.
struct BlockPartial {
  double max_speed = 0.0;     //!< max |F| over vertices with kSpeedDefined (0 if none)
  double sum_g = 0.0;         //!< Σ g over vertices with kPhotoDefined, summed in id order
  std::size_t defined_g = 0;  //!< number of vertices with kPhotoDefined
};

//! The partial reductions of the block \p vertices (sequential, in vertex-id order).
//! \throw Error if the range is outside the fields.
BlockPartial reduce_block(IndexRange vertices, const VertexFields& fields);

//! Combines block partials strictly in the order given (the blocks' order), so a fixed block
//! structure gives the same sums bit for bit at any thread count (STYLE practice 6).
BlockPartial combine(const std::vector<BlockPartial>& partials);

//! The CFL time step (thesis 5.3.3, SPEC §4): with the spatial step Δ = k·Δx = e_min/2,
//!   Δt = cfl · (e_min / 2) / (√3 · max_P |F(P)|),
//! so the fastest vertex moves cfl·e_min/(2√3) ≈ 0.29·cfl shortest edges.
//! \param shortest_edge e_min, the shortest edge of the current mesh; > 0, finite.
//! \param max_speed     max |F| over the moving vertices; ≥ 0, finite.
//! \param cfl           Courant number; > 0, finite. 1 in the thesis preset.
//! \return Δt; 0 when max_speed == 0 (nothing moves: there is no finite CFL bound, and a zero
//!         step lets the step-small stopping rule end the run).
//! \throw Error for arguments out of range.
double cfl_time_step(double shortest_edge, double max_speed, double cfl = 1.0);

//! fields.local_edge[v] = the shortest edge incident to v, for v in \p vertices (+∞ for an
//! isolated vertex). Run before any block moves, so every block reads the same positions.
void compute_local_edges(const TriMesh& mesh, IndexRange vertices, VertexFields& fields);

//! The longest move of one vertex in one step: the smaller of a distance and a fraction of the
//! vertex's shortest incident edge (the CFL bound taken locally: a vertex that stays within a
//! fraction of its own edges cannot fold its faces).
struct MoveLimit {
  double distance = std::numeric_limits<double>::infinity();  //!< world units, > 0
  double local_edge_fraction = 0.0;  //!< × the shortest edge at the vertex; 0 = no local limit
};

//! The forward Euler update P ← P + dt·F(P) for every vertex in \p vertices with kSpeedDefined
//! or kSpeedFilled;
//! boundary vertices never move. Writes the positions of \p vertices only: the speed was
//! computed from the old positions of every block, so run it after all blocks' speeds.
//! \param mesh     The surface, #V vertices; positions of \p vertices are updated.
//! \param vertices Range of vertex ids, within [0, #V).
//! \param fields   Per-vertex arrays sized #V with the speed of this iteration.
//! \param dt       The time step (cfl_time_step); ≥ 0, finite.
//! \throw Error if dt or the sizes are invalid.
//! \param limit    How far one vertex may move; a faster vertex moves that far along F. No limit
//!                 (the default) moves every vertex by dt·F, as the thesis does.
//! \param inside   When given, no vertex leaves the visual hull (SilhouetteConstraint::limit_move).
//! \param moved    When given (#V entries), moved[v] = the length of v's move for v in \p vertices
//!                 (0 for a vertex that did not move).
void move_vertices(TriMesh& mesh, IndexRange vertices, const VertexFields& fields, double dt,
                   const MoveLimit& limit = {}, const SilhouetteConstraint* inside = nullptr,
                   std::vector<double>* moved = nullptr);

//! The median of |F| over the moving vertices (kSpeedDefined, not boundary); 0 if none.
//! Δt times this, divided by e_min, is what the step-small stopping rule reads (SPEC §4).
//! Allocates one buffer per call (a global reduction, not a per-block stage).
double median_speed(const TriMesh& mesh, const VertexFields& fields);

//! The median of \p values (the mean of the two middle ones for an even count); 0 when empty.
double median_of(std::vector<double> values);

//! median_of the g (fields.photo_consistency) of the vertices v, in id order, for which
//! \p counts(v) is true; 0 when there is none. The far-vertex and implausible-g rules take
//! their thresholds from it.
template <typename Counts>
double median_g_where(const VertexFields& fields, Counts counts) {
  std::vector<double> g;
  g.reserve(fields.size());
  for (std::size_t v = 0; v < fields.size(); ++v)
    if (counts(v)) g.push_back(fields.photo_consistency[v]);
  return median_of(std::move(g));
}

//! The \p quantile (in (0, 1]; 1 = the maximum) of |F| over the moving vertices, the value at
//! rank ceil(quantile·n) − 1 of the sorted speeds; 0 if none move. Allocates one buffer.
double speed_quantile(const TriMesh& mesh, const VertexFields& fields, double quantile);

}  // namespace mvflow
