#pragma once
// Internal to the stage layers (flow, topology, hull): the one-ring sums that the normal,
// curvature, smoothing and remeshing stages share. In the model because every stage layer uses it;
// not part of the public interface; header-only so the hot loops inline.

#include <algorithm>
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "engine/model/error.h"
#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow::detail {

//! A face counts as degenerate when |(P2−P1)×(P3−P1)| ≤ this ratio · (longest edge)²: the sine
//! of its largest angle is below ~1e−12, so its normal and cotangents are rounding noise. The
//! threshold is relative so that it means the same in every world unit.
inline constexpr double degenerate_face_ratio = 1e-12;

inline Eigen::Vector3d point(const TriMesh& mesh, TriMesh::VertexHandle v) {
  return to_eigen(mesh.point(v));
}

//! True when the triangle (p, q, r) with cross product \p cross = (q−p)×(r−p) is degenerate
//! (also when anything is NaN or infinite: the comparison is false then).
inline bool is_degenerate(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r,
                          const Eigen::Vector3d& cross) {
  const double longest2 = std::max({(q - p).squaredNorm(), (r - p).squaredNorm(), (r - q).squaredNorm()});
  return !(cross.norm() > degenerate_face_ratio * longest2);
}

//! cot of the angle at \p r in the triangle (p, q, r).
inline double cot_at(const Eigen::Vector3d& r, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d a = p - r, b = q - r;
  return a.dot(b) / a.cross(b).norm();
}

//! P's share of triangle (p, q, r) in the mixed Voronoi area (Meyer, Desbrun, Schröder, Barr,
//! "Discrete differential-geometry operators for triangulated 2-manifolds", 2003, fig. 4): the
//! Voronoi region inside a non-obtuse triangle, else half or a quarter of the triangle.
inline double mixed_area_part(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r,
                              double area) {
  if ((q - p).dot(r - p) < 0) return area / 2;  // obtuse at P
  if ((p - q).dot(r - q) < 0 || (p - r).dot(q - r) < 0) return area / 4;
  return ((r - p).squaredNorm() * cot_at(q, p, r) + (q - p).squaredNorm() * cot_at(r, p, q)) / 8;
}

//! The cotangent-weighted one ring of a vertex P with neighbours Q_j (thesis 3.6).
struct CotangentRing {
  Eigen::Vector3d weighted_difference = Eigen::Vector3d::Zero();  //!< Σ_j c_j (Q_j − P)
  Eigen::Vector3d uniform_difference = Eigen::Vector3d::Zero();   //!< Σ_j (Q_j − P)
  double weight_sum = 0.0;                                        //!< Σ_j c_j
  double double_area_sum = 0.0;  //!< Σ over faces around P of |(P2−P1)×(P3−P1)| (twice the area)
  double mixed_area = 0.0;       //!< Meyer et al.'s mixed Voronoi area of P (see mixed_area_part)
  int neighbours = 0;            //!< m, the number of Q_j
  bool degenerate = false;       //!< some face around P is degenerate: sums are meaningless
  bool boundary = false;         //!< P is on a boundary (an edge with one face)
};

//! Sums the cotangent one ring of \p v, c_j = cot α_j + cot β_j with α_j, β_j the angles
//! opposite the edge (P, Q_j). Visits the outgoing halfedges in OpenMesh's fixed order, so the
//! result never depends on which block asks. No allocation.
inline CotangentRing cotangent_ring(const TriMesh& mesh, TriMesh::VertexHandle v) {
  CotangentRing ring;
  const Eigen::Vector3d p = point(mesh, v);
  for (auto it = mesh.cvoh_iter(v); it.is_valid(); ++it) {
    const TriMesh::HalfedgeHandle h = *it;
    const Eigen::Vector3d q = point(mesh, mesh.to_vertex_handle(h));
    double c = 0.0;
    if (mesh.face_handle(h).is_valid()) {
      // Face (P, Q, R): every face around P is visited exactly once this way.
      const Eigen::Vector3d r = point(mesh, mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
      const Eigen::Vector3d cross = (q - p).cross(r - p);
      if (is_degenerate(p, q, r, cross)) ring.degenerate = true;
      ring.double_area_sum += cross.norm();
      ring.mixed_area += mixed_area_part(p, q, r, 0.5 * cross.norm());
      c += cot_at(r, p, q);
    } else {
      ring.boundary = true;
    }
    const TriMesh::HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
    if (mesh.face_handle(o).is_valid()) {
      // Face (Q, P, S) on the other side of the edge; its degeneracy is caught when it is
      // visited as the face of the outgoing halfedge P→S.
      const Eigen::Vector3d s = point(mesh, mesh.to_vertex_handle(mesh.next_halfedge_handle(o)));
      c += cot_at(s, p, q);
    } else {
      ring.boundary = true;
    }
    ring.weighted_difference += c * (q - p);
    ring.uniform_difference += q - p;
    ring.weight_sum += c;
    ++ring.neighbours;
  }
  return ring;
}

//! Checks that \p vertices lies inside [0, \p n_vertices).
inline void check_range(IndexRange vertices, std::size_t n_vertices, const char* stage) {
  MVFLOW_CHECK(vertices.begin <= vertices.end && vertices.end <= n_vertices,
               std::string(stage) + ": vertex range [" + std::to_string(vertices.begin) + ", " +
                   std::to_string(vertices.end) + ") outside the mesh's " + std::to_string(n_vertices) +
                   " vertices");
}

inline TriMesh::VertexHandle handle(std::uint32_t id) {
  return TriMesh::VertexHandle(static_cast<int>(id));
}

}  // namespace mvflow::detail
