// SPDX-License-Identifier: BSD-3-Clause
// Value types shared by every graspfill module: camera model, depth frames,
// gripper states, triangle meshes and the object cloud handed to the planner.
//
// Frames (see docs/design.md): C camera (optical: z forward, x right, y down),
// G gripper (origin at the palm face centre, +z the approach direction, the
// object is rigid in G), B robot base. `T_C_G` maps points from G to C.
// Units: meters, seconds; timestamps are int64 microseconds (`utime`).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace graspfill {

/// Pinhole intrinsics of a depth camera, in pixels. Defaults are Kinect-like
/// (640x480, f = 525 px; the Kinect v1 figures used by the TUM RGB-D benchmark).
struct CameraIntrinsics {
  int width{640};
  int height{480};
  double fx{525.0};
  double fy{525.0};
  double cx{319.5};
  double cy{239.5};

  bool operator==(const CameraIntrinsics& o) const {
    return width == o.width && height == o.height && fx == o.fx && fy == o.fy && cx == o.cx && cy == o.cy;
  }
  bool operator!=(const CameraIntrinsics& o) const { return !(*this == o); }
};

/// One depth image. `depth_m` is row-major, width*height values in meters;
/// 0 marks an invalid pixel (no return, dropout or masked out).
struct DepthFrame {
  int64_t utime{0};
  CameraIntrinsics intrinsics;
  std::vector<float> depth_m;

  float at(int u, int v) const { return depth_m[v * intrinsics.width + u]; }
};

/// The gripper at one instant: its pose in the camera frame and its fingers.
struct GripperState {
  int64_t utime{0};
  /// Pose of the gripper in the camera frame (maps p_G to p_C).
  Eigen::Isometry3d T_C_G{Eigen::Isometry3d::Identity()};
  /// Claw opening; its meaning is the claw model's (for graspfill's
  /// procedural claws: distance of each finger's inner face from the axis).
  double opening_m{0.0};
  /// Optional finger joint values (rad or m); empty means "from opening".
  std::vector<double> joint_values;
  /// The robot's number of the grasp the claw is in; 0 = not numbered, or
  /// released (docs/live.md, "Grasp after grasp").
  int64_t grasp_id{0};
};

/// A plain indexed triangle mesh (vertices in the frame its name says).
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;

  bool empty() const { return triangles.empty(); }
  /// Appends `other`, re-indexing its triangles.
  void Append(const TriangleMesh& other);
  /// Returns this mesh with every vertex mapped by `T`.
  TriangleMesh Transformed(const Eigen::Isometry3d& T) const;
};

/// What a collision mesh for the planner is (collision_mesh_t.kind).
enum class CollisionMeshKind : uint8_t {
  kDecimated = 0,   ///< the object's shape, decimated and inflated to hold its cloud
  kConvexHull = 1,  ///< a convex hull of it
};

/// An 8-bit RGB picture for people (`graspfill view`): row-major from the
/// top-left pixel, 3 bytes (red, green, blue) per pixel.
struct RgbImage {
  int width{0};
  int height{0};
  std::vector<uint8_t> rgb;  ///< width * height * 3 bytes
};

/// Where an object-cloud point comes from.
enum class Provenance : uint8_t {
  kObserved = 0,  ///< fused from depth frames
  kSurface = 1,   ///< repaired from a reconstructed surface (claw holes)
  kSymmetry = 2,  ///< repaired by the object's symmetry (missing top)
};

/// Kind of a hole in the object cloud.
enum class HoleKind : uint8_t {
  kClaw = 0,            ///< where a finger covered the object (side)
  kMissingSurface = 1,  ///< the top the camera never sees
};

/// Summary of one hole found (and possibly repaired) in the object cloud.
struct HoleSummary {
  HoleKind kind{HoleKind::kClaw};
  int boundary_points{0};
  Eigen::Vector3f box_min_G{0, 0, 0};  ///< axis-aligned box in G [m]
  Eigen::Vector3f box_max_G{0, 0, 0};
  int points_added{0};
  /// Nothing is known inside: no completion explained the hole better than
  /// leaving it open (an open cup's mouth). Nothing was added there; the
  /// planner should avoid it (the safe bound covers it).
  bool unobserved{false};
  /// Confidence of the points added to it (0 when none), 0..1.
  float confidence{0.0f};
};

/// Wall time of one pipeline stage, for reports and the status message.
struct StageTiming {
  std::string stage;
  double ms{0.0};
};

/// The planner's safe bound: the space that may still hold the object, a
/// dense bit grid in G (evidence/safe_bound.hpp computes it from what the
/// camera saw). Voxel (i, j, k) spans origin_G + voxel_m * [i, i+1) x
/// [j, j+1) x [k, k+1); bit i + nx * (j + ny * k) set (LSB first) = may
/// hold the object. Empty (no bits) when no evidence was kept.
struct SafeBound {
  Eigen::Vector3f origin_G{0, 0, 0};
  float voxel_m{0.0f};
  int nx{0}, ny{0}, nz{0};
  std::vector<uint8_t> bits;

  bool empty() const { return bits.empty(); }
  bool Occupied(int i, int j, int k) const {
    const size_t b = static_cast<size_t>(i) +
                     static_cast<size_t>(nx) * (static_cast<size_t>(j) + static_cast<size_t>(ny) * k);
    return (bits[b >> 3] >> (b & 7)) & 1;
  }
  /// Whether the voxel holding `p_G` is set; false outside the grid.
  bool Contains(const Eigen::Vector3f& p_G) const;
  /// Voxels set.
  size_t count() const;
};

/// The object's point cloud as handed to the planner, in the gripper frame.
struct ObjectCloud {
  int64_t utime{0};
  int64_t seq{0};
  std::string frame_name{"gripper"};
  /// Pose of the gripper in the camera frame at `utime`.
  Eigen::Isometry3d T_C_G{Eigen::Isometry3d::Identity()};
  std::vector<Eigen::Vector3f> points_G;
  std::vector<Eigen::Vector3f> normals_G;  ///< unit, or empty if unknown
  std::vector<Provenance> provenance;      ///< one per point
  /// How much to trust each point, in [0, 1], or empty (all observed: 1).
  /// Observed points are 1; added points get the repair's prior for their
  /// source, raised where the camera's evidence says the spot was hidden,
  /// and at most 0.5 where nothing decides (a lid no view saw): above 0.5,
  /// more likely right than not (repair/repairer.hpp documents the values).
  std::vector<float> confidence;
  std::vector<HoleSummary> holes;
  /// Where the object may still be (empty unless the repair had evidence).
  SafeBound safe_bound;
  std::vector<StageTiming> timings;
  /// The grasp this is a model of (GripperState::grasp_id).
  int64_t grasp_id{0};
  /// The grasp's final model (it ended, or the session stopped).
  bool is_final{false};
  /// When its newest frame reached the live module (steady clock, this
  /// process only: not sent on the bus); the clock's epoch when not known.
  /// The latency timings are measured from it.
  std::chrono::steady_clock::time_point newest_frame_arrival{};

  size_t size() const { return points_G.size(); }
};

}  // namespace graspfill
