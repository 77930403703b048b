// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/evidence/visibility_record.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../allocation_count.hpp"
#include "evidence_fixtures.hpp"
#include "graspfill/core/random.hpp"

namespace graspfill::evidence {
namespace {

using testing::PlateFrame;
using testing::PointAt;
using testing::RecordOfPlate;
using testing::TestBox;
using testing::TestFrame;

TEST(VisibilityRecord, ClassifiesFreeSurfaceOccludedAndBehindClaw) {
  const VisibilityRecord record = RecordOfPlate();
  // In front of the plate: the ray passed it.
  EXPECT_EQ(record.Classify(PointAt(250, 300, 0.40f)), Visibility::kSeenFree);
  // On the plate, within the margin either way.
  EXPECT_EQ(record.Classify(PointAt(250, 300, 0.502f)), Visibility::kSurface);
  EXPECT_EQ(record.Classify(PointAt(250, 300, 0.498f)), Visibility::kSurface);
  // Behind the plate: hidden by the object itself.
  EXPECT_EQ(record.Classify(PointAt(250, 300, 0.60f)), Visibility::kNeverSeen);
  // Behind the claw block (on the plate's pixels): the claw hid it.
  EXPECT_EQ(record.Classify(PointAt(320, 220, 0.45f)), Visibility::kBehindClaw);
  // In front of the claw the ray passed.
  EXPECT_EQ(record.Classify(PointAt(320, 220, 0.20f)), Visibility::kSeenFree);
  // Beside the plate, the wall behind: free up to the wall.
  EXPECT_EQ(record.Classify(PointAt(100, 100, 0.90f)), Visibility::kSeenFree);
  // Outside the image: never seen.
  EXPECT_EQ(record.Classify(PointAt(-60, 300, 0.40f)), Visibility::kNeverSeen);
}

TEST(VisibilityRecord, SilhouettePixelsDoNotCarveTheEdgeTheyGraze) {
  const VisibilityRecord record = RecordOfPlate();
  // Just outside the plate's left edge (pixel 199 sees the wall, 200 the
  // plate): a point there at 0.7 m is within the erosion window.
  EXPECT_NE(record.Classify(PointAt(199, 300, 0.70f)), Visibility::kSeenFree);
  // Five pixels out it is carved.
  EXPECT_EQ(record.Classify(PointAt(194, 300, 0.70f)), Visibility::kSeenFree);
}

TEST(VisibilityRecord, TheCoarseTestKeepsAWiderBandAroundSilhouettes) {
  const VisibilityRecord record = RecordOfPlate();
  // 4 px left of the plate: free for a point, not for a whole voxel (6 px window).
  EXPECT_TRUE(record.SeenFree(PointAt(196, 300, 0.70f)));
  EXPECT_FALSE(record.SeenFree(PointAt(196, 300, 0.70f), 0.0f, /*coarse=*/true));
  EXPECT_TRUE(record.SeenFree(PointAt(192, 300, 0.70f), 0.0f, /*coarse=*/true));
  // The extra margin is along the ray: 0.25 m in front of the wall is not
  // free by 0.3 m more, 0.1 m more is.
  EXPECT_FALSE(record.SeenFree(PointAt(100, 100, 0.75f), 0.3f));
  EXPECT_TRUE(record.SeenFree(PointAt(100, 100, 0.75f), 0.1f));
}

TEST(VisibilityRecord, PointsInsideTheClawLeaveItAlongTheRay) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  EXPECT_FALSE(record.ExitClaw({0, 0, 0.5f}, {1, 0, 0}).has_value());  // no claw yet
  record.SetClaw(testing::ClawBlock());
  const auto out = record.ExitClaw({0.005f, 0, 0.5f}, {-2, 0, 0});
  ASSERT_TRUE(out.has_value());
  EXPECT_NEAR(out->x(), -0.01f, 1e-5f);
  EXPECT_NEAR(out->z(), 0.5f, 1e-6f);
  // Outside the claw, towards it or away: no exit.
  EXPECT_FALSE(record.ExitClaw({0.05f, 0, 0.5f}, {-1, 0, 0}).has_value());
  EXPECT_FALSE(record.ExitClaw({0.05f, 0, 0.5f}, {1, 0, 0}).has_value());
  const VisibilityRecord copy = record;
  record.Reset();
  EXPECT_FALSE(record.has_claw());
  EXPECT_TRUE(copy.ExitClaw({0, 0, 0.5f}, {0, 0, 1}).has_value());
}

TEST(VisibilityRecord, NoReturnNeverCarves) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  auto f = PlateFrame();
  for (float& d : f.raw.depth_m) {
    if (d == testing::kWallDepth) d = 0.0f;  // no return beside the plate
  }
  ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Eigen::Isometry3d::Identity()));
  EXPECT_EQ(record.Classify(PointAt(100, 100, 0.90f)), Visibility::kNeverSeen);
  EXPECT_EQ(record.Classify(PointAt(250, 300, 0.40f)), Visibility::kSeenFree);
}

// G turned about the box centre by `deg` about y: the camera sees it from
// another direction.
Eigen::Isometry3d Turned(double deg) {
  const Eigen::Vector3d c = 0.5 * (TestBox().min_G + TestBox().max_G);
  return Eigen::Translation3d(c) * Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitY()) *
         Eigen::Translation3d(-c);
}

TEST(VisibilityRecord, KeyFramesAreSpreadByViewDirectionAndBounded) {
  VisibilityConfig config;
  config.max_key_frames = 3;
  config.min_view_angle_deg = 10.0;
  VisibilityRecord record(config, TestBox());
  const auto f = PlateFrame();
  EXPECT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(0)));
  EXPECT_FALSE(record.Offer(f.raw, f.claw_depth, Turned(5)));  // too close
  EXPECT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(12)));
  EXPECT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(-12)));
  EXPECT_FALSE(record.Offer(f.raw, f.claw_depth, Turned(40)));  // full
  EXPECT_EQ(record.size(), 3u);
  EXPECT_GT(record.memory_bytes(), 0u);
}

// The blocks' maxima only skip pixels that cannot answer: every key
// frame's answer is the one its free depths give pixel by pixel, fine and
// coarse, with and without an extra margin, over a grid of points in front
// of, on and behind the plate, the claw and the wall, from three views.
TEST(VisibilityRecord, SeenFreeIsThePixelsAnswerWhereverTheBlocksSkipThem) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  const auto f = PlateFrame();
  for (const double deg : {0.0, 15.0, -30.0}) ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(deg)));
  const float margin = static_cast<float>(record.config().free_margin_m);
  int free = 0, not_free = 0;
  for (float x = -0.25f; x <= 0.25f; x += 0.0123f) {
    for (float y = -0.2f; y <= 0.2f; y += 0.0171f) {
      for (float z = 0.25f; z <= 1.15f; z += 0.0137f) {
        const Eigen::Vector3f p_G(x, y, z);
        for (size_t k = 0; k < record.size(); ++k) {
          const KeyFrame& kf = *record.key_frames()[k];
          const Eigen::Vector3f p = kf.T_C_G * p_G;
          bool in = p.z() > 0.01f;
          int u = 0, v = 0;
          if (in) {
            const CameraIntrinsics& K = kf.intrinsics;
            const float uf =
                std::floor(static_cast<float>(K.fx) * p.x() / p.z() + static_cast<float>(K.cx) + 0.5f);
            const float vf =
                std::floor(static_cast<float>(K.fy) * p.y() / p.z() + static_cast<float>(K.cy) + 0.5f);
            in = uf >= kf.roi.u0 && uf < kf.roi.u1 && vf >= kf.roi.v0 && vf < kf.roi.v1;
            u = static_cast<int>(uf) - kf.roi.u0;
            v = static_cast<int>(vf) - kf.roi.v0;
          }
          for (const float extra : {0.0f, 0.05f}) {
            for (const bool coarse : {false, true}) {
              bool expected = false;
              if (in) {
                const size_t i = static_cast<size_t>(v) * (kf.roi.u1 - kf.roi.u0) + u;
                const float d = coarse ? kf.coarse_free_depth_m[i] : kf.free_depth_m[i];
                expected = d > 0.0f && d > p.z() + margin + extra;
              }
              ASSERT_EQ(record.SeenFreeBy(k, p_G, extra, coarse), expected)
                  << "key frame " << k << " at " << p_G.transpose() << ", extra " << extra << ", coarse "
                  << coarse;
              (expected ? free : not_free) += 1;
            }
          }
        }
      }
    }
  }
  // Both answers are well represented.
  EXPECT_GT(free, 10000);
  EXPECT_GT(not_free, 10000);
}

TEST(VisibilityRecord, ARowOfPointsGetsEachPointsAnswer) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  const auto f = PlateFrame();
  for (const double deg : {0.0, 15.0, -30.0}) ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(deg)));
  // Rows longer than the row test's chunk, from behind the camera's side
  // of the box to past the image, with steps that land points on pixel
  // borders as well as between them.
  std::vector<float> x_G;
  for (float x = -0.4f; x <= 0.4f; x += 0.00073f) x_G.push_back(x);
  std::vector<uint8_t> free(x_G.size());
  int free_count = 0, not_free = 0;
  for (float y = -0.2f; y <= 0.2f; y += 0.0371f) {
    for (float z = -0.2f; z <= 1.15f; z += 0.0537f) {
      for (size_t k = 0; k < record.size(); ++k) {
        for (const float extra : {0.0f, 0.05f}) {
          for (const bool coarse : {false, true}) {
            record.SeenFreeAlongX(k, x_G.data(), static_cast<int>(x_G.size()), y, z, extra, coarse,
                                  free.data());
            for (size_t i = 0; i < x_G.size(); ++i) {
              const bool expected = record.SeenFreeBy(k, Eigen::Vector3f(x_G[i], y, z), extra, coarse);
              ASSERT_EQ(free[i] != 0, expected)
                  << "key frame " << k << " at " << x_G[i] << " " << y << " " << z;
              (expected ? free_count : not_free) += 1;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(free_count, 10000);
  EXPECT_GT(not_free, 10000);
}

// A key frame's free depths are its depths' minimum over the square of
// erode_px (and coarse_erode_px) pixels about each, cut at the rectangle's
// edges, exactly: checked pixel by pixel against the plain minimum on a
// frame of random depths with random holes (no return), for radii 0-3 and
// the default 1 and 6.
TEST(VisibilityRecord, FreeDepthsAreTheWindowMinimaOfTheDepths) {
  TestFrame f = PlateFrame();
  Rng rng(7);
  for (float& d : f.raw.depth_m) d = rng.Uniform() < 0.05 ? 0.0f : static_cast<float>(0.4 + rng.Uniform());
  for (const auto& [fine, coarse] : {std::pair{1, 6}, std::pair{0, 3}, std::pair{2, 2}}) {
    VisibilityConfig config;
    config.erode_px = fine;
    config.coarse_erode_px = coarse;
    VisibilityRecord record(config, TestBox());
    ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(0)));
    const KeyFrame& k = *record.key_frames()[0];
    const int w = k.roi.u1 - k.roi.u0, h = k.roi.v1 - k.roi.v0;
    ASSERT_GT(w, 50);
    ASSERT_GT(h, 50);
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        for (const int r : {fine, coarse}) {
          float least = std::numeric_limits<float>::infinity();
          for (int y = std::max(0, v - r); y <= std::min(h - 1, v + r); ++y) {
            for (int x = std::max(0, u - r); x <= std::min(w - 1, u + r); ++x) {
              least = std::min(least, k.depth_m[static_cast<size_t>(y) * w + x]);
            }
          }
          const size_t i = static_cast<size_t>(v) * w + u;
          ASSERT_EQ(r == fine ? k.free_depth_m[i] : k.coarse_free_depth_m[i], least)
              << "radius " << r << " at (" << u << ", " << v << ")";
        }
      }
    }
  }
}

// The hot path allocates nothing it could reuse: a new key frame allocates
// what it keeps (the KeyFrame, its four arrays and their free depths'
// block maxima, room in the record's list, and the safe bound it replaces
// with its bit set), not the window
// minima's working rows, which the record keeps from the first key frame.
TEST(VisibilityRecord, AKeyFrameAllocatesOnlyWhatItKeeps) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  const auto f = PlateFrame();
  ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(0)));  // the working rows grow here
  constexpr long kKept = 1 + 5 + 1 + 2;
  for (const double deg : {15.0, 30.0}) {
    const long before = testing::Allocations();
    ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(deg)));
    EXPECT_LE(testing::Allocations() - before, kKept) << "the key frame at " << deg << " degrees";
  }
}

TEST(VisibilityRecord, QueriesFollowTheKeyFramePose) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  const auto f = PlateFrame();
  const Eigen::Isometry3d T_C_G = Turned(30);
  ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, T_C_G));
  // The point that frame saw free / on the plate, expressed in G.
  const Eigen::Isometry3f T_G_C = T_C_G.inverse().cast<float>();
  EXPECT_EQ(record.Classify(T_G_C * PointAt(250, 300, 0.40f)), Visibility::kSeenFree);
  EXPECT_EQ(record.Classify(T_G_C * PointAt(250, 300, 0.50f)), Visibility::kSurface);
  EXPECT_EQ(record.Classify(T_G_C * PointAt(250, 300, 0.60f)), Visibility::kNeverSeen);
  // The frame's pose matters: untransformed, the plate point is not on it.
  EXPECT_NE(record.Classify(PointAt(250, 300, 0.50f)), Visibility::kSurface);
}

TEST(VisibilityRecord, VotesCountEveryKeyFrame) {
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  const auto f = PlateFrame();
  ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(0)));
  ASSERT_TRUE(record.Offer(f.raw, f.claw_depth, Turned(15)));
  // The box centre at 0.7 m: behind the plate in both frames.
  const VisibilityVotes centre = record.Votes(Eigen::Vector3f(0, 0, 0.7f));
  EXPECT_EQ(centre.free + centre.surface + centre.behind_claw, 0);
  // A point near the camera in front of the plate: free in both.
  EXPECT_EQ(record.Votes(PointAt(320, 300, 0.35f)).free, 2);
}

TEST(VisibilityRecord, ResetForgetsButSnapshotsStay) {
  VisibilityRecord record = RecordOfPlate();
  const VisibilityRecord snapshot = record;
  record.Reset();
  EXPECT_TRUE(record.empty());
  EXPECT_EQ(record.Classify(PointAt(250, 300, 0.40f)), Visibility::kNeverSeen);
  EXPECT_EQ(snapshot.Classify(PointAt(250, 300, 0.40f)), Visibility::kSeenFree);
}

TEST(VisibilityRecord, RejectsBadConfigAndMismatchedFrames) {
  VisibilityConfig bad;
  bad.free_margin_m = 0.0;
  EXPECT_THROW(VisibilityRecord(bad, TestBox()), std::invalid_argument);
  bad = VisibilityConfig{};
  bad.max_key_frames = 0;
  EXPECT_THROW(VisibilityRecord(bad, TestBox()), std::invalid_argument);
  VisibilityRecord record(VisibilityConfig{}, TestBox());
  auto f = PlateFrame();
  f.claw_depth.resize(10);
  EXPECT_FALSE(record.Offer(f.raw, f.claw_depth, Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(record.empty());
}

}  // namespace
}  // namespace graspfill::evidence
