// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/mesh/nearest_distances.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace graspfill::mesh {
namespace {

using Cloud = std::vector<Eigen::Vector3f>;

Cloud RandomCloud(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  Cloud c(n);
  for (auto& p : c) p = {u(rng), u(rng), u(rng)};
  return c;
}

TEST(NearestDistancesTest, MatchBruteForce) {
  const Cloud a = RandomCloud(300, 7);
  const Cloud b = RandomCloud(200, 8);
  const std::vector<double> d = NearestDistances(a, b);
  const std::vector<double> d2 = NearestSquaredDistances(a, b);
  ASSERT_EQ(d.size(), a.size());
  ASSERT_EQ(d2.size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& q : b) {
      best = std::min(best, (a[i].cast<double>() - q.cast<double>()).norm());
    }
    EXPECT_NEAR(d[i], best, 1e-12) << "point " << i;
    EXPECT_NEAR(d2[i], best * best, 1e-12) << "point " << i;
  }
}

TEST(NearestDistancesTest, EmptyOrNonFiniteCloudThrows) {
  const Cloud c = RandomCloud(10, 1);
  Cloud bad = c;
  bad[4].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(NearestDistances(c, {}), std::invalid_argument);
  EXPECT_THROW(NearestSquaredDistances({}, c), std::invalid_argument);
  EXPECT_THROW(NearestDistances(bad, c), std::invalid_argument);
  EXPECT_THROW(NearestSquaredDistances(c, bad), std::invalid_argument);
}

TEST(NearestDistancesTest, CheckCloudNamesTheCloudAndThePoint) {
  Cloud bad = RandomCloud(10, 1);
  bad[4].z() = std::numeric_limits<float>::infinity();
  try {
    CheckCloud(bad, "test");
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the test cloud has a non-finite coordinate"), std::string::npos) << what;
    EXPECT_NE(what.find("point 4"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(CheckCloud(RandomCloud(3, 2), "test"));
}

}  // namespace
}  // namespace graspfill::mesh
