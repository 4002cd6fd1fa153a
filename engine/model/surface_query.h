#pragma once
// Ray and closest-point queries against a triangle surface, through Embree 3.
//
// One SurfaceQuery owns its Embree device and scene (no process-global state, so two engines
// can live in one process). Queries are const and may run concurrently from many threads;
// update_positions() (a BVH refit after the vertices moved) must never run at the same time
// as a query — Embree's rule that modifying, committing and tracing happen sequentially.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/model/mesh.h"

namespace mvflow {

//! Where a ray first meets the surface.
struct RayHit {
  double distance = 0.0;         //!< along the (unit) ray direction
  std::uint32_t face = 0;        //!< face id
  Eigen::Vector2d barycentric;   //!< (u, v) as Embree's: point = (1−u−v)·P0 + u·P1 + v·P2
};

//! The hit of the ray on triangle (a, b, c), which Embree \p found, recomputed in double
//! precision: its distance and barycentric coordinates (clamped into the triangle), the face
//! kept. Embree's float answer depends on its instruction-set path and on the CPU's reciprocal
//! approximation (which may differ between CPU makers), and the synthetic renders and the
//! held-out renders shade it; this one is the same bits on every CPU. The distance is clamped
//! into [t_near, t_far], the range searched. \p found itself when the ray is parallel to the
//! triangle in double (then the bits are Embree's again).
RayHit hit_in_double(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b, const Eigen::Vector3d& c, const RayHit& found, double t_near = 0.0,
                     double t_far = std::numeric_limits<double>::infinity());

//! The point of the surface nearest to a query point (exact, in double precision).
struct ClosestPoint {
  double distance = 0.0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  std::uint32_t face = 0;
};

//! Embree's device configuration for every SurfaceQuery: "max_isa=avx2", so that an AVX-512 machine
//! traces rays by Embree's AVX2 path, as an AVX2 machine does (its paths differ in their last
//! bits), or "max_isa=sse2" under MVFLOW_KERNEL=baseline; Embree's config files ignored (README
//! "Performance").
std::string embree_device_config();

class SurfaceQuery {
 public:
  //! Builds the BVH. \p positions #V, \p triangles #F (indices into positions).
  //! \throw InputError when the mesh is empty or has a non-finite coordinate (Embree would
  //! silently drop such triangles).
  SurfaceQuery(const std::vector<Eigen::Vector3d>& positions, const std::vector<std::array<std::uint32_t, 3>>& triangles);
  explicit SurfaceQuery(const IndexedMesh& mesh);
  //! The same with Embree's device configuration (rtcNewDevice's string) given instead of
  //! embree_device_config()'s, e.g. "" for the widest instruction set the CPU has.
  SurfaceQuery(const IndexedMesh& mesh, const std::string& device_config);
  explicit SurfaceQuery(const TriMesh& mesh);
  ~SurfaceQuery();
  SurfaceQuery(const SurfaceQuery&) = delete;
  SurfaceQuery& operator=(const SurfaceQuery&) = delete;

  //! Moves the vertices (same count, same triangles) and refits the BVH.
  void update_positions(const std::vector<Eigen::Vector3d>& positions);
  void update_positions(const TriMesh& mesh);

  //! True when the segment origin + t·direction, t in (t_near, t_far), hits the surface.
  //! \p direction need not be unit length; t is in its units.
  bool occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_near, double t_far) const;
  //! The first hit along the ray with unit-length \p direction, if any: the face Embree finds,
  //! its distance and barycentric coordinates from hit_in_double (the same bits on every CPU).
  std::optional<RayHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double t_near = 0.0,
                                  double t_far = std::numeric_limits<double>::infinity()) const;
  //! The nearest surface point to \p point (exact point–triangle distance in double).
  ClosestPoint closest_point(const Eigen::Vector3d& point) const;


 private:
  SurfaceQuery(const std::vector<Eigen::Vector3d>& positions, const std::vector<std::array<std::uint32_t, 3>>& triangles,
               const std::string& device_config);
  struct Embree;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  std::unique_ptr<Embree> embree_;
  void upload_positions();
};

//! The exact closest point to \p p on triangle (a, b, c) (Ericson, Real-Time Collision
//! Detection, §5.1.5).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

}  // namespace mvflow
