#pragma once
// Speed for the vertices the photographs do not constrain (README, "Defaults and differences"):
// where g or ∇g is undefined (grazing views only, occluded, outside every image) the flow has no
// speed, so such a region would keep its initial error while its observed border moves. Here an
// unobserved vertex takes the mean of its neighbours' normal rates, ring by ring outward from the
// observed region (a breadth-first front, each ring reading only the rings before it), along its
// own normal: the region moves with the observed surface it joins, and smoothing keeps it fair.
// The engine passes as the observed rate the whole last step of a vertex (flow, smoothing and
// regularization together) per unit time, not its flow speed alone: at equilibrium the flow's
// speed is balanced by the smoothing, so a region that copied the speed alone would drift.

#include <span>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

struct UnobservedSpeedOptions {
  //! Fill unobserved vertices' speeds from their observed neighbours. false (the default and
  //! the thesis, §5.3.3): they do not move by the flow, only by smoothing and regularization.
  //! Off by default: it made every measured scene worse (README, "Defaults and differences").
  bool fill = false;
  //! Rings outward from the observed region that are filled; farther vertices stay unmoved.
  //! ≥ 1.
  int max_rings = 1000;
  //! A vertex counts as unobserved too when every view it uses lies beyond this angle to its
  //! normal (degrees; seen only obliquely, its g and ∇g are unreliable). 90: only vertices
  //! without a speed.
  double weak_angle_degrees = 90.0;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Clears kSpeedDefined (and the speed) of the vertices whose views all lie beyond
//! options.weak_angle_degrees from their normal, so that fill_unobserved_speeds treats them as
//! unobserved. Nothing when options.fill is false. \return the number of vertices demoted.
std::size_t demote_weakly_seen(const TriMesh& mesh, const std::vector<PhotoView>& views,
                               const UnobservedSpeedOptions& options, VertexFields& fields);

//! For every vertex without kSpeedDefined whose normal is defined and that is not on a boundary:
//! F = s̄·N with s̄ the mean over its one-ring neighbours j that have a rate of that rate: \p rate[j]
//! for an observed neighbour (kSpeedDefined), s̄_j for one filled in an earlier ring. Sets
//! kSpeedFilled. Serial, in vertex-id order within each ring, so the result does not depend on
//! blocks or threads.
//! \param rate One normal rate per vertex (read for observed vertices only), e.g. F·N.
//! \return the number of vertices filled.
std::size_t fill_unobserved_speeds(const TriMesh& mesh, const UnobservedSpeedOptions& options,
                                   std::span<const double> rate, VertexFields& fields);

}  // namespace mvflow
