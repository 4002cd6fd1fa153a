#pragma once
// Per-vertex quantities that the stages compute each iteration, as flat typed arrays indexed by
// vertex id (struct of arrays). Stages write only the entries of their own vertex block, so
// blocks can run in parallel; no std::vector<bool> anywhere (it packs bits and is not safe to
// write from parallel blocks).

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace mvflow {

//! Bits of VertexFields::defined: which quantities of a vertex are meaningful this iteration.
enum VertexDefined : std::uint8_t {
  kNormalDefined = 1u << 0,
  kCurvatureDefined = 1u << 1,
  kPhotoDefined = 1u << 2,     //!< g is defined (≥ 2 usable views)
  kGradientDefined = 1u << 3,  //!< every one of the 3k+1 samples had ≥ 2 views
  kSpeedDefined = 1u << 4,
  //! F was not observed (no defined g or ∇g) but taken from observed neighbours
  //! (stages/flow/unobserved_speed.h): the vertex moves, the step size and stopping rules ignore it.
  kSpeedFilled = 1u << 5,
  //! g's patch is of another kind than in the previous iteration of this mesh (PatchKind)
  kPatchSwitched = 1u << 6,
};

//! The kind of patch g used at a vertex in the last evaluation of its gradient
//! (PhotoConsistencyOptions::surface_patch): kept between iterations of one mesh, so that the
//! report can count the vertices that switch kind; Undecided after a change of topology.
enum class PatchKind : std::uint8_t { Undecided = 0, Image, Surface };

struct VertexFields {
  std::vector<Eigen::Vector3d> normal;       //!< outward unit normal N
  std::vector<double> mean_curvature;        //!< H (1/r on a sphere of radius r)
  //! |Σ_j c_j (Q_j − P)| / 2, the unnormalized mean-curvature-normal length (cotangent weights,
  //! no area division) that adaptive refinement compares with e_S/2 (SPEC §5); valid where
  //! kCurvatureDefined is set, 0 elsewhere.
  std::vector<double> curvature_normal_length;
  std::vector<double> photo_consistency;     //!< g
  std::vector<Eigen::Vector3d> photo_gradient;  //!< ∇g
  std::vector<Eigen::Vector3d> speed;        //!< F
  std::vector<double> local_edge;            //!< shortest edge at the vertex (the local CFL length)
  std::vector<std::uint8_t> defined;         //!< VertexDefined bits
  std::vector<PatchKind> patch_kind;         //!< the patch g used at the vertex last (see PatchKind)
  //! Visible views of vertex v: visible_views[v·view_capacity + 0 .. visible_count[v]-1].
  std::vector<std::uint16_t> visible_views;
  std::vector<std::uint16_t> visible_count;
  std::size_t view_capacity = 0;

  std::size_t size() const { return defined.size(); }
  //! The visible views of vertex \p v (ids into the view list), in the order visibility found them.
  std::span<const std::uint16_t> visible(std::size_t v) const {
    return {visible_views.data() + v * view_capacity, visible_count[v]};
  }
  //! Sizes every array for \p n_vertices and \p n_views (contents reset to zero).
  void resize(std::size_t n_vertices, std::size_t n_views);
};

//! A contiguous range [begin, end) of vertex (or face) ids that a stage processes on its own.
struct IndexRange {
  std::uint32_t begin = 0;
  std::uint32_t end = 0;
  std::uint32_t size() const { return end - begin; }
};

//! Cuts [0, count) into consecutive blocks of \p block_size (the last one may be shorter).
//! Depends only on its arguments, never on the thread count.
std::vector<IndexRange> split_into_blocks(std::size_t count, std::size_t block_size);

}  // namespace mvflow
