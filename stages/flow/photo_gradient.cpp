#include "stages/flow/photo_gradient.h"

#include <span>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/photo_kernel.h"
#include "stages/flow/photo_robust.h"
#include "stages/flow/surface_patch.h"

namespace mvflow {

void PhotoGradientOptions::check() const {
  check_member(savitzky_golay, "savitzky_golay");
  check_member(photo, "photo");
}

PhotoGradientStage::PhotoGradientStage(const PhotoGradientOptions& options)
    : options_(options) {
  options.check();
  coefficients_ = savitzky_golay_derivative_coefficients(options.savitzky_golay.half_window(),
                                                         options.savitzky_golay.order);
}

void PhotoGradientStage::run(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                             double sample_spacing, VertexFields& fields,
                             const std::vector<PhotoView>* surface_views) const {
  MVFLOW_CHECK(sample_spacing > 0, "photo gradient: sample spacing must be positive");
  const int half = options_.savitzky_golay.half_window();
  const PhotoConsistencyOptions& photo = options_.photo;
  // The 5×5 image patch's own kernel, where a vertex does not lay its patch on the surface.
  const bool default_patch = photo.half_patch == 2 && !photo.normalize;
  const bool surface_everywhere = photo.surface_patch == SurfacePatchUse::On;
  // Buffers for the whole block: no allocation per vertex.
  std::vector<PhotoValue> samples(static_cast<std::size_t>(6 * half + 1));
  std::vector<ViewGainBias> maps;  // with normalisation, one per visible view
  SurfacePatchLayout layout;       // with surface patches
  const std::vector<PhotoView>& laid = surface_views ? *surface_views : views;  // for surface patches
  const auto position = [&](std::uint32_t v) { return to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v)))); };
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    const std::span<const std::uint16_t> visible = fields.visible(v);
    const Eigen::Vector3d X = position(v);
    // The next vertex's image blocks travel to the cache while this vertex's 61 samples run.
    if (v + 1 < vertices.end && default_patch && !surface_everywhere)
      detail::prefetch_patches(position(v + 1), fields.visible(v + 1), views);
    std::uint8_t& defined = fields.defined[v];
    defined &= static_cast<std::uint8_t>(~(kPhotoDefined | kGradientDefined | kPatchSwitched));
    fields.photo_consistency[v] = 0.0;
    fields.photo_gradient[v].setZero();

    // samples[0] = g(X); samples[1 + axis·2·half + i]: s = −half..−1, 1..half (the centre is
    // shared by the axes).
    // The kind of patch is decided afresh every iteration; the previous one is kept only to count
    // the switches (a hysteresis of ±5° or ±10° around the angle was worse: README).
    const bool surface = uses_surface_patch(X, fields.normal[v], visible, views, photo);
    const PatchKind kind = surface ? PatchKind::Surface : PatchKind::Image;
    if (fields.patch_kind[v] != PatchKind::Undecided && fields.patch_kind[v] != kind) defined |= kPatchSwitched;
    fields.patch_kind[v] = kind;
    if (surface) {
      layout_surface_patch(X, fields.normal[v], visible, laid, photo.half_patch, photo.surface_patch_spacing, layout);
      // The next vertex's rows travel to the cache while this one's samples run.
      if (v + 1 < vertices.end && surface_everywhere) detail::prefetch_surface_patches(position(v + 1), layout, laid);
      surface_patch_samples(X, sample_spacing, half, layout, laid, samples);
    } else if (default_patch) {
      detail::photo_consistency_5x5_samples(X, sample_spacing, half, visible, views, samples);
    } else if (photo.normalize) {
      // One map per view, taken at X, for every sample: g stays smooth along the sample lines.
      gain_bias_at(X, visible, views, photo.half_patch, photo.noise_floor, maps);
      for_each_gradient_sample(X, sample_spacing, half, [&](std::size_t slot, const Eigen::Vector3d& point) {
        samples[slot] = normalized_photo_consistency(point, visible, maps, views, photo.half_patch);
        return samples[0].defined();
      });
    } else {
      for_each_gradient_sample(X, sample_spacing, half, [&](std::size_t slot, const Eigen::Vector3d& point) {
        samples[slot] = photo_consistency(point, visible, views, options_.photo);
        return samples[0].defined();
      });
    }
    const PhotoValue centre = samples[0];
    if (!centre.defined()) continue;
    fields.photo_consistency[v] = centre.g;
    defined |= kPhotoDefined;

    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    bool complete = true;
    for (int axis = 0; axis < 3 && complete; ++axis) {
      const PhotoValue* line = samples.data() + 1 + static_cast<std::size_t>(axis) * 2 * half;
      double derivative = 0.0;
      for (int s = -half; s <= half && complete; ++s) {
        const double c = coefficients_[static_cast<std::size_t>(s + half)];
        if (s == 0) {
          derivative += c * centre.g;
          continue;
        }
        const PhotoValue& value = line[s < 0 ? s + half : s + half - 1];
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
