#pragma once
// How far the surface has really moved over the last few iterations: the net move of each vertex
// along its normal over a window of iterations, not the sum of its steps. The settled stopping
// rule reads it (StoppingOptions::settled_tolerance).
//
// Why: at the finest level Σg/vertex keeps falling by about 1 % an iteration long after the
// error to the true surface has stopped changing (vertices sliding tangentially, noise in g
// averaged away), and a vertex that jitters across the minimum of g makes large steps with no
// net move. Neither is progress; a net move along the normal is.

#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

//! The positions of the last 2·window + 1 iterations of one topology, their net move and its
//! persistence from one window to the next.
class NetNormalMove {
 public:
  //! \param window The number of iterations the move is taken over; ≥ 1.
  explicit NetNormalMove(int window);

  //! Forgets the positions (a new topology: vertex ids no longer match).
  void reset();

  //! Records the mesh's current positions (after an iteration) and returns the median, over the
  //! vertices with kSpeedDefined that are not on a boundary, of |(P_now − P_window ago)·N| divided
  //! by the vertex's shortest edge (fields.local_edge), N = fields.normal. NaN until window + 1
  //! positions of this topology are recorded, or when no vertex counts.
  //! \throw Error if the fields are not sized for the mesh or the vertex count changed since the
  //!        last record without a reset.
  double record(const TriMesh& mesh, const VertexFields& fields);

  //! The 90th percentile (rank ⌈0.9·n⌉ of n, ascending) of the same ratios at the last record; NaN
  //! when that returned NaN. The tail the median does not see: at a settled stop the median can be
  //! 0.002 of an edge while a tenth of the vertices still move 0.15 (README, "Convergence").
  double last_tail() const { return last_tail_; }

  //! The persistence of the move at the last record: Σ a·b / Σ b² over the same vertices, a the
  //! signed net move along the normal over the last window and b over the window before it (both
  //! over the vertex's shortest edge, along the current normal): about 1 where the surface creeps on
  //! steadily, 0 for moves that do not carry on, below 0 where vertices step back and forth. NaN
  //! until 2·window + 1 positions of this topology are recorded, or when Σ b² is 0. The Σg rule
  //! cannot tell these apart: at the finest level a creeping minority (a waist seen against the
  //! background) and a surface jittering about its minimum both leave Σg per vertex flat within its
  //! noise (README, "Convergence").
  double last_persistence() const { return last_persistence_; }

  int window() const { return window_; }
  //! Positions recorded since the last reset.
  std::size_t recorded() const { return recorded_; }

  //! The mean, vertex by vertex, of the last \p count recorded positions of this topology (the
  //! newest first, summed in that order), into \p mean; false, and \p mean untouched, when fewer
  //! were recorded since the reset. 1 ≤ count ≤ 2·window + 1.
  //! \throw Error if count is out of that range.
  bool mean_of_last(std::size_t count, std::vector<Eigen::Vector3d>& mean) const;

 private:
  int window_;
  std::vector<std::vector<Eigen::Vector3d>> ring_;  // 2·window + 1 slots, the oldest at next_
  std::size_t next_ = 0;                             // the slot the next record overwrites
  std::size_t recorded_ = 0;                         // positions recorded since the reset
  double last_tail_ = std::numeric_limits<double>::quiet_NaN();         // last_tail()
  double last_persistence_ = std::numeric_limits<double>::quiet_NaN();  // last_persistence()
};

}  // namespace mvflow
