#pragma once
// Initial meshes for synthetic scenes: what refinement starts from. Same topology as the
// ground truth, but with its detail lost, so there is something to recover.

#include <cstdint>

#include "engine/model/mesh.h"

namespace mvflow {

enum class InitialMeshKind {
  Offset,  //!< truth smoothed (volume kept), pushed out along the normals, decimated
  Noise,   //!< truth decimated, each vertex moved along its normal by a random amount
  Hull     //!< the visual hull of the truth's silhouettes in the rendered views (make_synth_scene)
};

struct InitialMeshOptions {
  InitialMeshKind kind = InitialMeshKind::Offset;
  double amount = 0.01;   //!< D: offset, or largest noise displacement, × the truth's box diagonal (0..0.5)
  int vertices = 1000;    //!< target vertex count after decimation (≥ 20; no decimation above the truth's)
  //! Offset: length ℓ over which detail is smoothed away, × the box diagonal (0..0.5). Laplacian
  //! diffusion damps a surface wave of angular frequency ω by about exp(−ω²ℓ²).
  double smoothing = 0.1;
  std::uint64_t seed = 1;   //!< Noise: the displacements
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! The initial mesh for \p truth (closed, manifold). Texture coordinates are dropped.
//! \throw InputError when \p truth is not a closed manifold mesh, or for the kind Hull, which
//!        needs the views (make_synth_scene builds it).
IndexedMesh make_initial_mesh(const IndexedMesh& truth, const InitialMeshOptions& options);

//! Laplacian diffusion (normalized cotangent weights clamped at 0, λ = 0.5) of \p mesh over
//! the length \p length (world units), then a scaling about the centroid that restores the enclosed volume (Desbrun et al. 1999), so
//! the surface loses its detail but not its size. Positions only; topology unchanged.
//! \return the number of smoothing steps taken.
int smooth_keeping_volume(IndexedMesh& mesh, double length);

//! Quadric-error edge collapses (OpenMesh Decimater, normal flips forbidden) down to
//! \p vertices; keeps a closed manifold mesh closed and manifold.
IndexedMesh decimate(const IndexedMesh& mesh, int vertices);

}  // namespace mvflow
