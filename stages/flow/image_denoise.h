#pragma once
// Noisy photographs are smoothed before the whole-pixel image patches read them (README,
// "Convergence"; the patches laid on the surface read the photographs as given). Image noise
// enters g and, through the Savitzky–Golay samples, ∇g: on renders with σ ≈ 0.006 per grey value
// the net move over five iterations hovers at 0.4–0.9 % of an edge for 30 iterations and the
// coarsest level takes 50 iterations instead of 28. A Gaussian blur just strong enough to bring
// the estimated noise (stages/flow/image_noise.h) down to a reference removes that jitter where it
// matters and leaves photographs at or below the reference untouched, bit for bit.

#include <memory>
#include <vector>

#include "engine/model/image.h"
#include "stages/flow/image_pyramid.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

enum class DenoiseUse {
  Off,   //!< the photographs as given (the thesis)
  Auto,  //!< blur when their estimated noise is above DenoiseOptions::noise_reference
};

struct DenoiseOptions {
  //! Auto; Off in the thesis preset.
  DenoiseUse use = DenoiseUse::Auto;
  //! σ_r on the [0, 1] grey scale: photographs whose estimated noise σ is above it are blurred
  //! with the Gaussian whose white-noise gain is σ_r/σ (denoise_sigma_for). 0.002, as
  //! StoppingOptions::settled_noise_reference: above what clean renders and the dino and temple
  //! photographs read (0.0006–0.0018), below noisy renders (0.003 and 0.0058). > 0.
  double noise_reference = 0.002;

  //! \throw OptionError naming the field out of range, its value and its valid values.
  void check() const;
};

//! Σ w_i² of the normalised 1-D Gaussian of standard deviation \p sigma pixels sampled at the
//! integers within ⌈3σ⌉ (the kernel gaussian_blur applies along each axis): white noise of
//! standard deviation s is left with s·gain after the 2-D blur. 1 for sigma ≤ 0.
double gaussian_noise_gain(double sigma);

//! The σ (pixels) whose gaussian_noise_gain is reference/noise, by bisection on [0, 8]; 0 when
//! noise ≤ reference (nothing to remove) and 8 when even that leaves more.
double denoise_sigma_for(double noise, double reference);

//! \p image convolved with the Gaussian of \p sigma pixels along rows, then columns, each channel
//! on its own, the border pixel repeated; the same bits on every machine (a plain loop in a fixed
//! order). sigma ≤ 0 returns a copy.
Image gaussian_blur(const Image& image, double sigma);

//! \p views with their photographs blurred by gaussian_blur (each on its own thread) and their
//! cameras copied: a level held by pointer, as the image pyramid's.
std::unique_ptr<ImageLevel> blurred_views(const std::vector<PhotoView>& views, double sigma);

}  // namespace mvflow
