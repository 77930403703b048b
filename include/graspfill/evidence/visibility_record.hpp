// SPDX-License-Identifier: BSD-3-Clause
// What the camera saw, kept in the gripper frame G: a bounded set of key
// frames (measured depth, the claw's depth, T_C_G) spread over the turn,
// tested by projection. For a point in G it answers whether some ray
// passed it (seen free), measured it (surface), was stopped by the claw
// in front of it (behind the claw) or never reached it.
//
// Why key frames rather than a voxel grid: the queries are exact at the
// sensor's resolution (the top of a can lies 1-3 mm below the palm; a
// 4 mm grid cannot tell), a frame costs nothing unless it becomes a key
// frame, and memory is bounded by max_key_frames x the workspace's image
// footprint (about 0.9 MB per key frame for the default box at 0.55 m).
// The raw depth is kept (before the workspace crop): a ray that reached
// the far wall carved every point in front of it.
//
// Key frames are immutable and shared: copying the record (a snapshot for
// the repair thread) copies pointers only.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "graspfill/fusion/workspace_crop.hpp"
#include "graspfill/types.hpp"

namespace graspfill::evidence {

/// What the record knows about a point, strongest first.
enum class Visibility : uint8_t {
  kNeverSeen = 0,   ///< no key frame's ray reached it (occluded or out of view)
  kBehindClaw = 1,  ///< a ray towards it hit the claw first
  kSurface = 2,     ///< a measured depth within the margin of it
  kSeenFree = 3,    ///< a ray passed it and measured something farther
};

/// Key frames voting each way for one point.
struct VisibilityVotes {
  int free{0};
  int surface{0};
  int behind_claw{0};
  Visibility Verdict() const;
};

struct VisibilityConfig {
  /// Key frames kept at most (24: one per 15 degrees of a full turn).
  int max_key_frames{24};
  /// A frame becomes a key frame when its viewing direction (from the
  /// workspace centre to the camera, in G) is at least this far from every
  /// key frame's [deg].
  double min_view_angle_deg{12.0};
  /// A point is seen free by a frame when the measured depth behind it is
  /// farther by more than this [m]: > 3 sigma of the sensor noise at
  /// 0.5 m (sigma ~1.2 mm) so that a true surface point is never carved.
  double free_margin_m{0.004};
  /// A measured depth within this of a point marks it surface [m].
  double surface_margin_m{0.003};
  /// The free test reads the nearest depth in a (2r+1)^2 window: a mixed
  /// pixel at a silhouette must not carve the edge it grazes [px].
  int erode_px{1};
  /// The safe bound carves whole voxels, so its test reads a wider window:
  /// every ray through the voxel must have passed it. 6 px holds a 5 mm
  /// voxel's half diagonal (4.3 mm) at 0.4 m and f = 525 px [px].
  int coarse_erode_px{6};
  /// The planner's safe bound (safe_bound.hpp) is kept at this voxel edge
  /// as key frames come [m]: each new one carves the voxels still set, so
  /// a repair reads the bound instead of testing the whole box against
  /// every key frame (14 ms on a full turn). 0 keeps none; a repair asking
  /// for another voxel computes its own.
  double safe_bound_voxel_m{0.005};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// One frame's evidence over the workspace's image rectangle.
struct KeyFrame {
  int64_t utime{0};
  Eigen::Isometry3f T_C_G{Eigen::Isometry3f::Identity()};
  CameraIntrinsics intrinsics;
  fusion::PixelRect roi;                   ///< the arrays cover this rectangle
  Eigen::Vector3f view_dir_G{0, 0, 1};     ///< workspace centre -> camera, unit
  std::vector<float> depth_m;              ///< measured z-depth, 0 = no return
  std::vector<float> free_depth_m;         ///< window minimum of depth_m (0 if any pixel is 0)
  std::vector<float> coarse_free_depth_m;  ///< the same over the coarse window
  std::vector<float> claw_depth_m;         ///< the posed claw's z-depth, 0 = no claw
  /// free_depth_m's maximum over each kFreeBlockPx-square block of the
  /// rectangle (row by row, the last ones cut short): a point farther than
  /// it is seen free by no pixel of the block, fine or coarse, which most
  /// points the repair asks about are. A few kB, where the pixels are a
  /// few hundred: the test reads it from cache.
  std::vector<float> free_depth_block_max_m;
  static constexpr int kFreeBlockPx = 4;
};

class VisibilityRecord {
 public:
  VisibilityRecord() = default;
  /// Throws std::invalid_argument on a bad config or box.
  VisibilityRecord(const VisibilityConfig& config, const fusion::WorkspaceBox& workspace);

  /// Offers a fused frame: `raw` as measured (before crop and mask),
  /// `claw_depth_m` the claw's z-depth over the whole image (0 = none),
  /// the gripper at T_C_G. Returns true if it became a key frame. Costs an
  /// angle test unless it does; allocates only for a new key frame.
  bool Offer(const DepthFrame& raw, const std::vector<float>& claw_depth_m, const Eigen::Isometry3d& T_C_G);

  /// Every key frame's vote for `p_G`.
  VisibilityVotes Votes(const Eigen::Vector3f& p_G) const;
  /// The strongest vote (see Visibility).
  Visibility Classify(const Eigen::Vector3f& p_G) const { return Votes(p_G).Verdict(); }
  /// True when some key frame sees `p_G` free by at least `extra_m` beyond
  /// the free margin; `coarse` reads the coarse window (the safe bound
  /// carves whole voxels with it).
  /// `first_key_frame` (may be null): the key frame asked first, set to the
  /// one that saw the point free; neighbouring points are mostly carved by
  /// the same one (the repair walks its samples so). The answer is the same.
  bool SeenFree(const Eigen::Vector3f& p_G, float extra_m = 0.0f, bool coarse = false,
                size_t* first_key_frame = nullptr) const;
  /// SeenFree asking key frame `key_frame` only.
  bool SeenFreeBy(size_t key_frame, const Eigen::Vector3f& p_G, float extra_m = 0.0f,
                  bool coarse = false) const;
  /// SeenFreeBy(key_frame, (x_G[i], y_G, z_G), extra_m, coarse) for each
  /// i < count, into seen_free[i] (1 or 0): the same answers, a row of points
  /// projected at a time (the safe bound's carve).
  void SeenFreeAlongX(size_t key_frame, const float* x_G, int count, float y_G, float z_G, float extra_m,
                      bool coarse, uint8_t* seen_free) const;
  /// The safe bound at config().safe_bound_voxel_m over the key frames so
  /// far (the whole box before the first); null when none is kept.
  const std::shared_ptr<const SafeBound>& safe_bound() const { return safe_bound_; }

  bool empty() const { return key_frames_.empty(); }
  size_t size() const { return key_frames_.size(); }
  const std::vector<std::shared_ptr<const KeyFrame>>& key_frames() const { return key_frames_; }
  const VisibilityConfig& config() const { return config_; }
  const fusion::WorkspaceBox& workspace() const { return workspace_; }
  /// Bytes held by the key frames' arrays.
  size_t memory_bytes() const;

  /// Keeps the posed claw (G) as a solid: no part of the object can be
  /// inside it. Setup-time work (an Embree scene): call when the opening
  /// changes, as the mask does. Throws std::invalid_argument on a bad mesh.
  void SetClaw(const TriangleMesh& claw_G);
  bool has_claw() const { return claw_ != nullptr; }
  /// If `p_G` is inside the claw (the ray from it along `dir_G` leaves the
  /// claw through a face before hitting any other), where that ray leaves
  /// it; nullopt otherwise. For closed, outward-facing claw meshes.
  std::optional<Eigen::Vector3f> ExitClaw(const Eigen::Vector3f& p_G, const Eigen::Vector3f& dir_G) const;

  /// Forgets every key frame and the claw (a new object).
  void Reset();

 private:
  bool FreeIn(const KeyFrame& kf, const Eigen::Vector3f& p_G, float extra_m, bool coarse) const;
  // FreeIn for a point projected to (u, v) in kf's rectangle at depth z.
  bool FreeAt(const KeyFrame& kf, int u, int v, float z, float extra_m, bool coarse) const;

  VisibilityConfig config_;
  fusion::WorkspaceBox workspace_;
  std::vector<std::shared_ptr<const KeyFrame>> key_frames_;
  // Replaced, never changed in place: a copy of the record (the repair
  // thread's snapshot) shares it.
  std::shared_ptr<const SafeBound> safe_bound_;
  struct ClawSolid;
  std::shared_ptr<const ClawSolid> claw_;
  // Offer's working rows, kept from key frame to key frame so that a new
  // one allocates only what it keeps. Never copied: a copy of the record
  // starts without them.
  struct OfferScratch {
    std::vector<float> rows, column_g, column_h, pad;
    OfferScratch() = default;
    OfferScratch(const OfferScratch&) {}
    OfferScratch& operator=(const OfferScratch&) { return *this; }
  };
  OfferScratch scratch_;
  // The window minimum of `in` (w x h) with radius r into `out`.
  static void WindowMin(const std::vector<float>& in, int w, int h, int r, OfferScratch* scratch,
                        std::vector<float>* out);
};

}  // namespace graspfill::evidence
