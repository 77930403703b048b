// SPDX-License-Identifier: BSD-3-Clause
#include "boundary_classification.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace graspfill::repair {
namespace {

// How far past a claw side's end its points may still be interleaved with
// the rim's (positions along the line).
constexpr int kInterleave = 8;
// ... until this many rim points come in a row: beyond them a point below
// the level is the rim dipping, not the side (a prism's corner 13 mm from
// the side of a finger hole in its face, after 5 rim points: taken in, the
// hole's mouth spanned the face's whole edge and the hole was left open;
// from 3 on, an elliptic cylinder's claw sides lost interleaved points).
constexpr int kRimRun = 4;

// A z-monotone segment [start, end] of a line (positions in the line).
struct Leg {
  int start;
  int end;
  bool descending;
};

// A claw hole's piece of one line: positions [start, end]; low_start /
// low_end: it begins / ends at the line's end below the rim (half a hole).
struct Range {
  int start;
  int end;
  bool low_start;
  bool low_end;
  int descent_start{-1};  // where its first leg, a descent, starts
  int ascent_end{-1};     // where its last leg, an ascent, ends
};

struct Fragment {
  std::vector<int> indices;  // into points_V
  bool closed{false};
  bool low_start{false};
  bool low_end{false};
};

// Turning points of z along the line, with hysteresis `tol` (zig-zag
// indicator): a new extreme is confirmed once z has come back from it by
// more than tol.
std::vector<int> Pivots(const std::vector<double>& z, double tol) {
  const int n = static_cast<int>(z.size());
  std::vector<int> pivots = {0};
  int dir = 0, ext = 0, hi = 0, lo = 0;
  for (int i = 1; i < n; ++i) {
    if (dir == 0) {
      if (z[i] > z[hi]) hi = i;
      if (z[i] < z[lo]) lo = i;
      if (z[hi] - z[lo] > tol) {
        if (hi > lo) {
          if (lo != 0) pivots.push_back(lo);
          dir = 1, ext = hi;
        } else {
          if (hi != 0) pivots.push_back(hi);
          dir = -1, ext = lo;
        }
      }
    } else if (dir > 0) {
      if (z[i] >= z[ext]) {
        ext = i;
      } else if (z[ext] - z[i] > tol) {
        pivots.push_back(ext);
        dir = -1, ext = i;
      }
    } else {
      if (z[i] <= z[ext]) {
        ext = i;
      } else if (z[i] - z[ext] > tol) {
        pivots.push_back(ext);
        dir = 1, ext = i;
      }
    }
  }
  if (pivots.back() != n - 1) pivots.push_back(n - 1);
  return pivots;
}

// The line's height about position k: the median of k and its `reach`
// neighbours on either side (fewer at the line's ends; reach <= 7). A
// single point a few mm over the rim (a fused cloud's rim varies by 3-5
// mm) must not set the level a descent from it has to come back to: the
// whole line became one claw hole (the prism box at 60 frames, its top
// left open).
double LocalLevel(const std::vector<double>& z, int k, int reach = 2) {
  const int n = static_cast<int>(z.size());
  reach = std::min(reach, 7);
  double window[15];
  int count = 0;
  for (int i = std::max(0, k - reach); i <= std::min(n - 1, k + reach); ++i) {
    window[count++] = z[static_cast<size_t>(i)];
  }
  std::nth_element(window, window + count / 2, window + count);
  return window[count / 2];
}

// The claw sides of a line: monotone segments between pivots, trimmed to
// where they leave and reach their end levels (so a noisy rim before a
// descent is not part of it), kept when long, high and steep enough.
std::vector<Leg> SignificantLegs(const PointList& points_V, const std::vector<int>& line,
                                 const std::vector<double>& z, const ClassifyConfig& config) {
  const double tol = config.monotone_tolerance_m;
  const std::vector<int> pivots = Pivots(z, tol);
  // The segment from pivot a to pivot b, trimmed to where it leaves the
  // level za and reaches zb: a side when long, high and steep enough.
  const auto side = [&](int a, int b, double za, double zb) -> std::optional<Leg> {
    const bool descending = z[b] < z[a];
    // Last point still at the start level, first point at the end level.
    for (int i = b; i >= a; --i) {
      if (descending ? z[i] >= za - tol : z[i] <= za + tol) {
        a = i;
        break;
      }
    }
    for (int i = a; i <= b; ++i) {
      if (descending ? z[i] <= zb + tol : z[i] >= zb - tol) {
        b = i;
        break;
      }
    }
    const double drop = std::abs(z[b] - z[a]);
    const double chord = (points_V[static_cast<size_t>(line[static_cast<size_t>(b)])] -
                          points_V[static_cast<size_t>(line[static_cast<size_t>(a)])])
                             .norm();
    if (b - a + 1 >= config.min_segment_points && drop >= config.min_segment_height_m &&
        drop >= config.min_segment_slope * chord) {
      return Leg{a, b, descending};
    }
    return std::nullopt;
  };
  // A pivot that stands more than tol off a level of the line about it (7
  // positions either way, most of them within tol of their median) may be
  // a few points 3-5 mm over the rim, far along it from a side: the side,
  // stretched along the rim to them, is no side at their height (a flat
  // can's side can run 100 degrees from a finger pad that way), and is
  // tried again at that level. Not first: a round rim's pivot that stands
  // 2-3 mm over its neighbours is its side's end.
  constexpr int kReach = 7;
  const auto level = [&z, tol](int k) {
    const double around = LocalLevel(z, k, kReach);
    const int n = static_cast<int>(z.size());
    int count = 0, flat = 0;
    for (int i = std::max(0, k - kReach); i <= std::min(n - 1, k + kReach); ++i, ++count) {
      flat += std::abs(z[static_cast<size_t>(i)] - around) <= tol;
    }
    const double own = z[static_cast<size_t>(k)];
    return 2 * flat > count && std::abs(own - around) > tol ? around : own;
  };
  std::vector<Leg> legs;
  for (size_t k = 0; k + 1 < pivots.size(); ++k) {
    const int a = pivots[k], b = pivots[k + 1];
    std::optional<Leg> leg = side(a, b, z[a], z[b]);
    if (!leg) leg = side(a, b, level(a), level(b));
    if (leg) legs.push_back(*leg);
  }
  return legs;
}

// The claw holes of a line that reaches the top, as position ranges: from
// a descent's start to the end of the next ascent (further descents or
// ascents in between, e.g. a step in a hole's bottom, belong to it),
// unless the line is back at the level it left within fewer than
// `min_side_points` positions of the descent's end (a dip of the rim). A
// descent never followed by an ascent ends where the line is back at the
// level it left (or at the line's end); an ascent with no descent before it
// begins where the line was last at the level it reaches (or at the start).
// Two holes whose line climbs from one's side to the other's within
// 2 x min_side_points positions, peaking at `bridge_level` or higher (the
// rim's band), are two, split on that peak.
std::vector<Range> ClawRanges(const std::vector<Leg>& legs, const std::vector<double>& z, double tol,
                              int min_side_points, double bridge_level) {
  const int n = static_cast<int>(z.size());
  std::vector<Range> ranges;
  size_t i = 0;
  while (i < legs.size()) {
    Range r{0, n - 1, false, false};
    if (legs[i].descending) {
      r.start = r.descent_start = legs[i].start;
      const double level = LocalLevel(z, r.start) - tol;
      // The first position in [from, to) where the line is back at the
      // level the descent left, or -1.
      const auto back_at_level = [&z, level](int from, int to) {
        for (int k = from; k < to; ++k) {
          if (z[static_cast<size_t>(k)] >= level) return k;
        }
        return -1;
      };
      // The legs that follow belong to the hole (a step in its bottom, its
      // other side), unless the line first climbs back to that level in
      // fewer points than a side has: a dip of the rim (a box's rim can
      // dip 6 mm at a corner and be back in 2 points; taken for the hole,
      // it reached along the face's whole top edge to the next finger's).
      size_t j = i + 1;
      r.end = -1;
      while (j < legs.size() && r.end < 0) {
        const int from = legs[j - 1].end;
        r.end = back_at_level(from, std::min(legs[j].start, from + min_side_points));
        if (r.end >= 0 || !legs[j].descending) break;
        ++j;
      }
      if (r.end < 0 && j < legs.size()) {
        while (j < legs.size() && !legs[j].descending) r.end = r.ascent_end = legs[j++].end;
      } else if (r.end < 0) {
        r.end = back_at_level(legs[j - 1].end, n);
        if (r.end < 0) r.end = n - 1, r.low_end = true;
      }
      i = j;
    } else {
      size_t j = i;
      while (j < legs.size() && !legs[j].descending) r.end = r.ascent_end = legs[j++].end;
      const double level = LocalLevel(z, r.end);
      r.start = -1;
      for (int k = legs[i].start; k >= 0 && r.start < 0; --k) {
        if (z[static_cast<size_t>(k)] >= level - tol) r.start = k;
      }
      if (r.start < 0) r.start = 0, r.low_start = true;
      i = j;
    }
    // A side can end in a short, shallow leg (a zig-zag near the rim
    // splits it): stretch the range to where the line is back at the
    // level of its other end.
    const int floor = ranges.empty() ? 0 : ranges.back().end + 1;
    const int ceiling = i < legs.size() ? legs[i].start : n - 1;
    // Side points below that level a few places further on (a zig-zag
    // interleaves them with the rim's first points) belong to the hole too.
    // The rim's local height: the highest of its local medians just
    // outside the range.
    auto highest = [&z](int from, int to) {
      double h = -std::numeric_limits<double>::infinity();
      for (int k = from; k <= to; ++k) h = std::max(h, LocalLevel(z, k));
      return h;
    };
    if (!r.low_end) {
      const double level = highest(std::max(floor, r.start - kInterleave), r.start) - tol;
      while (r.end < ceiling && z[static_cast<size_t>(r.end)] < level) ++r.end;
      const int last = std::min(ceiling, r.end + kInterleave);  // fixed: no creeping
      int rim_run = 0;
      for (int k = r.end + 1; k <= last && rim_run < kRimRun; ++k) {
        if (z[static_cast<size_t>(k)] < level)
          r.end = k, rim_run = 0;
        else
          ++rim_run;
      }
    }
    if (!r.low_start) {
      const double level = highest(r.end, std::min(n - 1, r.end + kInterleave)) - tol;
      while (r.start > floor && z[static_cast<size_t>(r.start)] < level) --r.start;
      const int first = std::max(floor, r.start - kInterleave);
      int rim_run = 0;
      for (int k = r.start - 1; k >= first && rim_run < kRimRun; --k) {
        if (z[static_cast<size_t>(k)] < level)
          r.start = k, rim_run = 0;
        else
          ++rim_run;
      }
    }
    // Ranges come in order; one reaching back into the previous merges,
    // unless the line goes from one's side up to the other's within a few
    // points and peaks in the rim's band between them: a tooth of surface
    // between two fingers' holes that reach to 3 mm under a cut top (taken
    // as one hole, its mouth was closed the long way round the rim and
    // half of one hole left open: the protocol's ellipsoid at the 2% top
    // cut; 5-10 points between the sides). A ridge in one hole's bottom
    // peaks lower; a long run by the rim between two sides stays as it
    // was (the tea box in the parallel claw's oblique grasp: 34-38 points;
    // split, its coverage fell by up to 0.02).
    bool bridge = false;
    if (!ranges.empty() && r.start <= ranges.back().end + 1 && ranges.back().ascent_end >= 0 &&
        r.descent_start >= ranges.back().ascent_end &&
        r.descent_start - ranges.back().ascent_end <= 2 * min_side_points) {
      int peak = ranges.back().ascent_end;
      for (int k = peak; k <= r.descent_start; ++k) {
        if (z[static_cast<size_t>(k)] > z[static_cast<size_t>(peak)]) peak = k;
      }
      if (z[static_cast<size_t>(peak)] >= bridge_level) {
        ranges.back().end = peak;
        r.start = peak + 1;
        bridge = true;
      }
    }
    if (!ranges.empty() && !bridge && r.start <= ranges.back().end + 1) {
      ranges.back().end = std::max(ranges.back().end, r.end);
      ranges.back().low_end = r.low_end;
      ranges.back().ascent_end = r.ascent_end;
    } else {
      ranges.push_back(r);
    }
  }
  return ranges;
}

double WrapAngle(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a <= -M_PI) a += 2 * M_PI;
  return a;
}

// Centre for angles around V's z-axis: the origin (the cloud's axis), or
// the points' centroid when they do not surround the origin.
Eigen::Vector2d AngleCentre(const PointList& points_V, const std::vector<int>& indices) {
  if (indices.empty()) return Eigen::Vector2d::Zero();
  std::vector<double> angles;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int i : indices) {
    const Eigen::Vector3f& p = points_V[static_cast<size_t>(i)];
    angles.push_back(std::atan2(p.y(), p.x()));
    centroid += Eigen::Vector2d(p.x(), p.y());
  }
  std::sort(angles.begin(), angles.end());
  double max_gap = angles.front() + 2 * M_PI - angles.back();
  for (size_t k = 1; k < angles.size(); ++k) max_gap = std::max(max_gap, angles[k] - angles[k - 1]);
  return max_gap > M_PI ? Eigen::Vector2d(centroid / static_cast<double>(indices.size()))
                        : Eigen::Vector2d::Zero();
}

double AngleOf(const Eigen::Vector3f& p, const Eigen::Vector2d& centre) {
  return std::atan2(p.y() - centre.y(), p.x() - centre.x());
}

HoleBoundary MakeBoundary(HoleKind kind, const PointList& points_V, const std::vector<int>& indices,
                          bool closed) {
  HoleBoundary b;
  b.kind = kind;
  b.closed = closed;
  b.source_indices = indices;
  for (int i : indices) b.points_V.push_back(points_V[static_cast<size_t>(i)]);
  return b;
}

}  // namespace

void ClassifyConfig::Validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument("ClassifyConfig: " + what); };
  auto positive = [&](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0.0) fail(std::string(name) + " must be finite and > 0");
  };
  if (min_line_points < 2) fail("min_line_points must be >= 2");
  positive(top_band_m, "top_band_m");
  positive(monotone_tolerance_m, "monotone_tolerance_m");
  if (min_segment_points < 2) fail("min_segment_points must be >= 2");
  positive(min_segment_height_m, "min_segment_height_m");
  if (!std::isfinite(min_segment_slope) || min_segment_slope < 0.0) {
    fail("min_segment_slope must be finite and >= 0");
  }
  if (!std::isfinite(merge_distance_m) || merge_distance_m < 0.0) {
    fail("merge_distance_m must be finite and >= 0");
  }
  if (min_claw_points < 1) fail("min_claw_points must be >= 1");
}

std::vector<HoleBoundary> ClassifyBoundaries(const PointList& points_V,
                                             const std::vector<BoundaryLine>& lines,
                                             const ClassifyConfig& config) {
  config.Validate();
  // The lines' finite points; short lines are noise.
  std::vector<BoundaryLine> valid;
  for (size_t l = 0; l < lines.size(); ++l) {
    BoundaryLine line;
    line.closed = lines[l].closed;
    for (int i : lines[l].indices) {
      if (i < 0 || static_cast<size_t>(i) >= points_V.size()) {
        throw std::invalid_argument("ClassifyBoundaries: line " + std::to_string(l) + " has index " +
                                    std::to_string(i) + ", the cloud has " + std::to_string(points_V.size()) +
                                    " points");
      }
      if (points_V[static_cast<size_t>(i)].allFinite()) line.indices.push_back(i);
    }
    if (static_cast<int>(line.indices.size()) >= config.min_line_points) valid.push_back(std::move(line));
  }
  if (valid.empty()) return {};
  double z_top = -std::numeric_limits<double>::infinity();
  for (const BoundaryLine& line : valid) {
    for (int i : line.indices) z_top = std::max<double>(z_top, points_V[static_cast<size_t>(i)].z());
  }

  std::vector<std::vector<int>> rim_pieces;
  std::vector<Fragment> claws;
  bool rim_closed = false;
  for (const BoundaryLine& line : valid) {
    std::vector<int> seq = line.indices;
    double z_max = -std::numeric_limits<double>::infinity(), z_min = -z_max;
    size_t highest = 0;
    for (size_t k = 0; k < seq.size(); ++k) {
      const double z = points_V[static_cast<size_t>(seq[k])].z();
      if (z > z_max) z_max = z, highest = k;
      z_min = std::min(z_min, z);
    }
    if (z_max < z_top - config.top_band_m) {
      // Below the top: a hole by itself (middle grasp) or noise.
      if (z_max - z_min >= config.min_segment_height_m &&
          static_cast<int>(seq.size()) >= config.min_claw_points) {
        claws.push_back({seq, line.closed, false, false});
      }
      continue;
    }
    // Walk a closed line from its highest point, on the missing surface's
    // rim, so that no claw hole wraps around the walk's start.
    if (line.closed) std::rotate(seq.begin(), seq.begin() + static_cast<long>(highest), seq.end());
    std::vector<double> z(seq.size());
    for (size_t k = 0; k < seq.size(); ++k) z[k] = points_V[static_cast<size_t>(seq[k])].z();
    const std::vector<Leg> legs = SignificantLegs(points_V, seq, z, config);
    const std::vector<Range> ranges = ClawRanges(legs, z, config.monotone_tolerance_m,
                                                 config.min_segment_points, z_top - config.top_band_m);

    int next = 0;  // first position not yet assigned
    std::vector<std::vector<int>> pieces;
    for (const Range& r : ranges) {
      if (r.start > next) pieces.emplace_back(seq.begin() + next, seq.begin() + r.start);
      claws.push_back(
          {std::vector<int>(seq.begin() + r.start, seq.begin() + r.end + 1), false, r.low_start, r.low_end});
      next = r.end + 1;
    }
    if (next < static_cast<int>(seq.size())) pieces.emplace_back(seq.begin() + next, seq.end());
    // A closed line's last and first pieces meet across its start.
    if (line.closed && pieces.size() >= 2 && !ranges.empty() && ranges.front().start > 0 &&
        ranges.back().end < static_cast<int>(seq.size()) - 1) {
      pieces.back().insert(pieces.back().end(), pieces.front().begin(), pieces.front().end());
      pieces.erase(pieces.begin());
    }
    if (ranges.empty() && line.closed) rim_closed = true;
    for (std::vector<int>& piece : pieces) rim_pieces.push_back(std::move(piece));
  }

  // Halves of one claw hole on two lines (broken at its bottom) join.
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t a = 0; a < claws.size() && !merged; ++a) {
      if (!claws[a].low_end) continue;
      const Eigen::Vector3f& end = points_V[static_cast<size_t>(claws[a].indices.back())];
      size_t best = claws.size();
      double best_d = config.merge_distance_m;
      for (size_t b = 0; b < claws.size(); ++b) {
        if (b == a || !claws[b].low_start) continue;
        const double d = (points_V[static_cast<size_t>(claws[b].indices.front())] - end).norm();
        if (d <= best_d) best_d = d, best = b;
      }
      if (best == claws.size()) continue;
      claws[a].indices.insert(claws[a].indices.end(), claws[best].indices.begin(), claws[best].indices.end());
      claws[a].low_end = claws[best].low_end;
      claws.erase(claws.begin() + static_cast<long>(best));
      merged = true;
    }
  }

  std::vector<HoleBoundary> out;
  // The missing surface: pieces counter-clockwise, ordered by angle.
  std::vector<int> all_rim;
  for (const std::vector<int>& piece : rim_pieces) all_rim.insert(all_rim.end(), piece.begin(), piece.end());
  if (!all_rim.empty()) {
    const Eigen::Vector2d centre = AngleCentre(points_V, all_rim);
    std::vector<std::pair<double, size_t>> order;
    for (size_t k = 0; k < rim_pieces.size(); ++k) {
      std::vector<int>& piece = rim_pieces[k];
      double turn = 0.0;
      for (size_t i = 1; i < piece.size(); ++i) {
        turn += WrapAngle(AngleOf(points_V[static_cast<size_t>(piece[i])], centre) -
                          AngleOf(points_V[static_cast<size_t>(piece[i - 1])], centre));
      }
      if (turn < 0) std::reverse(piece.begin(), piece.end());
      order.push_back({AngleOf(points_V[static_cast<size_t>(piece.front())], centre), k});
    }
    std::sort(order.begin(), order.end());
    std::vector<int> merged;
    for (const auto& entry : order) {
      const std::vector<int>& piece = rim_pieces[entry.second];
      merged.insert(merged.end(), piece.begin(), piece.end());
    }
    out.push_back(
        MakeBoundary(HoleKind::kMissingSurface, points_V, merged, rim_closed && rim_pieces.size() == 1));
  }
  // The claw holes, by the angle of their centroid.
  std::vector<std::pair<double, size_t>> claw_order;
  for (size_t k = 0; k < claws.size(); ++k) {
    if (static_cast<int>(claws[k].indices.size()) < config.min_claw_points) continue;
    Eigen::Vector3f c = Eigen::Vector3f::Zero();
    for (int i : claws[k].indices) c += points_V[static_cast<size_t>(i)];
    claw_order.push_back({std::atan2(c.y(), c.x()), k});
  }
  std::sort(claw_order.begin(), claw_order.end());
  for (const auto& entry : claw_order) {
    const Fragment& f = claws[entry.second];
    out.push_back(MakeBoundary(HoleKind::kClaw, points_V, f.indices, f.closed));
  }
  return out;
}

}  // namespace graspfill::repair
