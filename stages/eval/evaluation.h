#pragma once
// How far a mesh is from a ground-truth surface (SPEC §8; Seitz et al., CVPR 2006):
// accuracy = the distance d such that a fraction (90 %) of the mesh's surface samples lie within
// d of the ground truth; completeness = the fraction of ground-truth samples within a threshold
// of the mesh; plus mean, RMS and maximum (Hausdorff) distances in both directions.

#include <cstdint>
#include <vector>

#include "engine/model/mesh.h"

namespace mvflow {

struct EvaluationOptions {
  std::size_t samples = 200000;           //!< surface samples per mesh, uniform by area
  double accuracy_fraction = 0.9;         //!< accuracy is this quantile of mesh→truth distances
  double completeness_threshold = 0.01;   //!< relative to the truth's bounding-box diagonal
  std::uint64_t seed = 1;                 //!< sampling is deterministic for a given seed
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Distances from one surface's samples to another surface.
struct DirectedDistances {
  double mean = 0.0;
  double rms = 0.0;
  double max = 0.0;
  double quantile = 0.0;        //!< at EvaluationOptions::accuracy_fraction
  double within_threshold = 0.0;  //!< fraction of samples within the completeness threshold
};

struct EvaluationResult {
  double truth_diagonal = 0.0;     //!< bounding-box diagonal of the ground truth (absolute unit)
  double threshold = 0.0;          //!< completeness threshold in absolute units
  DirectedDistances mesh_to_truth;  //!< accuracy side
  DirectedDistances truth_to_mesh;  //!< completeness side
  double accuracy() const { return mesh_to_truth.quantile; }
  double completeness() const { return truth_to_mesh.within_threshold; }
  double symmetric_mean() const { return 0.5 * (mesh_to_truth.mean + truth_to_mesh.mean); }
  double symmetric_rms() const;
  double hausdorff() const { return std::max(mesh_to_truth.max, truth_to_mesh.max); }
};

//! \p count points uniformly distributed by area over the triangles (deterministic for \p seed).
//! \throw InputError when the mesh has no area.
std::vector<Eigen::Vector3d> sample_surface(const IndexedMesh& mesh, std::size_t count, std::uint64_t seed);

//! Compares \p mesh with \p truth. Exact point–triangle distances through Embree point queries,
//! parallel over samples (TBB); the result does not depend on the thread count.
//! \throw InputError for an empty mesh or truth, or invalid options.
EvaluationResult evaluate_against_truth(const IndexedMesh& mesh, const IndexedMesh& truth,
                                        const EvaluationOptions& options = {});

}  // namespace mvflow
