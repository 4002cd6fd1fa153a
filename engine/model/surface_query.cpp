#include "engine/model/surface_query.h"

#include <embree3/rtcore.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <string>

#include "engine/model/error.h"

namespace mvflow {

namespace {

// Embree reports errors through a callback; we keep the last message and throw from the caller.
struct DeviceErrors {
  std::mutex mutex;
  std::string message;
};

void on_embree_error(void* user, RTCError code, const char* text) {
  auto* errors = static_cast<DeviceErrors*>(user);
  std::lock_guard lock(errors->mutex);
  errors->message = "Embree error " + std::to_string(static_cast<int>(code)) + ": " + (text ? text : "");
}

struct PointQueryState {
  const std::vector<Eigen::Vector3d>* positions;
  const std::vector<std::array<std::uint32_t, 3>>* triangles;
  Eigen::Vector3d query;
  ClosestPoint best;
};

bool point_query_callback(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<PointQueryState*>(args->userPtr);
  const auto& t = (*state->triangles)[args->primID];
  const auto& P = *state->positions;
  const Eigen::Vector3d nearest = closest_point_on_triangle(state->query, P[t[0]], P[t[1]], P[t[2]]);
  const double distance = (nearest - state->query).norm();
  if (distance >= state->best.distance) return false;
  state->best = {distance, nearest, args->primID};
  // Embree culls with float bounds: keep the radius a hair above the exact double distance so a
  // node holding an equally near triangle is never culled by rounding.
  args->query->radius = static_cast<float>(distance) * (1.0f + 1e-6f) + 1e-30f;
  return true;
}

}  // namespace

struct SurfaceQuery::Embree {
  DeviceErrors errors;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  RTCGeometry geometry = nullptr;
  bool attached = false;      // the scene holds the geometry's reference (set once released to it)
  float* vertices = nullptr;  // Embree-owned buffer, 3 floats per vertex (+ padding)

  void check(const char* what) {
    std::lock_guard lock(errors.mutex);
    if (!errors.message.empty()) throw Error(std::string(what) + ": " + errors.message);
  }
  ~Embree() {
    // A constructor that threw (a non-finite vertex, an Embree error) before handing the geometry
    // to the scene still holds it, and through it the device.
    if (geometry && !attached) rtcReleaseGeometry(geometry);
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

SurfaceQuery::SurfaceQuery(const TriMesh& mesh) : SurfaceQuery(positions_of(mesh), triangles_of(mesh)) {}

std::string embree_device_config() {
  // AVX2: what most machines have, about 1 % of a run against AVX-512 (SSE2 for all: 2–7 %).
  // Embree's config files (.embree3 beside the program or in the home folder) are ignored, so that
  // none can set an instruction set (`isa=`) past the cap. (Debian's Embree 3.13.5 read neither in
  // a check with `isa=sse2` in both places; other builds may.)
  const char* forced = std::getenv("MVFLOW_KERNEL");
  const bool baseline = forced != nullptr && std::string(forced) == "baseline";
  return std::string(baseline ? "max_isa=sse2" : "max_isa=avx2") + ",ignore_config_files=1";
}

SurfaceQuery::SurfaceQuery(const IndexedMesh& mesh) : SurfaceQuery(mesh.positions, mesh.triangles) {}

SurfaceQuery::SurfaceQuery(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<std::array<std::uint32_t, 3>>& triangles)
    : SurfaceQuery(positions, triangles, embree_device_config()) {}

SurfaceQuery::SurfaceQuery(const IndexedMesh& mesh, const std::string& device_config)
    : SurfaceQuery(mesh.positions, mesh.triangles, device_config) {}

SurfaceQuery::SurfaceQuery(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::string& device_config)
    : positions_(positions), triangles_(triangles), embree_(std::make_unique<Embree>()) {
  if (triangles_.empty()) throw InputError("surface query: the mesh has no triangles");
  for (const auto& t : triangles_)
    for (auto v : t) MVFLOW_CHECK(v < positions_.size(), "triangle index out of range");
  Embree& e = *embree_;
  e.device = rtcNewDevice(device_config.c_str());
  if (!e.device) throw Error("Embree: cannot create a device (unsupported CPU?)");
  rtcSetDeviceErrorFunction(e.device, on_embree_error, &e.errors);
  e.scene = rtcNewScene(e.device);
  // Refit-friendly: vertices move every iteration while the triangles stay.
  rtcSetSceneFlags(e.scene, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(e.scene, RTC_BUILD_QUALITY_LOW);
  e.geometry = rtcNewGeometry(e.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(e.geometry, RTC_BUILD_QUALITY_REFIT);
  e.vertices = static_cast<float*>(rtcSetNewGeometryBuffer(e.geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), positions_.size()));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(e.geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                                 RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                                 triangles_.size()));
  e.check("creating the Embree geometry");
  for (std::size_t f = 0; f < triangles_.size(); ++f)
    for (int c = 0; c < 3; ++c) indices[3 * f + c] = triangles_[f][c];
  upload_positions();
  rtcAttachGeometry(e.scene, e.geometry);
  rtcReleaseGeometry(e.geometry);  // the scene holds the reference now
  e.attached = true;
  rtcCommitScene(e.scene);
  e.check("building the Embree scene");
}

SurfaceQuery::~SurfaceQuery() = default;

void SurfaceQuery::upload_positions() {
  for (std::size_t v = 0; v < positions_.size(); ++v) {
    if (!positions_[v].allFinite())
      throw InputError("surface query: vertex " + std::to_string(v) + " has a non-finite coordinate");
    for (int c = 0; c < 3; ++c) embree_->vertices[3 * v + c] = static_cast<float>(positions_[v][c]);
  }
  rtcUpdateGeometryBuffer(embree_->geometry, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(embree_->geometry);
}

void SurfaceQuery::update_positions(const std::vector<Eigen::Vector3d>& positions) {
  MVFLOW_CHECK(positions.size() == positions_.size(), "update_positions: vertex count changed");
  positions_ = positions;
  upload_positions();
  rtcCommitScene(embree_->scene);
  embree_->check("refitting the Embree scene");
}

void SurfaceQuery::update_positions(const TriMesh& mesh) { update_positions(positions_of(mesh)); }

bool SurfaceQuery::occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_near,
                            double t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = static_cast<float>(origin.x());
  ray.org_y = static_cast<float>(origin.y());
  ray.org_z = static_cast<float>(origin.z());
  ray.dir_x = static_cast<float>(direction.x());
  ray.dir_y = static_cast<float>(direction.y());
  ray.dir_z = static_cast<float>(direction.z());
  ray.tnear = static_cast<float>(t_near);
  ray.tfar = static_cast<float>(std::min(t_far, static_cast<double>(std::numeric_limits<float>::max())));
  ray.mask = 0xFFFFFFFFu;
  rtcOccluded1(embree_->scene, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to −inf on a hit
}

std::optional<RayHit> SurfaceQuery::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                              double t_near, double t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit query{};
  query.ray.org_x = static_cast<float>(origin.x());
  query.ray.org_y = static_cast<float>(origin.y());
  query.ray.org_z = static_cast<float>(origin.z());
  query.ray.dir_x = static_cast<float>(direction.x());
  query.ray.dir_y = static_cast<float>(direction.y());
  query.ray.dir_z = static_cast<float>(direction.z());
  query.ray.tnear = static_cast<float>(t_near);
  query.ray.tfar = static_cast<float>(std::min(t_far, static_cast<double>(std::numeric_limits<float>::max())));
  query.ray.mask = 0xFFFFFFFFu;
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree_->scene, &context, &query);
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  const RayHit found{query.ray.tfar, query.hit.primID, Eigen::Vector2d(query.hit.u, query.hit.v)};
  const auto& triangle = triangles_[found.face];
  return hit_in_double(origin, direction, positions_[triangle[0]], positions_[triangle[1]], positions_[triangle[2]],
                       found, t_near, t_far);
}

RayHit hit_in_double(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b, const Eigen::Vector3d& c, const RayHit& found, double t_near,
                     double t_far) {
  // Möller–Trumbore on the double positions: only IEEE operations in one fixed order (no
  // reciprocal approximation, and no fused multiply-add: the build sets -ffp-contract=off), so
  // the same bits on every CPU.
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = direction.cross(e2);
  const double det = e1.dot(p);
  if (!(std::abs(det) > 0.0)) return found;  // parallel in double: Embree's float answer stands
  const Eigen::Vector3d s = origin - a;
  const Eigen::Vector3d q = s.cross(e1);
  double u = s.dot(p) / det, v = direction.dot(q) / det;
  const double t = e2.dot(q) / det;
  if (!std::isfinite(u) || !std::isfinite(v) || !std::isfinite(t)) return found;
  // Embree's float test accepted the face; a hit on its edge may land a rounding outside in double.
  u = std::clamp(u, 0.0, 1.0);
  v = std::clamp(v, 0.0, 1.0);
  if (u + v > 1.0) {
    const double sum = u + v;
    u /= sum;
    v /= sum;
  }
  // ... and its distance a rounding outside the range Embree searched.
  return RayHit{std::clamp(t, t_near, t_far), found.face, Eigen::Vector2d(u, v)};
}

ClosestPoint SurfaceQuery::closest_point(const Eigen::Vector3d& point) const {
  PointQueryState state{&positions_, &triangles_, point, {std::numeric_limits<double>::infinity(), {}, 0}};
  RTCPointQuery query{};
  query.x = static_cast<float>(point.x());
  query.y = static_cast<float>(point.y());
  query.z = static_cast<float>(point.z());
  query.radius = std::numeric_limits<float>::infinity();
  query.time = 0.0f;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(embree_->scene, &query, &context, point_query_callback, &state);
  return state.best;
}

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

}  // namespace mvflow
