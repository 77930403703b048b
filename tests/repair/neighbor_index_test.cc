#include "graspfill/repair/neighbor_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <utility>

#include "graspfill/synth/paper_protocol.hpp"
#include "graspfill/synth/random.hpp"

namespace graspfill::repair {
namespace {

// Process CPU time [ms]: steadier than wall time on a shared machine; with
// OMP_THREAD_LIMIT=1 (as ctest runs the tests) it is one core's time.
double CpuMs() { return 1e3 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

PointList RandomCloud(int n, uint64_t seed) {
  synth::Rng rng(seed);
  PointList points;
  for (int i = 0; i < n; ++i) {
    points.emplace_back(static_cast<float>(rng.Uniform()), static_cast<float>(rng.Uniform()),
                        static_cast<float>(0.1 * rng.Uniform()));
  }
  return points;
}

// All squared distances from `q`, sorted (distance, index).
std::vector<std::pair<double, int>> BruteForce(const PointList& points, const Eigen::Vector3f& q) {
  std::vector<std::pair<double, int>> all;
  for (size_t i = 0; i < points.size(); ++i) {
    all.emplace_back((points[i].cast<double>() - q.cast<double>()).squaredNorm(),
                     static_cast<int>(i));
  }
  std::sort(all.begin(), all.end());
  return all;
}

TEST(NeighborIndex, RejectsAnEmptyCloud) {
  const PointList empty;
  EXPECT_THROW(NeighborIndex index(empty), std::invalid_argument);
}

TEST(NeighborIndex, KnnMatchesBruteForce) {
  const PointList points = RandomCloud(3000, 1);
  const NeighborIndex index(points);
  EXPECT_EQ(index.size(), points.size());
  EXPECT_EQ(&index.points(), &points);
  std::vector<int> nn;
  std::vector<double> d2;
  synth::Rng rng(2);
  for (int t = 0; t < 200; ++t) {
    // Half the queries are cloud points (themselves first), half are not.
    const Eigen::Vector3f q =
        t % 2 == 0 ? points[static_cast<size_t>(t * 13)]
                   : Eigen::Vector3f(static_cast<float>(rng.Uniform()),
                                     static_cast<float>(rng.Uniform()), 0.05f);
    for (const int k : {1, 7, 21}) {
      index.Knn(q, k, &nn, &d2);
      const auto truth = BruteForce(points, q);
      ASSERT_EQ(nn.size(), static_cast<size_t>(k));
      ASSERT_EQ(d2.size(), static_cast<size_t>(k));
      for (int j = 0; j < k; ++j) {
        // Distances match exactly in order (indices may swap on ties).
        EXPECT_NEAR(d2[static_cast<size_t>(j)], truth[static_cast<size_t>(j)].first, 1e-12);
        EXPECT_NEAR((points[static_cast<size_t>(nn[static_cast<size_t>(j)])].cast<double>() -
                     q.cast<double>()).squaredNorm(),
                    d2[static_cast<size_t>(j)], 1e-12);
      }
      if (t % 2 == 0) {
        EXPECT_DOUBLE_EQ(d2[0], 0.0);
      }
    }
  }
  // Without the distances, and more neighbours than points.
  const PointList few{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const NeighborIndex few_index(few);
  few_index.Knn(Eigen::Vector3f(1.9f, 0, 0), 10, &nn);
  EXPECT_EQ(nn, (std::vector<int>{2, 1, 0}));
}

TEST(NeighborIndex, RadiusMatchesBruteForce) {
  const PointList points = RandomCloud(3000, 4);
  const NeighborIndex index(points);
  std::vector<int> nn;
  std::vector<double> d2;
  for (int t = 0; t < 100; ++t) {
    const Eigen::Vector3f& q = points[static_cast<size_t>(t * 29)];
    const double radius = 0.03;
    index.Radius(q, radius, &nn, &d2);
    std::vector<int> found = nn;
    std::sort(found.begin(), found.end());
    std::vector<int> truth;
    for (const auto& [dist_sq, i] : BruteForce(points, q)) {
      if (dist_sq <= radius * radius) truth.push_back(i);
    }
    std::sort(truth.begin(), truth.end());
    EXPECT_EQ(found, truth);
    for (size_t j = 0; j < nn.size(); ++j) {
      EXPECT_NEAR((points[static_cast<size_t>(nn[j])] - q).squaredNorm(), d2[j], 1e-9);
    }
  }
}

// The cost every step pays: printed for ~50k points, not asserted.
TEST(NeighborIndex, TimingOn50k) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.num_points = 66000;  // ~50k left after the cut and the holes
  const PointList points = synth::MakePaperProtocolCloud(config).holey;
  double t0 = CpuMs();
  const NeighborIndex index(points);
  const double build_ms = CpuMs() - t0;
  std::vector<int> nn;
  std::vector<double> d2;
  double knn_ms = 1e30;
  for (int r = 0; r < 3; ++r) {
    t0 = CpuMs();
    for (const Eigen::Vector3f& p : points) index.Knn(p, 21, &nn, &d2);
    knn_ms = std::min(knn_ms, CpuMs() - t0);
  }
  std::printf("NeighborIndex, %zu points: build %.1f ms, one kNN(21) per point %.1f ms "
              "(best of 3, CPU time)\n",
              points.size(), build_ms, knn_ms);
  EXPECT_EQ(nn.size(), 21u);
}

}  // namespace
}  // namespace graspfill::repair
