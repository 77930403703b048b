// SPDX-License-Identifier: BSD-3-Clause
// PipelineConfig::num_threads: the caller's OpenMP settings come back
// after each call, and the cloud is the same bytes at any count. The
// integration runs on the caller alone (fusion/unit_integrator.hpp), so no
// count starts a team while frames are fused; Open3D's own integration,
// which names a team per call, would. Runs without OMP_THREAD_LIMIT
// (tests/CMakeLists.txt, OPENMP_UNLIMITED).
#include <gtest/gtest.h>
#include <omp.h>

#include <filesystem>
#include <iterator>

#include "graspfill/core/openmp_threads.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "sphere_scene.hpp"

namespace graspfill {
namespace {

// Threads of this process: libgomp keeps a team's threads once it started
// them, so a count that did not grow means no team ran.
int ProcessThreads() {
  const std::filesystem::directory_iterator tasks("/proc/self/task");
  return static_cast<int>(std::distance(begin(tasks), end(tasks)));
}

class PipelineThreads : public PipelineTest {
 public:
  using PipelineTest::Feed;
};

// The cloud of 12 frames fused at `num_threads`; *new_threads: threads the
// process gained while they were fused (Embree's own start with the
// pipeline, before).
ObjectCloud FuseWith(PipelineThreads* scene, int num_threads, int* new_threads = nullptr) {
  PipelineConfig config;
  config.num_threads = num_threads;
  Pipeline pipeline(config, Claw());
  const int before = ProcessThreads();
  scene->Feed(&pipeline, 12);
  EXPECT_EQ(pipeline.stats().frames_integrated, 12);
  ObjectCloud cloud = pipeline.ExtractCloud();
  if (new_threads != nullptr) *new_threads = ProcessThreads() - before;
  return cloud;
}

void ExpectSameBytes(const ObjectCloud& a, const ObjectCloud& b) {
  ASSERT_EQ(a.points_G.size(), b.points_G.size());
  ASSERT_EQ(a.normals_G.size(), b.normals_G.size());
  for (size_t i = 0; i < a.points_G.size(); ++i) {
    ASSERT_EQ(a.points_G[i], b.points_G[i]) << i;
    ASSERT_EQ(a.normals_G[i], b.normals_G[i]) << i;
  }
}

TEST_F(PipelineThreads, OneThreadStartsNoTeamAndEveryCountGivesTheSameCloud) {
  const int max_threads = omp_get_max_threads();
  const int levels = omp_get_max_active_levels();
  // The default, 1, first: a team once started stays in the process.
  int new_threads = -1;
  const ObjectCloud one = FuseWith(this, 1, &new_threads);
  ASSERT_GT(one.size(), 1000u);
  EXPECT_EQ(new_threads, 0) << "an OpenMP team ran with num_threads = 1";
  EXPECT_EQ(omp_get_max_threads(), max_threads);
  EXPECT_EQ(omp_get_max_active_levels(), levels);

  const ObjectCloud own_count = FuseWith(this, 0, &new_threads);
  EXPECT_EQ(new_threads, 0) << "an OpenMP team ran with OpenMP's own count";
  ExpectSameBytes(one, own_count);
  ExpectSameBytes(one, FuseWith(this, 2));
  ExpectSameBytes(one, FuseWith(this, 3));
  EXPECT_EQ(omp_get_max_threads(), max_threads);
  EXPECT_EQ(omp_get_max_active_levels(), levels);
}

TEST(PipelineThreadsConfig, OutOfRangeIsRefused) {
  PipelineConfig config;
  config.num_threads = -1;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config.num_threads = kMaxOpenMpThreads + 1;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config.num_threads = 0;
  EXPECT_NO_THROW(config.Validate());
}

}  // namespace
}  // namespace graspfill
