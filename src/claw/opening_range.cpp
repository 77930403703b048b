// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/opening_range.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace graspfill::claw {

OpeningRange FindOpeningRange(const ClawModel& model) {
  const std::vector<Link>& links = model.links();
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  std::vector<bool> moves(links.size(), false);
  for (size_t i = 0; i < links.size(); ++i) {
    const Joint& j = links[i].joint;
    const bool driven = j.type != JointType::kFixed && j.gain != 0.0 && std::isfinite(j.lower) &&
                        std::isfinite(j.upper) && j.lower < j.upper;
    if (driven) {
      const double a = (j.lower - j.offset) / j.gain;
      const double b = (j.upper - j.offset) / j.gain;
      lo = std::min(lo, std::min(a, b));
      hi = std::max(hi, std::max(a, b));
    }
    moves[i] = driven || (links[i].parent >= 0 && moves[links[i].parent]);
  }
  if (!(lo < hi)) {
    throw std::invalid_argument("claw '" + model.name() + "': no joint follows the opening");
  }
  const auto mean_radius = [&](double opening) {
    const std::vector<Eigen::Isometry3d> poses = model.LinkPoses(opening);
    double sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < links.size(); ++i) {
      if (!moves[i]) continue;
      const Eigen::Isometry3d T = poses[i] * links[i].T_link_mesh;
      for (const Eigen::Vector3f& v : links[i].mesh.vertices) {
        sum += (T * v.cast<double>()).head<2>().norm();
        ++n;
      }
    }
    return n == 0 ? 0.0 : sum / static_cast<double>(n);
  };
  return mean_radius(hi) >= mean_radius(lo) ? OpeningRange{hi, lo} : OpeningRange{lo, hi};
}

}  // namespace graspfill::claw
