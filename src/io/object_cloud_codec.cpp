// SPDX-License-Identifier: BSD-3-Clause
// object_cloud_t <-> ObjectCloud: the points packed (packed_points.hpp), the
// holes, the safe bound and the timings.
#include "graspfill/io/messages.hpp"

#include "wire.hpp"

#include "packed_points.hpp"

#include <graspfill/hole_t.hpp>
#include <graspfill/object_cloud_t.hpp>

#include <cstdint>

namespace graspfill::io {
using namespace wire;

namespace {

// `bytes` (> 0) hold nx ny nz bits (each > 0), rounded up to a byte:
// 8 (bytes - 1) < nx ny nz <= 8 bytes. The product of three int32 counts
// overflows int64 (found by fuzz_object_cloud), that of two does not: the
// third divides the bounds instead.
bool BitsFillTheBytes(int32_t nx, int32_t ny, int32_t nz, int32_t bytes) {
  const int64_t nx_ny = static_cast<int64_t>(nx) * ny;
  const int64_t most = 8 * static_cast<int64_t>(bytes);
  return nx_ny <= most / nz && nx_ny > (most - 8) / nz;
}

}  // namespace

std::vector<uint8_t> EncodeObjectCloud(const ObjectCloud& cloud) {
  PackedPoints packed;
  try {
    packed = PackPoints(cloud);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("EncodeObjectCloud: ") + e.what());
  }
  graspfill::object_cloud_t msg{};
  msg.utime = cloud.utime;
  msg.seq = cloud.seq;
  msg.frame_name = cloud.frame_name;
  PoseToWire(cloud.T_C_G, msg.position, msg.orientation);
  msg.num_points = static_cast<int32_t>(cloud.points_G.size());
  for (int k = 0; k < 3; ++k) msg.origin[k] = packed.origin[k];
  msg.step_m = packed.step_m;
  msg.has_normals = packed.has_normals ? 1 : 0;
  msg.num_packed_bytes = static_cast<int32_t>(packed.deflated.size());
  msg.packed_points = std::move(packed.deflated);
  const SafeBound& bound = cloud.safe_bound;
  if (!bound.empty() && static_cast<size_t>(bound.nx) * bound.ny * bound.nz > 8 * bound.bits.size()) {
    throw std::invalid_argument("EncodeObjectCloud: the safe bound's bits do not cover its grid");
  }
  for (int k = 0; k < 3; ++k) msg.bound_origin[k] = bound.origin_G[k];
  msg.bound_voxel_m = bound.voxel_m;
  msg.bound_nx = bound.nx;
  msg.bound_ny = bound.ny;
  msg.bound_nz = bound.nz;
  msg.bound_num_bytes = static_cast<int32_t>(bound.bits.size());
  msg.bound_bits.assign(bound.bits.begin(), bound.bits.end());
  msg.num_holes = static_cast<int32_t>(cloud.holes.size());
  msg.holes.resize(cloud.holes.size());
  for (size_t i = 0; i < cloud.holes.size(); ++i) {
    const HoleSummary& h = cloud.holes[i];
    graspfill::hole_t& m = msg.holes[i];
    m.kind = static_cast<int8_t>(h.kind);
    m.boundary_points = h.boundary_points;
    for (int k = 0; k < 3; ++k) {
      m.box_min[k] = h.box_min_G[k];
      m.box_max[k] = h.box_max_G[k];
    }
    m.points_added = h.points_added;
    m.unobserved = h.unobserved ? 1 : 0;
    m.confidence = h.confidence;
  }
  msg.num_timings = static_cast<int32_t>(cloud.timings.size());
  for (const StageTiming& t : cloud.timings) {
    msg.timing_names.push_back(t.stage);
    msg.timing_ms.push_back(t.ms);
  }
  msg.grasp_id = cloud.grasp_id;
  msg.is_final = cloud.is_final ? 1 : 0;
  return EncodeMessage(msg);
}

static bool DecodeObjectCloudImpl(const void* data, size_t size, ObjectCloud* out, std::string* error) {
  if (!CheckBuffer(data, size, out, "object_cloud_t", error)) return false;
  // Walk the whole message so that every count is known to fit before the
  // generated decoder resizes anything. Layout: object_cloud_t.lcm.
  {
    WireReader r(data, size);
    int32_t num_points, num_packed_bytes, num_holes, num_timings, bound_num_bytes;
    int8_t has_normals;
    constexpr size_t kHoleBytes = 1 + 4 + 3 * 4 + 3 * 4 + 4 + 1 + 4;
    bool ok = r.Hash(graspfill::object_cloud_t::getHash()) && r.Skip(16) && r.SkipString() && r.Skip(7 * 8) &&
              r.I32(&num_points) && r.Skip(4 * 8) && r.I8(&has_normals) &&  // origin, step_m
              r.Count(&num_packed_bytes, 1) && r.Skip(static_cast<size_t>(num_packed_bytes)) &&
              r.Count(&num_holes, kHoleBytes) && r.Skip(kHoleBytes * static_cast<size_t>(num_holes)) &&
              r.Skip(4 * 4 + 3 * 4) && r.Count(&bound_num_bytes, 1) &&  // the safe bound
              r.Skip(static_cast<size_t>(bound_num_bytes)) && r.Count(&num_timings, 4 + 1 + 8);
    for (int32_t i = 0; ok && i < num_timings; ++i) ok = r.SkipString();
    ok = ok && r.Skip(8 * static_cast<size_t>(num_timings)) && r.Skip(8 + 1) &&  // grasp_id, is_final
         r.remaining() == 0;
    if (!ok) {
      SetError(error, "object_cloud_t: malformed message");
      return false;
    }
    if (num_points < 0 || (has_normals != 0 && has_normals != 1)) {
      SetError(error, "object_cloud_t: num_points " + std::to_string(num_points) + ", has_normals " +
                          std::to_string(static_cast<int>(has_normals)));
      return false;
    }
  }
  thread_local graspfill::object_cloud_t msg{};
  // As for gripper_state_t: empty arrays are not resized by lcm-gen.
  msg.packed_points.clear();
  msg.bound_bits.clear();
  msg.timing_ms.clear();
  if (!DecodeMessage(data, size, &msg, error)) return false;

  Eigen::Isometry3d T_C_G;
  if (!PoseFromWire("object_cloud_t", msg.position, msg.orientation, &T_C_G, error)) {
    return false;
  }
  // Into scratch first: `out` is left as it was on a failure.
  thread_local ObjectCloud points;
  std::string why;
  if (!UnpackPoints(msg.origin, msg.step_m, msg.has_normals != 0, static_cast<size_t>(msg.num_points),
                    msg.packed_points.data(), msg.packed_points.size(), &points, &why)) {
    SetError(error, "object_cloud_t: " + why);
    return false;
  }
  if (msg.bound_num_bytes > 0) {
    if (msg.bound_nx <= 0 || msg.bound_ny <= 0 || msg.bound_nz <= 0 || !(msg.bound_voxel_m > 0.0f) ||
        !std::isfinite(msg.bound_voxel_m) || !std::isfinite(msg.bound_origin[0]) ||
        !std::isfinite(msg.bound_origin[1]) || !std::isfinite(msg.bound_origin[2]) ||
        !BitsFillTheBytes(msg.bound_nx, msg.bound_ny, msg.bound_nz, msg.bound_num_bytes)) {
      SetError(error, "object_cloud_t: inconsistent safe bound (" + std::to_string(msg.bound_nx) + " x " +
                          std::to_string(msg.bound_ny) + " x " + std::to_string(msg.bound_nz) + " voxels, " +
                          std::to_string(msg.bound_num_bytes) + " bytes)");
      return false;
    }
  }
  for (const graspfill::hole_t& h : msg.holes) {
    if (h.kind != graspfill::hole_t::CLAW && h.kind != graspfill::hole_t::MISSING_SURFACE) {
      SetError(error, "object_cloud_t: unknown hole kind " + std::to_string(static_cast<int>(h.kind)));
      return false;
    }
    if ((h.unobserved != 0 && h.unobserved != 1) || !(h.confidence >= 0.0f && h.confidence <= 1.0f)) {
      SetError(error, "object_cloud_t: a hole's unobserved must be 0 or 1 and its confidence in 0..1 (got " +
                          std::to_string(static_cast<int>(h.unobserved)) + ", " +
                          std::to_string(h.confidence) + ")");
      return false;
    }
  }

  out->utime = msg.utime;
  out->seq = msg.seq;
  out->frame_name = msg.frame_name;
  out->T_C_G = T_C_G;
  out->points_G.swap(points.points_G);
  out->normals_G.swap(points.normals_G);
  out->provenance.swap(points.provenance);
  out->confidence.swap(points.confidence);
  SafeBound& bound = out->safe_bound;
  bound = SafeBound{};
  if (msg.bound_num_bytes > 0) {
    bound.origin_G = Eigen::Vector3f(msg.bound_origin[0], msg.bound_origin[1], msg.bound_origin[2]);
    bound.voxel_m = msg.bound_voxel_m;
    bound.nx = msg.bound_nx;
    bound.ny = msg.bound_ny;
    bound.nz = msg.bound_nz;
    bound.bits.assign(msg.bound_bits.begin(), msg.bound_bits.end());
  }
  out->holes.resize(msg.holes.size());
  for (size_t i = 0; i < msg.holes.size(); ++i) {
    const graspfill::hole_t& m = msg.holes[i];
    HoleSummary& h = out->holes[i];
    h.kind = static_cast<HoleKind>(m.kind);
    h.boundary_points = m.boundary_points;
    h.box_min_G = Eigen::Vector3f(m.box_min[0], m.box_min[1], m.box_min[2]);
    h.box_max_G = Eigen::Vector3f(m.box_max[0], m.box_max[1], m.box_max[2]);
    h.points_added = m.points_added;
    h.unobserved = m.unobserved != 0;
    h.confidence = m.confidence;
  }
  out->timings.resize(msg.timing_names.size());
  for (size_t i = 0; i < msg.timing_names.size(); ++i) {
    out->timings[i].stage = msg.timing_names[i];
    out->timings[i].ms = msg.timing_ms[i];
  }
  out->grasp_id = msg.grasp_id;
  out->is_final = msg.is_final != 0;
  return true;
}

bool DecodeObjectCloud(const void* data, size_t size, ObjectCloud* out, std::string* error,
                       MessageError* reason) {
  return WithReason(reason, [&] { return DecodeObjectCloudImpl(data, size, out, error); });
}

}  // namespace graspfill::io
