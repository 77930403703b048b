// SPDX-License-Identifier: BSD-3-Clause
// The top's scored search (src/repair/top_search.hpp): a completion that
// meets the rim wins over "open" with a high confidence; one that stops
// short of the rim (the mirror of a cup's narrower bottom at its wider
// mouth), or that the camera saw through, loses to "open"; the claw fills
// count at the seal; of two that meet it, the closer, and of equals, the
// simpler.
#include "top_search.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace graspfill::repair {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSpacing = 0.001;

// A ring of radius r at height z, `spacing` apart.
PointList Ring(double r, double z) {
  PointList out;
  const int n = static_cast<int>(std::ceil(2.0 * kPi * r / kSpacing));
  for (int k = 0; k < n; ++k) {
    const double t = 2.0 * kPi * k / n;
    out.emplace_back(static_cast<float>(r * std::cos(t)), static_cast<float>(r * std::sin(t)),
                     static_cast<float>(z));
  }
  return out;
}

// A flat disc of radius r at height z (rings a spacing apart).
PointList Disc(double r, double z) {
  PointList out;
  for (double rr = r; rr > 0.0; rr -= kSpacing) {
    const PointList ring = Ring(rr, z);
    out.insert(out.end(), ring.begin(), ring.end());
  }
  return out;
}

TopCandidate Candidate(TopFamily family, PointList points, int parameters, double free_share = 0.0) {
  TopCandidate c;
  c.family = family;
  c.points_V = std::move(points);
  c.parameters = parameters;
  c.free_share = free_share;
  return c;
}

const PointList kRim = Ring(0.03, 0.0);  // the mouth's rim: 30 mm at z = 0

TEST(TopSearch, ACompletionThatMeetsTheRimWinsConfidently) {
  const TopChoice choice =
      ChooseTop({Candidate(TopFamily::kMirror, Disc(0.03, 0.001), 1)}, kRim, {}, kSpacing);
  EXPECT_EQ(choice.Best().family, TopFamily::kMirror);
  EXPECT_LT(choice.Best().seal_m, 1.5 * kSpacing);
  EXPECT_GT(choice.confidence, 0.95f);
  ASSERT_EQ(choice.candidates.size(), 2u);
  EXPECT_EQ(choice.candidates.back().family, TopFamily::kOpen);
}

TEST(TopSearch, OpenWinsOverAnImageThatStopsShortOfTheRim) {
  // The mirror of a bottom 24 mm wide under a 30 mm mouth: 6 spacings short.
  const TopChoice choice =
      ChooseTop({Candidate(TopFamily::kMirror, Disc(0.024, 0.001), 1)}, kRim, {}, kSpacing);
  EXPECT_EQ(choice.Best().family, TopFamily::kOpen);
  EXPECT_GT(choice.candidates.front().seal_m, 3.0 * kSpacing);
  EXPECT_GT(choice.confidence, 0.5f);
}

TEST(TopSearch, OpenWinsOverACapTheCameraSawThrough) {
  const TopChoice choice =
      ChooseTop({Candidate(TopFamily::kDome, Disc(0.03, 0.001), 6, /*free_share=*/0.08)}, kRim, {}, kSpacing);
  EXPECT_EQ(choice.Best().family, TopFamily::kOpen);
}

TEST(TopSearch, ClawFillsCloseTheRimWhereTheCompletionDoesNot) {
  // The image meets a third of the rim; the claw fills the rest. Alone it
  // leaves most of the rim unmet, and loses to "open".
  PointList image, fill;
  for (const Eigen::Vector3f& p : Disc(0.03, 0.001)) (p.x() < 0.015f ? fill : image).push_back(p);
  const TopChoice without = ChooseTop({Candidate(TopFamily::kMirror, image, 1)}, kRim, {}, kSpacing);
  const TopChoice with = ChooseTop({Candidate(TopFamily::kMirror, image, 1)}, kRim, fill, kSpacing);
  EXPECT_EQ(without.Best().family, TopFamily::kOpen);
  EXPECT_LT(with.Best().cost, without.candidates.front().cost);
  EXPECT_EQ(with.Best().family, TopFamily::kMirror);
}

TEST(TopSearch, TheCloserCompletionWinsAndOfEqualsTheSimpler) {
  const TopChoice closer = ChooseTop({Candidate(TopFamily::kMirror, Disc(0.0285, 0.001), 1),
                                      Candidate(TopFamily::kRevolution, Disc(0.03, 0.001), 5)},
                                     kRim, {}, kSpacing);
  EXPECT_EQ(closer.Best().family, TopFamily::kRevolution);
  const TopChoice simpler = ChooseTop({Candidate(TopFamily::kRevolution, Disc(0.03, 0.001), 5),
                                       Candidate(TopFamily::kMirror, Disc(0.03, 0.001), 1)},
                                      kRim, {}, kSpacing);
  EXPECT_EQ(simpler.Best().family, TopFamily::kMirror);
  EXPECT_LT(simpler.confidence, 0.6f);  // two near-equal explanations
}

TEST(TopSearch, NothingProposedOrNoRimLeavesItOpen) {
  const TopChoice alone = ChooseTop({}, kRim, {}, kSpacing);
  EXPECT_EQ(alone.Best().family, TopFamily::kOpen);
  EXPECT_EQ(alone.confidence, 0.5f);  // nothing weighed against it
  EXPECT_EQ(ChooseTop({Candidate(TopFamily::kMirror, Disc(0.03, 0.001), 1)}, {}, {}, kSpacing).Best().family,
            TopFamily::kOpen);
  // No rim, with claw fills beside it: still "open" (the fills are not
  // looked up against a rim that is not there).
  EXPECT_EQ(ChooseTop({Candidate(TopFamily::kMirror, Disc(0.03, 0.001), 1)}, {}, Disc(0.01, 0.0), kSpacing)
                .Best()
                .family,
            TopFamily::kOpen);
  EXPECT_EQ(ChooseTop({Candidate(TopFamily::kMirror, {}, 1)}, kRim, {}, kSpacing).Best().family,
            TopFamily::kOpen);
}

}  // namespace
}  // namespace graspfill::repair
