#pragma once
// Speed for the vertices the photographs do not constrain (README, "Defaults and differences"):
// where g or ∇g is undefined (grazing views only, occluded, outside every image) the flow has no
// speed, so such a region would keep its initial error while its observed border moves. Here an
// unobserved vertex takes the mean normal speed of its neighbours that already have one, ring by
// ring outward from the observed region (a breadth-first front, each ring reading only the rings
// before it), along its own normal: the region moves with the observed surface it joins, and
// smoothing keeps it fair.

#include "engine/mesh.h"
#include "engine/vertex_fields.h"

namespace mvflow {

struct UnobservedSpeedOptions {
  //! Fill unobserved vertices' speeds from their observed neighbours. false (the default and
  //! the thesis, §5.3.3): they do not move by the flow, only by smoothing and regularization.
  //! Off by default: it made every measured scene worse (README, "Defaults and differences").
  bool fill = false;
  //! Rings outward from the observed region that are filled; farther vertices stay unmoved.
  //! ≥ 1.
  int max_rings = 1000;
  bool check() const { return max_rings >= 1; }
};

//! For every vertex without kSpeedDefined whose normal is defined and that is not on a boundary:
//! F = s̄·N with s̄ the mean of F_j·N_j over the one-ring neighbours j that have a speed
//! (kSpeedDefined, or filled in an earlier ring); sets kSpeedFilled. Serial, in vertex-id order
//! within each ring, so the result does not depend on blocks or threads.
//! \return the number of vertices filled.
std::size_t fill_unobserved_speeds(const TriMesh& mesh, const UnobservedSpeedOptions& options, VertexFields& fields);

}  // namespace mvflow
