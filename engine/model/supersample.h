#pragma once
// The supersampled pixel every renderer shares (synthetic scenes, `mvflow render`, the held-out
// view error): n×n rays through a regular grid of sub-pixel centres.

#include "engine/model/camera.h"

namespace mvflow {

//! Calls \p sample(ray) for the n×n sub-pixel centres of pixel (x, y), row by row. Pixel (x, y)
//! covers [x − ½, x + ½) × [y − ½, y + ½) (SPEC §2), so its centre is (x, y).
template <typename Sample>
void for_each_subpixel_ray(const Camera& camera, int x, int y, int n, Sample&& sample) {
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) sample(camera.ray(x + (i + 0.5) / n - 0.5, y + (j + 0.5) / n - 0.5));
}

}  // namespace mvflow
