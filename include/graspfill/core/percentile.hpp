// SPDX-License-Identifier: BSD-3-Clause
// Percentiles of a sample, as the mesh deviation and the metrics report them.
#pragma once

#include <vector>

namespace graspfill {

/// Percentile `q` in [0, 100] of `values` by linear interpolation between
/// order statistics (numpy's default); same unit as `values`.
/// @throws std::invalid_argument if `values` is empty or `q` is outside
///         [0, 100].
double Percentile(std::vector<double> values, double q);

}  // namespace graspfill
