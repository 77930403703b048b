// SPDX-License-Identifier: BSD-3-Clause
// Metrics on clouds whose nearest-neighbour distances follow from geometry:
// a planar grid of spacing kSpacing compared with itself, shifted along its
// normal, cut in half, or with an outlier added.
#include "eval/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill::eval {
namespace {

using Cloud = std::vector<Eigen::Vector3f>;

constexpr int kN = 20;              // grid is kN x kN points
constexpr float kSpacing = 0.005f;  // 5 mm: far more than every tau tested

// kN x kN grid in the plane z = `z`, columns x = i * spacing, rows y.
// `max_col` keeps only columns i < max_col (to cut the grid).
Cloud Grid(float z, int max_col = kN) {
  Cloud c;
  for (int i = 0; i < max_col; ++i) {
    for (int j = 0; j < kN; ++j) c.emplace_back(i * kSpacing, j * kSpacing, z);
  }
  return c;
}

double Mm(double m) { return m * 1e3; }

TEST(MetricsTest, IdenticalCloudsAreZeroAndPerfect) {
  const Cloud c = Grid(0.0f);
  const CloudMetrics m = Compare(c, c);
  EXPECT_EQ(m.chamfer_mm2, 0.0);
  EXPECT_EQ(m.pred_to_gt_mean_sq_mm2, 0.0);
  EXPECT_EQ(m.gt_to_pred_mean_sq_mm2, 0.0);
  EXPECT_EQ(m.fscore_1mm, 1.0);
  EXPECT_EQ(m.fscore_2mm, 1.0);
  EXPECT_EQ(m.p95_pred_to_gt_mm, 0.0);
  EXPECT_EQ(m.p95_gt_to_pred_mm, 0.0);
  EXPECT_EQ(m.max_pred_to_gt_mm, 0.0);
  EXPECT_EQ(m.num_pred, c.size());
  EXPECT_EQ(m.num_gt, c.size());
}

TEST(MetricsTest, GridShiftedAlongNormal) {
  // Each shifted point's nearest neighbour is its twin straight below (any
  // other is sqrt(shift^2 + spacing^2) away), so every distance is `shift`
  // both ways and Eq. 6 gives 2 * shift^2.
  const float shift = 0.0015f;
  const Cloud gt = Grid(0.0f);
  const Cloud pred = Grid(shift);
  const CloudMetrics m = Compare(pred, gt);

  const double shift_mm = Mm(static_cast<double>(shift));
  EXPECT_NEAR(m.pred_to_gt_mean_sq_mm2, shift_mm * shift_mm, 1e-9);
  EXPECT_NEAR(m.gt_to_pred_mean_sq_mm2, shift_mm * shift_mm, 1e-9);
  EXPECT_NEAR(m.chamfer_mm2, 2.0 * shift_mm * shift_mm, 1e-9);
  EXPECT_NEAR(m.chamfer_mm2, 2.0 * 1.5 * 1.5, 1e-6);  // the 4.5 mm^2 of 1.5 mm
  EXPECT_EQ(m.fscore_1mm, 0.0);                       // 1.5 mm > 1 mm: nothing within tau
  EXPECT_EQ(m.fscore_2mm, 1.0);                       // 1.5 mm <= 2 mm: everything within tau
  EXPECT_NEAR(m.p95_pred_to_gt_mm, 1.5, 1e-6);
  EXPECT_NEAR(m.p95_gt_to_pred_mm, 1.5, 1e-6);
  EXPECT_NEAR(m.max_pred_to_gt_mm, 1.5, 1e-6);
}

TEST(MetricsTest, HalfMissingGivesHalfRecallFullPrecision) {
  const Cloud gt = Grid(0.0f);
  const Cloud pred = Grid(0.0f, kN / 2);  // columns kN/2 .. kN-1 missing
  const double tau = 1e-3;

  const std::vector<double> p2g = mesh::NearestDistances(pred, gt);
  const std::vector<double> g2p = mesh::NearestDistances(gt, pred);
  const double precision = FractionWithin(p2g, tau);
  const double recall = FractionWithin(g2p, tau);
  EXPECT_EQ(precision, 1.0);
  EXPECT_EQ(recall, 0.5);

  const CloudMetrics m = Compare(pred, gt);
  const double f = 2.0 * precision * recall / (precision + recall);  // = 2/3
  EXPECT_NEAR(m.fscore_1mm, f, 1e-12);
  EXPECT_NEAR(m.fscore_1mm, 2.0 / 3.0, 1e-12);
  // The missing half is >= one 5 mm column from the kept one: not covered.
  EXPECT_EQ(m.coverage_2mm, 0.5);
  EXPECT_EQ(m.precision_2mm, 1.0);
  EXPECT_EQ(m.pred_to_gt_mean_sq_mm2, 0.0);
  // A gt point in missing column kN/2 - 1 + k is k columns from the nearest
  // kept column: distance k * spacing, kN points per column.
  double sum_sq_mm2 = 0.0;
  for (int k = 1; k <= kN / 2; ++k) {
    const double d_mm = Mm(k * static_cast<double>(kSpacing));
    sum_sq_mm2 += kN * d_mm * d_mm;
  }
  // Relative tolerance: the grid's float coordinates (i * spacing) carry
  // ~1e-7 relative rounding.
  const double expected_mm2 = sum_sq_mm2 / gt.size();
  EXPECT_NEAR(m.gt_to_pred_mean_sq_mm2, expected_mm2, 1e-6 * expected_mm2);
  EXPECT_NEAR(m.chamfer_mm2, m.gt_to_pred_mean_sq_mm2, 1e-12);
  EXPECT_EQ(m.num_pred, gt.size() / 2);
  // Sorted gt->pred distances: 200 zeros, then 20 of each k * 5 mm, k = 1..10.
  // Rank 0.95 * 399 = 379.05 falls between the last k = 9 (index 379) and the
  // first k = 10 (index 380): 45 mm + 0.05 * 5 mm.
  static_assert(kN == 20, "the p95 arithmetic below assumes a 20x20 grid");
  const double s_mm = Mm(static_cast<double>(kSpacing));
  EXPECT_NEAR(m.p95_gt_to_pred_mm, 9 * s_mm + 0.05 * s_mm, 1e-6);
}

TEST(MetricsTest, OutlierRaisesMaxOnly) {
  const Cloud gt = Grid(0.0f);
  Cloud pred = gt;
  const float height = 0.05f;  // 50 mm straight above grid point (0, 0)
  pred.emplace_back(0.0f, 0.0f, height);

  const CloudMetrics m = Compare(pred, gt);
  const double height_mm = Mm(static_cast<double>(height));
  EXPECT_NEAR(m.max_pred_to_gt_mm, height_mm, 1e-6);
  // One outlier among kN^2 + 1 points lies above the 95th percentile.
  EXPECT_EQ(m.p95_pred_to_gt_mm, 0.0);
  EXPECT_NEAR(m.pred_to_gt_mean_sq_mm2, height_mm * height_mm / pred.size(), 1e-9);
  EXPECT_EQ(m.gt_to_pred_mean_sq_mm2, 0.0);
  EXPECT_EQ(m.fscore_2mm, 2.0 * (1.0 - 1.0 / pred.size()) / (2.0 - 1.0 / pred.size()));
  EXPECT_EQ(m.coverage_2mm, 1.0);
  EXPECT_EQ(m.precision_2mm, 1.0 - 1.0 / pred.size());
}

TEST(MetricsTest, Deterministic) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  Cloud a(500), b(400);
  for (auto& p : a) p = {u(rng), u(rng), u(rng)};
  for (auto& p : b) p = {u(rng), u(rng), u(rng)};
  const CloudMetrics m1 = Compare(a, b);
  const CloudMetrics m2 = Compare(a, b);
  EXPECT_EQ(m1.chamfer_mm2, m2.chamfer_mm2);
  EXPECT_EQ(m1.p95_gt_to_pred_mm, m2.p95_gt_to_pred_mm);
  EXPECT_EQ(m1.fscore_1mm, m2.fscore_1mm);
}

// Expects `fn` to throw std::invalid_argument whose message has `needle`.
template <typename Fn>
void ExpectInvalid(Fn fn, const std::string& needle) {
  try {
    fn();
    ADD_FAILURE() << "no exception; expected one mentioning '" << needle << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << "message: " << e.what();
  }
}

TEST(MetricsTest, EmptyInputThrows) {
  const Cloud c = Grid(0.0f);
  ExpectInvalid([&] { Compare({}, c); }, "predicted cloud is empty");
  ExpectInvalid([&] { Compare(c, {}); }, "ground-truth cloud is empty");
}

TEST(MetricsTest, NonFiniteInputThrows) {
  const Cloud gt = Grid(0.0f);
  Cloud pred = gt;
  pred[7].y() = std::numeric_limits<float>::quiet_NaN();
  ExpectInvalid([&] { Compare(pred, gt); }, "predicted cloud has a non-finite");
  ExpectInvalid([&] { Compare(pred, gt); }, "point 7");
  Cloud bad_gt = gt;
  bad_gt[3].z() = std::numeric_limits<float>::infinity();
  ExpectInvalid([&] { Compare(gt, bad_gt); }, "ground-truth cloud has a non");
}

}  // namespace
}  // namespace graspfill::eval
