// SPDX-License-Identifier: BSD-3-Clause
// The rig config's ranges and checks: one table for the parser
// (rig_config_parse.cpp), the dump (rig_config_dump.cpp) and Validate
// (rig_config.cpp). Every failure is a ConfigError naming the field.
#pragma once

#include <string>
#include <vector>

#include "config/rig_config.hpp"
#include "graspfill/core/openmp_threads.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/mesh/planner_mesh.hpp"
#include "graspfill/refine/pose_refiner.hpp"

namespace graspfill::rt::internal {

struct Range {
  double min;
  double max;
  const char* unit;
};

inline constexpr Range kVideoPx{0, 16384, "pixels"};
inline constexpr Range kFps{0, 1000, "frames/s"};
inline constexpr Range kImagePx{1, 16384, "pixels"};
inline constexpr Range kDepthPixels{1, static_cast<double>(io::kMaxDepthPixels), "pixels"};
inline constexpr Range kFocalPx{1.0, 100000.0, "pixels"};
inline constexpr Range kCentrePx{-100000.0, 100000.0, "pixels"};
inline constexpr Range kTranslationM{-io::kMaxHandEyeTranslationM, io::kMaxHandEyeTranslationM, "m"};
inline constexpr Range kQuaternion{-1.0, 1.0, ""};
inline constexpr Range kClockOffsetS{-3600.0, 3600.0, "s"};
inline constexpr Range kPoseGapS{0.001, 1.0, "s"};
inline constexpr Range kBoxM{-io::kMaxWorkspaceM, io::kMaxWorkspaceM, "m"};  // session_limits.hpp
inline constexpr Range kVoxelM{io::kMinVoxelM, io::kMaxVoxelM, "m"};
inline constexpr Range kTruncVoxels{1.5, 32.0, "voxels"};
inline constexpr Range kBlockResolution{2, 128, "voxels"};
inline constexpr Range kStride{1, 16, "pixels"};
inline constexpr Range kFusionPixels{64 * 48, 4096 * 4096, "pixels"};
inline constexpr Range kSafeBoundM{0.0, 0.1, "m"};  // and 0 or >= kMinSafeBoundM
inline constexpr double kMinSafeBoundM = 0.0005;
inline constexpr Range kRimBandM{0.0, 0.5, "m"};
inline constexpr Range kCorrectionM{0.0, 0.005, "m"};
inline constexpr Range kDepthScale{refine::kMinDepthScale, refine::kMaxDepthScale, ""};
inline constexpr Range kCorrectionDeg{0.0, 2.0, "deg"};
inline constexpr Range kPublishEvery{0, 100000, "frames"};
inline constexpr Range kStatusPeriodS{0.05, 60.0, "s"};
inline constexpr Range kNumThreads{0, kMaxOpenMpThreads, "threads"};
inline constexpr Range kMeshTriangles{mesh::kMinPlannerTriangles, mesh::kMaxPlannerTriangles, "triangles"};
inline constexpr double kUnitTolerance = 1e-3;  // |norm - 1| of a typed quaternion

/// Shortest round-trip text of v, fixed notation from 1e-4 up (as %g).
std::string FormatNumber(double v);
/// v within r, else "FIELD 'V': out of range, expected MIN..MAX UNIT".
void CheckRange(const std::string& field, double v, const Range& r);
/// One channel name, as LCM takes it (io/channel_names.hpp).
void CheckChannel(const std::string& field, const std::string& v);
/// Two channels of the same name: named at `role`.
ConfigError SameChannelError(const std::string& role, const std::string& name, const std::string& other_role);
/// Every name as LCM takes it, and no two the same.
void CheckChannels(const RigConfig::Channels& channels);
/// v one of `allowed`.
void CheckOneOf(const std::string& field, const std::string& v, const std::vector<std::string>& allowed);
/// Both corners within kBoxM, min below max on every axis.
void CheckBox(const std::string& field, const RigConfig::Box& b);
/// The translation within kTranslationM; the rotation a unit quaternion.
void CheckPose(const std::string& field, const RigConfig::Pose& p);
void CheckIntrinsics(const std::string& field, const RigConfig::Intrinsics& K);
/// 0 (no bound) or kMinSafeBoundM..kSafeBoundM.max.
void CheckSafeBound(const std::string& field, double v);

}  // namespace graspfill::rt::internal
