#pragma once
// How noisy the photographs are, for the settled stopping rule (StoppingOptions::
// settled_noise_reference): Immerkær's estimate of the standard deviation of additive noise
// (J. Immerkær, "Fast noise variance estimation", CVIU 64(2), 1996). The 3×3 mask
// [1 −2 1; −2 4 −2; 1 −2 1] is the difference of two discrete Laplacians: it gives 0 on any
// locally planar intensity, so on photographs smooth at the pixel scale what it responds to is
// the noise, σ = √(π/2) / (6·N) · Σ |I ∗ M| over N pixels. Texture, edges and shading detail add to
// the response, so the mask is summed only over the flattest pixels (smallest Sobel gradient):
// on clean renders of textured scenes the whole-image mean reads 0.0039 at 320×240, the flattest
// tenth 0.0013 (README "Convergence").

#include <vector>

#include "engine/model/image.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

//! The share of an image's pixels, those with the smallest gradient, the estimate reads.
inline constexpr double kNoiseFlattestFraction = 0.1;

//! σ of the noise of \p image's grey values (the mean of R, G and B), on the image's [0, 1]
//! scale, read on its kNoiseFlattestFraction flattest interior pixels; 0 for an image smaller
//! than 3×3 pixels.
double estimate_image_noise(const Image& image);

//! The median over \p views of estimate_image_noise of their images (the lower middle one for an
//! even count), each view's on its own thread; 0 without views.
double estimate_views_noise(const std::vector<PhotoView>& views);

}  // namespace mvflow
