#include "stages/synth/synth_objects.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <vector>

#include "engine/model/bounding_box.h"
#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/primitives.h"

namespace mvflow {

namespace {

// Smooth bumps on the unit sphere. The second term, rotated and at another frequency, breaks
// the symmetry of the first so no two bumps look alike.
double bumps(const Eigen::Vector3d& p, double f) {
  const double a = std::sin(f * p.x()) * std::sin(f * p.y()) * std::sin(f * p.z());
  const Eigen::Vector3d q(0.6 * p.x() + 0.8 * p.z(), p.y(), -0.8 * p.x() + 0.6 * p.z());
  const double g = 0.7 * f;
  const double b = std::cos(g * q.x() + 0.5) * std::cos(g * q.y() + 1.3) * std::cos(g * q.z() + 2.1);
  return 0.6 * a + 0.4 * b;
}

IndexedMesh star_shaped(const BuiltinShapeOptions& options, double (*base_radius)(const Eigen::Vector3d&, double)) {
  options.check();
  IndexedMesh mesh = make_icosphere(1.0, options.level);
  for (auto& p : mesh.positions) {
    const Eigen::Vector3d direction = p.normalized();
    p = direction * (base_radius(direction, options.waist) + options.amplitude * bumps(direction, options.frequency));
  }
  return mesh;
}

}  // namespace

void BuiltinShapeOptions::check() const {
  require_option(level >= 1 && level <= 7, "level", level, "[1, 7]");
  require_option(amplitude >= 0 && amplitude <= 0.5, "amplitude", amplitude, "[0, 0.5]");
  require_option(frequency > 0 && frequency <= 40, "frequency", frequency, "(0, 40]");
  require_option(waist >= 0.2 && waist <= 1, "waist", waist, "[0.2, 1]");
}

IndexedMesh make_bumpy_sphere(const BuiltinShapeOptions& options) {
  return star_shaped(options, [](const Eigen::Vector3d&, double) { return 1.0; });
}

IndexedMesh make_peanut(const BuiltinShapeOptions& options) {
  // With amplitude ≤ 0.5 and waist ≥ 0.2 the radius stays positive, so the surface is embedded.
  BuiltinShapeOptions scaled = options;
  scaled.amplitude = std::min(options.amplitude, 0.5 * options.waist);
  return star_shaped(scaled, [](const Eigen::Vector3d& d, double waist) { return waist + (1.0 - waist) * d.x() * d.x(); });
}

Normalization normalize_to_unit_box(IndexedMesh& mesh) {
  if (mesh.positions.empty() || mesh.triangles.empty()) throw InputError("object mesh: it has no triangles");
  BoundingBox box;
  for (const auto& p : mesh.positions) box.extend(p);
  const double longest = box.size().maxCoeff();
  if (!(longest > 0) || !std::isfinite(longest)) throw InputError("object mesh: its bounding box has no extent");
  Normalization n{box.centre(), 2.0 / longest};
  for (auto& p : mesh.positions) p = n.scale * (p - n.centre);
  return n;
}

std::size_t split_pinched_vertices(IndexedMesh& mesh) {
  std::vector<std::vector<std::uint32_t>> incident(mesh.positions.size());
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f)
    for (auto v : mesh.triangles[f]) incident[v].push_back(f);
  const std::size_t original = mesh.positions.size();
  for (std::uint32_t v = 0; v < original; ++v) {
    const auto& faces = incident[v];
    if (faces.size() < 2) continue;
    // Faces around v are in one fan when linked through edges (v, w): union-find over them.
    std::vector<std::size_t> parent(faces.size());
    std::iota(parent.begin(), parent.end(), std::size_t{0});
    const auto root = [&](std::size_t i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    std::map<std::uint32_t, std::size_t> first_face_with;
    for (std::size_t i = 0; i < faces.size(); ++i)
      for (auto w : mesh.triangles[faces[i]]) {
        if (w == v) continue;
        const auto [it, inserted] = first_face_with.emplace(w, i);
        if (!inserted) parent[root(i)] = root(it->second);
      }
    std::map<std::size_t, std::uint32_t> copy_of_fan;  // fan root → vertex id
    copy_of_fan[root(0)] = v;
    for (std::size_t i = 0; i < faces.size(); ++i) {
      auto [it, inserted] = copy_of_fan.emplace(root(i), 0);
      if (inserted) {
        it->second = static_cast<std::uint32_t>(mesh.positions.size());
        mesh.positions.push_back(mesh.positions[v]);
        if (mesh.has_colors()) mesh.colors.push_back(mesh.colors[v]);
        if (mesh.has_quality()) mesh.quality.push_back(mesh.quality[v]);
      }
      for (auto& corner : mesh.triangles[faces[i]])
        if (corner == v) corner = it->second;
    }
  }
  return mesh.positions.size() - original;
}

double radius_about_origin(const IndexedMesh& mesh) {
  double r = 0.0;
  for (const auto& p : mesh.positions) r = std::max(r, p.norm());
  return r;
}

}  // namespace mvflow
