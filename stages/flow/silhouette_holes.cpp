#include "stages/flow/silhouette_holes.h"

#include <cstdint>

namespace mvflow {

namespace {

//! 4-connected background regions: region id per pixel (-1 for object pixels), and per region
//! its area and whether it touches the image border. Ids in the order of the first pixel.
struct BackgroundRegions {
  std::vector<std::int32_t> id;
  std::vector<std::size_t> area;
  std::vector<std::uint8_t> touches_border;
};

BackgroundRegions background_regions(const Mask& mask) {
  const int w = mask.width, h = mask.height;
  BackgroundRegions regions;
  regions.id.assign(mask.inside.size(), -1);
  std::vector<std::size_t> stack;
  for (std::size_t seed = 0; seed < mask.inside.size(); ++seed) {
    if (mask.inside[seed] != 0 || regions.id[seed] >= 0) continue;
    const auto region = static_cast<std::int32_t>(regions.area.size());
    std::size_t area = 0;
    bool border = false;
    regions.id[seed] = region;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t p = stack.back();
      stack.pop_back();
      ++area;
      const int x = static_cast<int>(p % w), y = static_cast<int>(p / w);
      border = border || x == 0 || y == 0 || x == w - 1 || y == h - 1;
      auto visit = [&](int xx, int yy) {
        if (xx < 0 || yy < 0 || xx >= w || yy >= h) return;
        const std::size_t q = static_cast<std::size_t>(yy) * w + xx;
        if (mask.inside[q] != 0 || regions.id[q] >= 0) return;
        regions.id[q] = region;
        stack.push_back(q);
      };
      visit(x - 1, y);
      visit(x + 1, y);
      visit(x, y - 1);
      visit(x, y + 1);
    }
    regions.area.push_back(area);
    regions.touches_border.push_back(border);
  }
  return regions;
}

}  // namespace

std::vector<std::size_t> silhouette_hole_areas(const Mask& mask) {
  const BackgroundRegions regions = background_regions(mask);
  std::vector<std::size_t> holes;
  for (std::size_t r = 0; r < regions.area.size(); ++r)
    if (!regions.touches_border[r]) holes.push_back(regions.area[r]);
  return holes;
}

Mask fill_silhouette_holes(const Mask& mask, std::size_t max_area) {
  if (max_area == 0) return mask;
  const BackgroundRegions regions = background_regions(mask);
  Mask filled = mask;
  for (std::size_t p = 0; p < filled.inside.size(); ++p) {
    const std::int32_t r = regions.id[p];
    if (r >= 0 && !regions.touches_border[r] && regions.area[r] <= max_area) filled.inside[p] = 1;
  }
  return filled;
}

}  // namespace mvflow
