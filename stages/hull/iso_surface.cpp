#include "stages/hull/iso_surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

namespace {

// Corner c of a cell sits at offset (c & 1, c >> 1 & 1, c >> 2 & 1). The Kuhn split: one
// tetrahedron 0 → a → a|b → 7 per ordering (a, b, c) of the three axis bits. Every cell uses the
// same split, so each square face is cut along the same diagonal from both sides.
constexpr std::array<std::array<int, 4>, 6> kTetrahedra{
    {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};

struct Corner {
  std::uint64_t sample = 0;  //!< index into the grid's values
  Eigen::Vector3d position;
  double value = 0.0;
  bool inside = false;
};

class Extractor {
 public:
  Extractor(const ScalarGrid& grid, const IsoSurfaceOptions& options) : grid_(grid), options_(options) {}

  IndexedMesh run() {
    const auto& n = grid_.size;
    std::array<Corner, 8> corners;
    for (int k = 0; k + 1 < n[2]; ++k)
      for (int j = 0; j + 1 < n[1]; ++j)
        for (int i = 0; i + 1 < n[0]; ++i) {
          int inside = 0;
          for (int c = 0; c < 8; ++c) {
            const int x = i + (c & 1), y = j + (c >> 1 & 1), z = k + (c >> 2 & 1);
            Corner& corner = corners[c];
            corner.sample = grid_.index(x, y, z);
            corner.value = grid_.values[corner.sample];
            corner.inside = corner.value > options_.level;
            inside += corner.inside;
          }
          if (inside == 0 || inside == 8) continue;
          for (int c = 0; c < 8; ++c) corners[c].position = grid_.point(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
          for (const auto& tetrahedron : kTetrahedra)
            march({&corners[tetrahedron[0]], &corners[tetrahedron[1]], &corners[tetrahedron[2]], &corners[tetrahedron[3]]});
        }
    return std::move(mesh_);
  }

 private:
  const ScalarGrid& grid_;
  const IsoSurfaceOptions& options_;
  IndexedMesh mesh_;
  std::unordered_map<std::uint64_t, std::uint32_t> vertex_of_edge_;

  //! The vertex where the level crosses the lattice edge (a, b), created on first request. It is
  //! computed from the lower sample's end, so it is the same whichever tetrahedron asks first.
  std::uint32_t crossing(const Corner* a, const Corner* b) {
    if (a->sample > b->sample) std::swap(a, b);
    const std::uint64_t key = a->sample << 32 | b->sample;
    const auto [it, added] = vertex_of_edge_.try_emplace(key, static_cast<std::uint32_t>(mesh_.positions.size()));
    if (added) {
      const double m = options_.min_edge_fraction;
      const double t = std::clamp((options_.level - a->value) / (b->value - a->value), m, 1.0 - m);
      mesh_.positions.push_back(a->position + t * (b->position - a->position));
    }
    return it->second;
  }

  //! Adds the triangle, turned so that its normal points towards \p outside (a sample outside):
  //! the triangle separates the tetrahedron's inside corners from its outside ones.
  void emit(std::uint32_t a, std::uint32_t b, std::uint32_t c, const Eigen::Vector3d& outside) {
    const Eigen::Vector3d& pa = mesh_.positions[a];
    const Eigen::Vector3d normal = (mesh_.positions[b] - pa).cross(mesh_.positions[c] - pa);
    if (normal.dot(outside - pa) < 0.0) std::swap(b, c);
    mesh_.triangles.push_back({a, b, c});
  }

  void march(const std::array<const Corner*, 4>& t) {
    std::array<const Corner*, 4> in{}, out{};
    int n_in = 0, n_out = 0;
    for (const Corner* c : t) (c->inside ? in[n_in++] : out[n_out++]) = c;
    if (n_in == 0 || n_out == 0) return;
    if (n_in == 1) {
      emit(crossing(in[0], out[0]), crossing(in[0], out[1]), crossing(in[0], out[2]), out[0]->position);
    } else if (n_out == 1) {
      emit(crossing(out[0], in[0]), crossing(out[0], in[1]), crossing(out[0], in[2]), out[0]->position);
    } else {
      // A quadrilateral through the four edges between the two inside and the two outside
      // corners, in cyclic order (consecutive edges share a face of the tetrahedron).
      const std::uint32_t q0 = crossing(in[0], out[0]), q1 = crossing(in[0], out[1]);
      const std::uint32_t q2 = crossing(in[1], out[1]), q3 = crossing(in[1], out[0]);
      emit(q0, q1, q2, out[0]->position);
      emit(q0, q2, q3, out[0]->position);
    }
  }
};

}  // namespace

void IsoSurfaceOptions::check() const {
  require_option(std::isfinite(level), "level", level, "a finite number");
  require_option(min_edge_fraction >= 0.0 && min_edge_fraction <= 0.25, "min_edge_fraction", min_edge_fraction,
                 "[0, 0.25]");
}

IndexedMesh extract_iso_surface(const ScalarGrid& grid, const IsoSurfaceOptions& options) {
  options.check();
  if (grid.values.size() != grid.count() || !(grid.spacing > 0.0))
    throw InputError("iso-surface: the grid's values do not match its size, or its spacing is not positive");
  return Extractor(grid, options).run();
}

}  // namespace mvflow
