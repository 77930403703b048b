// SPDX-License-Identifier: BSD-3-Clause
#include "top_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "neighbor_index.hpp"

namespace graspfill::repair {
namespace {

// The seal looks this many sigma from the rim; a rim point with nothing
// nearer counts as this far (past "open" at any rate).
constexpr double kSealCapSigmas = 4.0;
// The share of a right completion's points the record sees free or in the
// claw (its noise).
constexpr double kFreeShareNoise = 0.02;

}  // namespace

std::string TopFamilyName(TopFamily family) {
  switch (family) {
    case TopFamily::kOpen:
      return "open";
    case TopFamily::kMirror:
      return "mirror";
    case TopFamily::kRevolution:
      return "revolution";
    case TopFamily::kDome:
      return "dome";
    case TopFamily::kExtrusion:
      return "extrusion";
  }
  return "open";
}

TopChoice ChooseTop(std::vector<TopCandidate> candidates, const PointList& rim_V, const PointList& fills_V,
                    double spacing_m) {
  TopChoice choice;
  const double sigma = std::max(spacing_m, 1e-6);
  const double n = static_cast<double>(std::max<size_t>(rim_V.size(), 1));
  const double cap = kSealCapSigmas * sigma;
  // Only what lies within the cap of the rim can answer for the seal; with
  // no rim nothing can, and "open" is the answer.
  std::optional<NeighborIndex> rim_index;
  PointList fills_near;
  if (rim_V.empty()) {
    candidates.clear();
  } else {
    rim_index.emplace(rim_V);
    for (const Eigen::Vector3f& p : fills_V) {
      if (rim_index->AnyWithin(p, cap)) fills_near.push_back(p);
    }
  }
  for (TopCandidate& c : candidates) {
    if (c.points_V.empty()) continue;  // adds nothing: "open" says it
    PointList added = fills_near;
    for (const Eigen::Vector3f& p : c.seam_V.empty() ? c.points_V : c.seam_V) {
      if (rim_index->AnyWithin(p, cap)) added.push_back(p);
    }
    std::vector<int> nearest;
    std::vector<double> squared;
    if (added.empty()) added.push_back(Eigen::Vector3f::Constant(std::numeric_limits<float>::max()));
    const NeighborIndex index(added);
    std::vector<double> seal;
    seal.reserve(rim_V.size());
    for (const Eigen::Vector3f& r : rim_V) {
      index.Knn(r, 1, &nearest, &squared);
      seal.push_back(squared.empty() ? cap : std::min(std::sqrt(squared[0]), cap));
    }
    std::nth_element(seal.begin(), seal.begin() + seal.size() / 2, seal.end());
    c.seal_m = seal[seal.size() / 2];
    c.cost = 0.5 * std::pow(c.seal_m / sigma, 2) + 0.5 * std::pow(c.free_share / kFreeShareNoise, 2) +
             c.parameters * std::log(n) / (2.0 * n);
    choice.candidates.push_back(std::move(c));
  }
  TopCandidate open;
  open.cost = 0.5 * kOpenSigmas * kOpenSigmas;
  open.seal_m = std::numeric_limits<double>::quiet_NaN();
  choice.candidates.push_back(std::move(open));
  double runner_up = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < choice.candidates.size(); ++i) {
    if (choice.candidates[i].cost < choice.candidates[choice.best].cost) choice.best = i;
  }
  for (size_t i = 0; i < choice.candidates.size(); ++i) {
    if (i != choice.best) runner_up = std::min(runner_up, choice.candidates[i].cost);
  }
  // Nothing weighed against "open" (nothing proposed): no margin, 0.5.
  const double margin = std::isfinite(runner_up) ? runner_up - choice.Best().cost : 0.0;
  choice.confidence = static_cast<float>(1.0 / (1.0 + std::exp(-margin)));
  return choice;
}

}  // namespace graspfill::repair
