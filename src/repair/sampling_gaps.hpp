// SPDX-License-Identifier: BSD-3-Clause
// The two spacings every proposed surface (a claw hole's fill, the mirror
// image) is sampled by, in units of the cloud's spacing D. Internal to the
// repair library.
#pragma once

namespace graspfill::repair {

/// A proposed point is new only where no cloud point (nor an earlier fill)
/// lies within this many D: the original is kept where the two overlap,
/// and a fill stays inside its hole.
inline constexpr double kNewPointGapSpacings = 1.0;

/// A hole's box, and the missing surface's, is padded by this many D on
/// every side: the boundary of a hole on a flat face spans no depth.
inline constexpr double kHoleBoxPadSpacings = 2.0;

}  // namespace graspfill::repair
