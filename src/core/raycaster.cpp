// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/raycaster.hpp"

#include <embree3/rtcore.h>

#include <stdexcept>
#include <string>

namespace graspfill {
namespace {

void ThrowOnEmbreeError(void* /*user*/, RTCError code, const char* message) {
  // Embree calls this from inside its API; throwing carries the error to the
  // caller of the failed rtc* call instead of continuing with a bad handle.
  throw std::runtime_error("embree error " + std::to_string(code) + ": " + (message ? message : ""));
}

}  // namespace

struct Raycaster::Impl {
  RTCDevice device{nullptr};
  RTCScene scene{nullptr};
  bool committed{false};
};

Raycaster::Raycaster() : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice("threads=1");
  if (!impl_->device) {
    throw std::runtime_error("embree: rtcNewDevice failed (error " +
                             std::to_string(rtcGetDeviceError(nullptr)) + ")");
  }
  rtcSetDeviceErrorFunction(impl_->device, ThrowOnEmbreeError, nullptr);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
}

Raycaster::~Raycaster() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

unsigned Raycaster::AddMesh(const TriangleMesh& mesh) {
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if ((t.array() < 0).any() || (t.array() >= num_vertices).any()) {
      throw std::invalid_argument("Raycaster::AddMesh: triangle index out of range");
    }
  }
  RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree reads vertex buffers with 16-byte loads: one float of padding.
  float* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), mesh.vertices.size() + 1));
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    v[3 * i + 0] = mesh.vertices[i].x();
    v[3 * i + 1] = mesh.vertices[i].y();
    v[3 * i + 2] = mesh.vertices[i].z();
  }
  v[3 * mesh.vertices.size() + 0] = v[3 * mesh.vertices.size() + 1] = v[3 * mesh.vertices.size() + 2] = 0.0f;
  unsigned* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) idx[3 * i + k] = static_cast<unsigned>(mesh.triangles[i][k]);
  }
  rtcCommitGeometry(geom);
  const unsigned id = rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  impl_->committed = false;
  return id;
}

void Raycaster::Commit() {
  rtcCommitScene(impl_->scene);
  impl_->committed = true;
}

void Raycaster::Clear() {
  rtcReleaseScene(impl_->scene);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  impl_->committed = false;
}

bool Raycaster::committed() const { return impl_->committed; }

RayHit Raycaster::Cast(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near,
                       float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = origin.x();
  rh.ray.org_y = origin.y();
  rh.ray.org_z = origin.z();
  rh.ray.dir_x = dir.x();
  rh.ray.dir_y = dir.y();
  rh.ray.dir_z = dir.z();
  rh.ray.tnear = t_near;
  rh.ray.tfar = t_far;
  rh.ray.time = 0.0f;
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  RayHit out;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    out.t = rh.ray.tfar;
    out.geom_id = rh.hit.geomID;
    out.normal = Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  }
  return out;
}

bool Raycaster::Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near,
                         float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = origin.x();
  ray.org_y = origin.y();
  ray.org_z = origin.z();
  ray.dir_x = dir.x();
  ray.dir_y = dir.y();
  ray.dir_z = dir.z();
  ray.tnear = t_near;
  ray.tfar = t_far;
  ray.time = 0.0f;
  ray.mask = ~0u;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

void Raycaster::Cast16(const Eigen::Vector3f& origin, const float (*dirs)[3], int count, float* t_out) const {
  alignas(64) RTCRayHit16 rh;
  alignas(64) int valid[16];
  for (int i = 0; i < 16; ++i) {
    valid[i] = i < count ? -1 : 0;
    rh.ray.org_x[i] = origin.x();
    rh.ray.org_y[i] = origin.y();
    rh.ray.org_z[i] = origin.z();
    rh.ray.dir_x[i] = i < count ? dirs[i][0] : 0.0f;
    rh.ray.dir_y[i] = i < count ? dirs[i][1] : 0.0f;
    rh.ray.dir_z[i] = i < count ? dirs[i][2] : 1.0f;
    rh.ray.tnear[i] = 0.0f;
    rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
    rh.ray.time[i] = 0.0f;
    rh.ray.mask[i] = ~0u;
    rh.ray.id[i] = static_cast<unsigned>(i);
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // Rays of one packet share an origin (a pixel tile): the coherent hint
  // lets Embree traverse them together, ~1.5x faster than the default.
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect16(valid, impl_->scene, &context, &rh);
  for (int i = 0; i < count; ++i) {
    t_out[i] =
        rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar[i] : std::numeric_limits<float>::infinity();
  }
}

}  // namespace graspfill
