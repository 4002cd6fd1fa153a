#pragma once
// g and its gradient at each vertex (SPEC §3; thesis §5.3.3): along each axis a, g is sampled
// at X + s·Δx·e_a for s = −k/2..k/2 (the centre shared: 3k+1 = 61 evaluations for k = 20), and
// ∂g/∂a = (1/Δx)·Σ_s c_s·g(X + sΔx e_a) with the Savitzky–Golay first-derivative coefficients
// c_s of a polynomial fit. Δx = e_min/(2k), so the fitting neighbourhood kΔx is e_min/2 (B.7).
// Every sample uses the vertex's own view set; a sample with fewer than 2 usable views makes the
// gradient undefined.

#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_views.h"
#include "stages/flow/savitzky_golay.h"

namespace mvflow {

struct PhotoGradientOptions {
  SavitzkyGolayOptions savitzky_golay;  //!< k = 20, quartic (thesis B.7)
  PhotoConsistencyOptions photo;        //!< patch used for every sample
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Precomputed Savitzky–Golay coefficients; one per run, shared by every block (read-only).
class PhotoGradientStage {
 public:
  explicit PhotoGradientStage(const PhotoGradientOptions& options = {});
  const PhotoGradientOptions& options() const { return options_; }
  const std::vector<double>& coefficients() const { return coefficients_; }
  //! Δx for a mesh whose shortest edge is \p shortest_edge: e_min / (2k).
  double sample_spacing(double shortest_edge) const { return options_.savitzky_golay.sample_spacing(shortest_edge); }

  //! g (photo_consistency, kPhotoDefined) and ∇g (photo_gradient, kGradientDefined) for the
  //! vertices of \p vertices, over their visible views. Writes only those vertices' entries.
  //! Patches laid on the surface read \p surface_views when given (the same cameras in the same
  //! order, other photographs: the refinement's blurred views serve the image patches only,
  //! DenoiseOptions), else \p views.
  void run(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views, double sample_spacing,
           VertexFields& fields, const std::vector<PhotoView>* surface_views = nullptr) const;

 private:
  PhotoGradientOptions options_;
  std::vector<double> coefficients_;
};

}  // namespace mvflow
