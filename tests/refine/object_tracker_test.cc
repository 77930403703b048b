// SPDX-License-Identifier: BSD-3-Clause
// Object tracking (the object slipping in G): aligned to a model of the
// object as first seen, the object pixels of a frame taken after a slip
// give the slip's displacement; a frame without one leaves the pose as it
// is; frames it cannot trust are rejected and counted, the pose untouched.
// Frames are synth's (an ideal sensor), the model the exact surface sampled.
#include "graspfill/refine/object_tracker.hpp"

#include <gtest/gtest.h>

#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/renderer.hpp"
#include "synth/scene.hpp"

namespace graspfill::refine {
namespace {

// A sphere (every shift is seen) in the three-finger claw, slipping 3 mm.
synth::SceneConfig SlippingSphere(double slip_m) {
  synth::SceneConfig c;
  c.shape = synth::Shape::kSphere;
  c.sensor = synth::SensorModelConfig::Ideal();
  c.seed = 4;
  c.slip.distance_m = slip_m;
  return c;
}

// What the pipeline hands the tracker: the object's pixels only (the claw
// cut out, the rest cropped), here from the renderer's labels.
DepthFrame ObjectPixels(const synth::Scene& scene, const synth::SceneRenderer& renderer, int f) {
  const synth::IdealDepthImage ideal = renderer.RenderIdeal(f);
  DepthFrame frame;
  frame.utime = scene.DepthUtime(f);
  frame.intrinsics = ideal.intrinsics;
  frame.depth_m.assign(ideal.depth_m.size(), 0.0f);
  for (size_t i = 0; i < ideal.depth_m.size(); ++i) {
    if (ideal.label[i] == synth::SurfaceLabel::kObject) frame.depth_m[i] = ideal.depth_m[i];
  }
  return frame;
}

class ObjectTrackerTest : public ::testing::Test {
 protected:
  ObjectTrackerTest() : scene_(SlippingSphere(0.003)), renderer_(scene_) {
    // The model: the object as grasped, in G (= its frame as first seen).
    const mesh::SurfaceSamples model = mesh::SampleSurface(scene_.object_G(), 40000, 7);
    points_ = model.points;
    normals_ = model.normals;
  }
  Eigen::Isometry3d TrueT_C_G(int f) const { return scene_.T_C_G_AtUtime(scene_.DepthUtime(f)); }
  int last() const { return scene_.num_frames() - 1; }

  synth::Scene scene_;
  synth::SceneRenderer renderer_;
  std::vector<Eigen::Vector3f> points_;
  std::vector<Eigen::Vector3f> normals_;
};

TEST_F(ObjectTrackerTest, NothingToTrackWithoutAModel) {
  ObjectTracker tracker;
  EXPECT_FALSE(ObjectTrackingConfig{}.enabled);  // off by default
  EXPECT_EQ(tracker.Track(ObjectPixels(scene_, renderer_, 0), TrueT_C_G(0)), TrackOutcome::kNoModel);
  EXPECT_TRUE(tracker.S_G().isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(tracker.stats().frames_no_model, 1);
}

TEST_F(ObjectTrackerTest, FindsTheSlip) {
  ASSERT_GE(scene_.DepthUtime(last()), scene_.slip().end_utime());  // the premise
  ObjectTracker tracker;
  tracker.SetModel(points_, normals_);
  ASSERT_TRUE(tracker.has_model());
  EXPECT_EQ(tracker.Track(ObjectPixels(scene_, renderer_, last()), TrueT_C_G(last())),
            TrackOutcome::kTracked);
  const Eigen::Vector3d d = scene_.slip().Displacement_G();
  const Eigen::Vector3d found = tracker.S_G().translation();
  std::printf("slip %.3f %.3f %.3f mm, found %.3f %.3f %.3f mm, %d matches, rms %.3f mm\n", 1000 * d.x(),
              1000 * d.y(), 1000 * d.z(), 1000 * found.x(), 1000 * found.y(), 1000 * found.z(),
              tracker.last_matches(), 1000 * tracker.last_rms_m());
  EXPECT_LT((found - d).norm(), 0.0002);
  EXPECT_TRUE(tracker.S_G().linear().isIdentity(1e-12));  // a shift only, by default
  EXPECT_EQ(tracker.stats().frames_tracked, 1);
  EXPECT_EQ(tracker.stats().pose_updates, 1);
  // Fused at T_C_G * S_G, the frame's object pixels land on the model.
  EXPECT_TRUE(tracker.T_C_O(TrueT_C_G(last())).isApprox(TrueT_C_G(last()) * tracker.S_G()));
}

TEST_F(ObjectTrackerTest, AFrameBeforeTheSlipLeavesThePose) {
  ObjectTracker tracker;
  tracker.SetModel(points_, normals_);
  EXPECT_EQ(tracker.Track(ObjectPixels(scene_, renderer_, 0), TrueT_C_G(0)), TrackOutcome::kTracked);
  EXPECT_TRUE(tracker.S_G().isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(tracker.stats().pose_updates, 0);
  EXPECT_LT(tracker.stats().max_step_m, 0.0002);  // what it found: nothing
}

TEST_F(ObjectTrackerTest, RejectsAndCountsWhatItCannotTrust) {
  ObjectTrackingConfig config;
  config.max_step_m = 0.002;  // below the 3 mm slip
  ObjectTracker tracker(config);
  tracker.SetModel(points_, normals_);
  EXPECT_EQ(tracker.Track(ObjectPixels(scene_, renderer_, last()), TrueT_C_G(last())), TrackOutcome::kJump);
  EXPECT_TRUE(tracker.S_G().isApprox(Eigen::Isometry3d::Identity()));
  DepthFrame empty = ObjectPixels(scene_, renderer_, 0);
  std::fill(empty.depth_m.begin(), empty.depth_m.end(), 0.0f);
  EXPECT_EQ(tracker.Track(empty, TrueT_C_G(0)), TrackOutcome::kTooFewPoints);
  // The object where the model is not (the gripper pose 2 cm off): no match.
  Eigen::Isometry3d off = TrueT_C_G(0);
  off.pretranslate(Eigen::Vector3d(0.02, 0.0, 0.0));
  EXPECT_EQ(tracker.Track(ObjectPixels(scene_, renderer_, 0), off), TrackOutcome::kTooFewPoints);
  EXPECT_EQ(tracker.stats().rejected_jump, 1);
  EXPECT_EQ(tracker.stats().rejected_too_few_points, 2);
  EXPECT_EQ(tracker.stats().rejected(), 3);
  EXPECT_EQ(tracker.stats().frames_tracked, 0);
  tracker.Reset();
  EXPECT_FALSE(tracker.has_model());
  EXPECT_EQ(tracker.stats().rejected(), 0);
}

// The same alignment with Open3D's point-to-plane ICP (6 DoF, its own
// KD-tree of the model per call, as its API builds one), on the same object
// pixels: both find the slip; the times are printed (docs/imperfect-robots.md,
// "Object tracking").
TEST_F(ObjectTrackerTest, Open3DRegistrationFindsTheSameSlip) {
  const DepthFrame frame = ObjectPixels(scene_, renderer_, last());
  const Eigen::Isometry3d T_G_C = TrueT_C_G(last()).inverse();
  const CameraIntrinsics& K = frame.intrinsics;
  open3d::geometry::PointCloud source, target;
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const float z = frame.at(u, v);
      if (z > 0.0f) {
        source.points_.push_back(T_G_C * Eigen::Vector3d((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z));
      }
    }
  }
  // About the tracker's 1500 points.
  const size_t every = std::max<size_t>(1, source.points_.size() / 1500);
  source = *source.UniformDownSample(every);
  for (size_t i = 0; i < points_.size(); ++i) {
    target.points_.push_back(points_[i].cast<double>());
    target.normals_.push_back(normals_[i].cast<double>());
  }
  const int runs = 10;
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < runs; ++r) {
    T = open3d::pipelines::registration::RegistrationICP(
            source, target, 0.0045, Eigen::Matrix4d::Identity(),
            open3d::pipelines::registration::TransformationEstimationPointToPlane(),
            open3d::pipelines::registration::ICPConvergenceCriteria(1e-8, 1e-8, 30))
            .transformation_;
  }
  const double open3d_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / runs;
  // T maps the frame's points onto the model: the object's motion is T^-1,
  // measured at the sphere's centre.
  const Eigen::Vector3d centre = mesh::Bounds(scene_.object_G()).center();
  const Eigen::Isometry3d S_open3d(T.inverse());
  const Eigen::Vector3d d = scene_.slip().Displacement_G();
  const double open3d_miss = (S_open3d * centre - centre - d).norm();

  ObjectTracker tracker;
  tracker.SetModel(points_, normals_);
  double ours_ms = 0.0;
  for (int r = 0; r < runs; ++r) {
    ObjectTracker fresh;
    fresh.SetModel(points_, normals_);  // untimed: built once per model
    start = std::chrono::steady_clock::now();
    ASSERT_EQ(fresh.Track(frame, TrueT_C_G(last())), TrackOutcome::kTracked);
    ours_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    tracker = fresh;
  }
  ours_ms /= runs;
  const double ours_miss = (tracker.S_G().translation() - d).norm();
  std::printf(
      "3 mm slip, %zu object points: Open3D point-to-plane ICP %.3f mm off in %.2f ms "
      "(its KD-tree of %zu model points included), ours %.3f mm off in %.2f ms\n",
      source.points_.size(), 1000 * open3d_miss, open3d_ms, target.points_.size(), 1000 * ours_miss, ours_ms);
  EXPECT_LT(open3d_miss, 0.0005);
  EXPECT_LT(ours_miss, 0.0002);
}

TEST(ObjectTrackingConfigTest, BadValuesAreRejected) {
  ObjectTrackingConfig c;
  c.band_m = c.cell_m;
  EXPECT_THROW(ObjectTracker{c}, std::invalid_argument);
  c = ObjectTrackingConfig{};
  c.min_step_m = c.max_step_m;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = ObjectTrackingConfig{};
  c.warmup_frames = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  std::vector<Eigen::Vector3f> two(2, Eigen::Vector3f::Zero()), one(1, Eigen::Vector3f::UnitZ());
  ObjectTracker tracker;
  EXPECT_THROW(tracker.SetModel(two, one), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::refine
