#include "stages/photo_gradient.h"

#include <span>

#include "engine/error.h"

namespace mvflow {

PhotoGradientStage::PhotoGradientStage(const PhotoGradientOptions& options)
    : options_(options) {
  MVFLOW_CHECK(options.check(), "photo gradient options out of range");
  coefficients_ = savitzky_golay_derivative_coefficients(options.savitzky_golay.half_window(),
                                                         options.savitzky_golay.order);
}

void PhotoGradientStage::run(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                             double sample_spacing, VertexFields& fields) const {
  MVFLOW_CHECK(sample_spacing > 0, "photo gradient: sample spacing must be positive");
  const int half = options_.savitzky_golay.half_window();
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    const std::span<const std::uint16_t> visible(fields.visible_views.data() + v * fields.view_capacity,
                                                 fields.visible_count[v]);
    const Eigen::Vector3d X = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
    std::uint8_t& defined = fields.defined[v];
    defined &= static_cast<std::uint8_t>(~(kPhotoDefined | kGradientDefined));
    fields.photo_consistency[v] = 0.0;
    fields.photo_gradient[v].setZero();

    const PhotoValue centre = photo_consistency(X, visible, views, options_.photo);
    if (!centre.defined()) continue;
    fields.photo_consistency[v] = centre.g;
    defined |= kPhotoDefined;

    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    bool complete = true;
    for (int axis = 0; axis < 3 && complete; ++axis) {
      double derivative = 0.0;
      for (int s = -half; s <= half && complete; ++s) {
        const double c = coefficients_[static_cast<std::size_t>(s + half)];
        if (s == 0) {
          derivative += c * centre.g;  // the centre sample is shared by the three axes
          continue;
        }
        Eigen::Vector3d sample = X;
        sample[axis] += s * sample_spacing;
        const PhotoValue value = photo_consistency(sample, visible, views, options_.photo);
        complete = value.defined();
        derivative += c * value.g;
      }
      gradient[axis] = derivative / sample_spacing;
    }
    if (!complete) continue;
    fields.photo_gradient[v] = gradient;
    defined |= kGradientDefined;
  }
}

}  // namespace mvflow
