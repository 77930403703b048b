// SPDX-License-Identifier: BSD-3-Clause
// Conversion between graspfill's value types and its LCM messages
// (lcmtypes/*.lcm, package graspfill). Pure functions over bytes: nothing
// here opens a socket or a file, so the same code serves the live bus, log
// replay and tests.
//
// Frames: C camera (optical), G gripper, B robot base (see types.hpp).
// Units: meters, microseconds (`utime`), milliseconds for timings.
//
// Error policy: Decode* are on the per-frame path, so they never throw on bad
// input; they return false and say why in *error. Encode* throw
// std::invalid_argument only on caller misuse (inconsistent sizes).
//
// Thread safety: every function may be called concurrently from any thread.
// Encoders and decoders keep per-thread scratch (thread_local zlib streams,
// intermediate messages) that grows to the largest message seen on that
// thread and is then reused, so steady-state decoding does not allocate
// beyond growing the caller's output buffers.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/core/frame_skip.hpp"
#include "graspfill/io/session_limits.hpp"
#include "graspfill/types.hpp"

namespace graspfill::io {

/// LCM channel names used by graspfill. Defaults are the documented ones; a
/// deployment may rename any of them (e.g. to run two modules on one bus).
struct ChannelNames {
  /// depth_image_t from the camera (or a recorded log).
  std::string depth{"GRASPFILL_DEPTH"};
  /// gripper_state_t from the robot.
  std::string gripper_state{"GRASPFILL_GRIPPER_STATE"};
  /// object_cloud_t to the motion planner.
  std::string object_cloud{"GRASPFILL_OBJECT_CLOUD"};
  /// module_status_t, the module's health.
  std::string status{"GRASPFILL_STATUS"};
  /// session_description_t: what the session was set up with (published
  /// when a session starts, written at the head of every recording).
  std::string session{"GRASPFILL_SESSION"};
  /// collision_mesh_t to the motion planner (the model's collision mesh,
  /// when one is made: io/collision_mesh_message.hpp).
  std::string collision_mesh{"GRASPFILL_COLLISION_MESH"};
};

/// Why a message was rejected: decoders report one (optional last
/// argument) so that a bus subscriber can count bad messages per reason.
enum class MessageError : int {
  kNone = 0,
  kMalformed,           ///< wrong type hash, truncated, trailing bytes, bad counts
  kBadSize,             ///< image width/height <= 0 or over the pixel limit (max_depth_pixels)
  kBadIntrinsics,       ///< focal length or principal point out of range
  kBadDepthScale,       ///< depth scale out of range
  kBadEncoding,         ///< unknown encoding, corrupt zlib, data size mismatch
  kBadPose,             ///< pose not finite, quaternion not unit
  kBadValue,            ///< any other field out of range (opening, joints, kinds, frames)
  kBadTimestamp,        ///< utime outside [0, kMaxUtime]
  kIntrinsicsMismatch,  ///< image size differs from the session's intrinsics override
  kNonMonotonicTime,    ///< utime older than the previous one on its channel (subscriber)
  kBadClawName,         ///< a session's claw_name is not a plain name (a path, "..")
  kOutOfLimits,         ///< a session asks for values beyond session_limits.hpp's
  kClawUnloadable,      ///< a session's claw cannot be built (receiver)
  kCount                ///< number of reasons (array size)
};
/// A short stable name ("malformed", "bad_intrinsics", ...), for status and logs.
const char* MessageErrorName(MessageError reason);
/// The reason of a name MessageErrorName gives; kNone for any other text.
MessageError MessageErrorFromName(const std::string& name);

/// Bad messages received on our channels, per reason, cumulative: for the
/// module's status (a bad message is counted and dropped, never fatal).
struct BadMessageCounts {
  static constexpr size_t kNumReasons = static_cast<size_t>(MessageError::kCount);
  /// Indexed by MessageError (kNone stays 0).
  std::array<int64_t, kNumReasons> by_reason{};
  int64_t operator[](MessageError reason) const { return by_reason[static_cast<size_t>(reason)]; }
  int64_t total() const {
    int64_t sum = 0;
    for (int64_t n : by_reason) sum += n;
    return sum;
  }
};

/// Input limits checked by the decoders (docs/input-limits-and-fuzzing.md).
/// Largest depth image anything accepts: 4096 x 4096 pixels (the encoder's
/// limit, and the most a config's max_depth_pixels may be).
constexpr int64_t kMaxDepthPixels = int64_t{1} << 24;
/// Largest depth image the decoder accepts by default (max_depth_pixels):
/// 2^23 = 8,388,608 pixels (4096 x 2048, or 3840 x 2160). The largest
/// common depth sensors are ~5 MP (structured-light cameras such as Zivid 2+
/// at 2448 x 2048); RealSense D4xx (1280 x 720) and Azure Kinect (1024 x
/// 1024) are ~1 MP. A frame at the limit is 32 MiB decoded (4 bytes a
/// pixel), 16 MiB raw: what one bus message can make the module hold.
constexpr int64_t kDefaultMaxDepthPixels = int64_t{1} << 23;
/// Deflate's largest possible expansion (zlib's documented 1032:1): a
/// ZLIB16 payload of N bytes cannot inflate to more than this times N, so
/// a payload too short for its declared image is refused before anything
/// is allocated for it.
constexpr int64_t kMaxDeflateRatio = 1032;
/// Focal lengths fx, fy accepted [pixels].
constexpr double kMinFocalPx = 1.0;
constexpr double kMaxFocalPx = 1e5;
/// The principal point may lie up to one image size outside the image:
/// cx in [-width, 2 width], cy in [-height, 2 height].
/// Depth scale accepted [m per unit]: 1 um .. 1 m.
constexpr double kMinDepthScaleM = 1e-6;
constexpr double kMaxDepthScaleM = 1.0;
/// Latest utime accepted (2^53 us, year ~2255): differences of two valid
/// utimes never overflow, and they are exact in a double.
constexpr int64_t kMaxUtime = int64_t{1} << 53;

/// Checks intrinsics against the limits above; false + *why (one line) if not.
bool IntrinsicsInRange(const CameraIntrinsics& K, std::string* why);

/// How depth_image_t carries its pixels.
enum class DepthEncoding {
  /// width*height little-endian uint16, uncompressed (2 bytes/pixel).
  kRaw16,
  /// The uint16 image after a per-row horizontal delta (each sample minus
  /// its left neighbour, mod 2^16), little-endian, zlib-compressed at
  /// Z_BEST_SPEED. Lossless on the quantized depth; about 0.3 of kRaw16 on
  /// a noisy 640x480 plane and far less on masked frames.
  kZlib16,
};

/// Encodes a depth frame as depth_image_t.
///
/// Depth is quantized to round(depth_m / depth_scale_m); pixels that are
/// non-finite, <= 0, or beyond 65535 units become 0 (invalid). Decoding
/// gives back exactly float(units * depth_scale_m) (the product rounded
/// once to float).
/// @param frame  depth in meters, frame.depth_m.size() must be width*height.
/// @param encoding  pixel encoding (kZlib16 for the bus, kRaw16 when CPU
///   matters more than bandwidth).
/// @param depth_scale_m  meters per depth unit, finite and > 0 (0.001 = mm:
///   range up to 65.5 m; 0.0001 = 100 um: range up to 6.5 m).
/// @throws std::invalid_argument on a size mismatch or a bad depth scale.
std::vector<uint8_t> EncodeDepthImage(const DepthFrame& frame,
                                      DepthEncoding encoding = DepthEncoding::kZlib16,
                                      double depth_scale_m = 0.001);

/// Decodes a depth_image_t into *out, reusing out->depth_m's capacity.
///
/// Rejects malformed bytes (wrong type hash, truncated, trailing bytes),
/// bad sizes (width/height <= 0, more than `max_depth_pixels` pixels, data
/// size not matching the encoding), unknown encodings, corrupt zlib
/// streams, intrinsics outside the limits above (IntrinsicsInRange), a depth
/// scale outside [kMinDepthScaleM, kMaxDepthScaleM] and a utime outside
/// [0, kMaxUtime]. `reason`, if not null, gets why (kNone on success).
///
/// Memory: the size is checked before anything of the decoded size is
/// allocated; a ZLIB16 payload inflates into the declared size only (never
/// more: a zlib bomb ends there, kBadEncoding), and one shorter than the
/// declared size / kMaxDeflateRatio is refused before any allocation. At
/// most 6 bytes a pixel of the limit are held: out->depth_m (4) and this
/// thread's inflate scratch (2, ZLIB16 only), both reused.
/// @param data, size  one encoded message (LCM payload).
/// @param out  receives the frame (depth in meters, 0 = invalid); on failure
///   its contents are unspecified.
/// @param error  if not null, set to a one-line reason on failure.
/// @param max_depth_pixels  largest width x height accepted, 1..kMaxDepthPixels
///   (larger values count as kMaxDepthPixels): kBadSize beyond it.
/// @return true on success.
bool DecodeDepthImage(const void* data, size_t size, DepthFrame* out, std::string* error,
                      MessageError* reason = nullptr, int64_t max_depth_pixels = kDefaultMaxDepthPixels);

/// Encodes a gripper state as gripper_state_t with frame = FRAME_CAMERA
/// (the pose written is state.T_C_G; the quaternion is normalized).
std::vector<uint8_t> EncodeGripperState(const GripperState& state);

/// Decodes a gripper_state_t into *out (reusing out->joint_values).
///
/// Camera-frame messages give T_C_G directly; base-frame messages carry
/// T_B_G and are converted as T_C_G = T_C_B * T_B_G.
/// Rejects malformed bytes, unknown frames, NaN/inf anywhere (pose,
/// opening, joints), quaternions whose norm is off 1 by more than 1e-3
/// (the accepted ones are renormalized) and a utime outside [0, kMaxUtime].
/// @param T_C_B  hand-eye calibration: maps points from B to C.
/// @param error  if not null, set to a one-line reason on failure.
bool DecodeGripperState(const void* data, size_t size, const Eigen::Isometry3d& T_C_B, GripperState* out,
                        std::string* error, MessageError* reason = nullptr);

/// Encodes an object cloud as object_cloud_t.
///
/// Normals are sent when cloud.normals_G has one per point, none when it is
/// empty; provenance defaults to kObserved when cloud.provenance is empty.
/// @throws std::invalid_argument if normals or provenance are non-empty and
///   not one per point.
std::vector<uint8_t> EncodeObjectCloud(const ObjectCloud& cloud);

/// Decodes an object_cloud_t into *out (reusing its vectors).
///
/// Rejects malformed bytes, inconsistent counts (n3 != 3*num_points,
/// num_normals3 not 0 or n3), unknown provenance or hole kinds, non-finite
/// points or pose, and non-unit quaternions (as DecodeGripperState).
/// @param error  if not null, set to a one-line reason on failure.
bool DecodeObjectCloud(const void* data, size_t size, ObjectCloud* out, std::string* error,
                       MessageError* reason = nullptr);

/// What the module is doing (module_status_t.state_code).
enum class ModuleState : int8_t {
  kWaiting = 0,    ///< no depth frame yet, or the claw is empty
  kFusing = 1,     ///< frames are being fused
  kRepairing = 2,  ///< a grasp ended; its final model is being repaired
  kStalled = 3,    ///< frames come but none was fused for a while
  kError = 4,      ///< cannot go on (state_detail says why)
};

/// The module's health, as carried by module_status_t. Counters are
/// cumulative since the module started.
struct ModuleStatus {
  int64_t utime{0};           ///< bus time: the newest depth frame's utime [us]
  int64_t frames_in{0};       ///< depth frames received
  int64_t frames_used{0};     ///< depth frames fused into the TSDF
  int64_t frames_skipped{0};  ///< frames deliberately not fused
  int64_t frames_dropped{0};  ///< frames lost to a full queue
  double last_frame_ms{0.0};  ///< receive-to-fused time of the last frame
  std::string state;          ///< state_code as text, with the detail
  ModuleState state_code{ModuleState::kWaiting};
  std::string state_detail;  ///< why, for kStalled and kError
  int64_t frames_skipped_no_pose{0};
  int64_t frames_skipped_clock_jump{0};
  int64_t frames_bad{0};
  int64_t frames_skipped_refine{0};  ///< pose refinement or object tracking
  /// Every frame not fused, by reason (kPendingFull also in frames_dropped).
  FrameSkipCounts frames_skipped_by_reason;
  int64_t decode_errors{0};       ///< messages on our channels that did not decode
  BadMessageCounts bad_messages;  ///< decode_errors per reason
  int64_t clock_jumps{0};         ///< backwards jumps the module started over at
  int64_t repairs_done{0};
  int64_t repairs_superseded{0};
  int64_t repairs_failed{0};
  int64_t grasp_id{0};  ///< the grasp being modelled (0: none / not numbered)
  int64_t grasps_completed{0};
  /// Arrival of a cloud's newest depth frame -> its publication [ms], over
  /// the last clouds; clouds published.
  double latency_ms_p50{0.0}, latency_ms_p95{0.0}, latency_ms_p99{0.0}, latency_ms_max{0.0};
  int64_t clouds_published{0};
  /// Incremental updates and full repairs run, and their times [ms].
  int64_t repair_updates{0};
  int64_t repairs_full{0};
  double update_ms_p50{0.0}, update_ms_p99{0.0};
  double full_repair_ms_p50{0.0}, full_repair_ms_p99{0.0};
  double rss_mb{0.0};  ///< resident memory of the module's process
};

/// Encodes a status as module_status_t.
std::vector<uint8_t> EncodeModuleStatus(const ModuleStatus& status);

/// Decodes a module_status_t; false + *error on malformed bytes.
bool DecodeModuleStatus(const void* data, size_t size, ModuleStatus* out, std::string* error,
                        MessageError* reason = nullptr);

/// How a session description gives its claw (session_description_t's
/// claw_kind).
enum class SessionClawKind {
  /// A procedural claw of graspfill's ("three-finger", "parallel"); the text
  /// is a JSON object of its dimensions (claw::ProceduralClawConfig's
  /// fields, meters).
  kBuiltin,
  /// A claw description file's text (config/claws/README.md).
  kDescription,
  /// A URDF's text (not read by graspfill yet).
  kUrdf,
};

/// What a session was set up with, as carried by session_description_t:
/// the claw, the hand-eye calibration, an intrinsics override, the
/// workspace box and the voxel size. Receivers use it by default; their own
/// flags override it.
struct SessionDescription {
  int64_t utime{0};              ///< when the session started [us]
  std::string software_version;  ///< e.g. "graspfill 0.1.0"
  SessionClawKind claw_kind{SessionClawKind::kBuiltin};
  std::string claw_name;       ///< the built-in's or the description's name
  std::string claw_text;       ///< see SessionClawKind
  std::string claw_source;     ///< path it was read from, "" if none
  std::string claw_mesh_root;  ///< folder of its meshes, "" if none
  /// Hand-eye calibration: maps points from the robot base B to the camera
  /// C (identity when unknown).
  Eigen::Isometry3d T_C_B{Eigen::Isometry3d::Identity()};
  /// Used instead of the depth images' own intrinsics for images of this
  /// width x height; none = the images' own.
  std::optional<CameraIntrinsics> intrinsics;
  /// The workspace box in G [m]; none = the receiver's default.
  std::optional<Eigen::AlignedBox3d> workspace_G;
  /// TSDF voxel edge [m]; 0 = the receiver's default.
  double voxel_m{0.0};
};

/// "graspfill <version>", the software_version graspfill writes.
std::string SoftwareVersion();

/// Encodes a session description as session_description_t.
/// @throws std::invalid_argument if a field would not decode (non-finite
///   T_C_B, bad intrinsics, an empty or inverted box, voxel_m < 0 or NaN,
///   a claw_name that is not IsPlainClawName).
std::vector<uint8_t> EncodeSessionDescription(const SessionDescription& session);

/// True when `name` may name a claw in a session description: 1..256
/// bytes, no '/', '\\' or control character, not "." or "..". A claw name
/// is a name, never a path (a publisher must not steer a file).
bool IsPlainClawName(const std::string& name);

/// True when every value `session` asks for of its receiver is within
/// session_limits.hpp's limits (the rig config file's): the workspace box,
/// the voxel (when not 0) and T_C_B's translation; else false and *why, one
/// line naming the field, its value and the limit.
bool SessionWithinLimits(const SessionDescription& session, std::string* why);

/// Decodes a session_description_t into *out.
///
/// Rejects malformed bytes (wrong type hash, truncated, bad string lengths,
/// trailing bytes), unknown claw kinds, a claw name that is not a plain
/// name (IsPlainClawName; reason kBadClawName), a non-finite or
/// non-unit T_C_B (as DecodeGripperState), flags other than 0/1, a bad
/// intrinsics override (size <= 0 or over 2^24 pixels, focal lengths not
/// finite and > 0, centre not finite), a workspace box that is not finite
/// with min < max on every axis, and a voxel size not finite and >= 0.
/// @param error  if not null, set to a one-line reason on failure.
bool DecodeSessionDescription(const void* data, size_t size, SessionDescription* out, std::string* error,
                              MessageError* reason = nullptr);

}  // namespace graspfill::io
