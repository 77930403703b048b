// SPDX-License-Identifier: BSD-3-Clause
#include "boundary_linking.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "boundary_detection.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

void LinkConfig::Validate() const {
  if (candidates < 1) {
    throw std::invalid_argument("LinkConfig: candidates must be >= 1, got " + std::to_string(candidates));
  }
  if (min_points < 3) {
    throw std::invalid_argument("LinkConfig: min_points must be >= 3, got " + std::to_string(min_points));
  }
  if (!(absorb_factor > 0.0 && absorb_factor < max_link_factor && std::isfinite(max_link_factor))) {
    throw std::invalid_argument("LinkConfig: need 0 < absorb_factor < max_link_factor, got " +
                                std::to_string(absorb_factor) + " and " + std::to_string(max_link_factor));
  }
  if (!(max_deflection_rad > 0.0 && max_deflection_rad <= M_PI)) {
    throw std::invalid_argument("LinkConfig: max_deflection_rad must be in (0, pi], got " +
                                std::to_string(max_deflection_rad));
  }
}

namespace {

// Boundary points considered around each one for its local spacing.
constexpr int kSpacingNeighbors = 8;
// Along a line, the k-th nearest point is ~k/2 spacings away (one side or
// the other); k = 4 smooths the irregular gaps of a random sample's rim.
constexpr int kSpacingRank = 4;

// Local point spacing at every boundary point: the detector's (`given`, one
// per point) or, without it, half the distance to the kSpacingRank-th
// nearest boundary point; median-filtered over the kSpacingNeighbors
// nearest boundary points. Zero only where all of those are zero.
std::vector<float> LocalSpacing(const NeighborIndex& tree, const std::vector<float>& given) {
  const PointList& bp = tree.points();
  const size_t m = bp.size();
  std::vector<int> nn;
  std::vector<double> d2;
  std::vector<float> raw = given;
  if (raw.empty()) {
    raw.resize(m);
    for (size_t b = 0; b < m; ++b) {
      tree.Knn(bp[b], kSpacingRank + 1, &nn, &d2);
      raw[b] = 0.5f * static_cast<float>(std::sqrt(d2.back()));
    }
  }
  std::vector<float> spacing(m, 0.0f);
  std::vector<float> window;
  window.reserve(kSpacingNeighbors);
  for (size_t b = 0; b < m; ++b) {
    tree.Knn(bp[b], kSpacingNeighbors, &nn, &d2);
    window.clear();
    for (const int j : nn) window.push_back(raw[static_cast<size_t>(j)]);
    auto mid = window.begin() + static_cast<std::ptrdiff_t>(window.size() / 2);
    std::nth_element(window.begin(), mid, window.end());
    spacing[b] = *mid;
  }
  return spacing;
}

// Cosine of the deflection angle (Eq. 3) between the direction `dir` the
// chain arrives with and the link from `from` to `to`; 1 (straight on) for
// a zero-length link.
float DeflectionCos(const Eigen::Vector3f& dir, const Eigen::Vector3f& from, const Eigen::Vector3f& to) {
  const Eigen::Vector3f next = to - from;
  const float norms = dir.norm() * next.norm();
  return norms > 0.0f ? dir.dot(next) / norms : 1.0f;
}

// Links of the chain the arrival direction spans (P1 of Eq. 3 is this many
// points back, or the chain's first): the last link alone zig-zags across
// the flagged band and would make the true continuation look like a turn.
constexpr size_t kDirectionLag = 3;
// Only candidates at most this much farther than the nearest acceptable one
// compete on theta: the chain follows the nearest points and Eq. 3 picks
// among them, rather than leaping to the straightest far point.
constexpr float kNearRatio = 2.0f;
// A dead end is bridged by looking this much farther than the reach,
// straight on only (within half the deflection limit): a random sample
// leaves gaps of 3-5 spacings in a flagged rim here and there.
constexpr float kBridgeFactor = 2.0f;
// Cosine of the largest angle between a candidate's gap direction and the
// chain's: 0 lets the hole's side swing by up to 90 degrees (a rim's
// corner) and rejects the other hole's points across a neck (~180).
constexpr float kSideCos = 0.0f;
// A loop closing onto its own middle rather than its first point must be at
// least this many reaches long: a tail joining a rim is such a loop, a
// squiggle through the band at a corner is not.
constexpr float kSideLoopReaches = 4.0f;
// Least area a loop must enclose [squared spacings]: a ring of 10 points
// around a hole has ~8; a chain folded back along its own band, ~0.
constexpr float kMinLoopArea = 4.0f;
// Failed chains may give back, in all, this many times the number of
// boundary points: enough to undo wandering, and linear in the worst case.
constexpr long kReleaseBudget = 20;

// The chaining state over the boundary points (indices into `bp`).
class Linker {
 public:
  Linker(const NeighborIndex& tree, std::vector<float> spacing, std::vector<Eigen::Vector3f> gap_dirs,
         const LinkConfig& config)
      : bp_(tree.points()),
        gap_dirs_(std::move(gap_dirs)),
        tree_(tree),
        spacing_(std::move(spacing)),
        config_(config),
        cos_max_(static_cast<float>(std::cos(config.max_deflection_rad))),
        cos_bridge_(static_cast<float>(std::cos(0.5 * config.max_deflection_rad))),
        consumed_(bp_.size(), 0),
        tried_(bp_.size(), 0),
        release_budget_(kReleaseBudget * static_cast<long>(bp_.size())),
        chain_pos_(bp_.size(), -1) {}

  // True when the loop encloses some area: |vector area| at least
  // kMinLoopArea squared spacings. A chain that folds back along its own
  // band and meets itself encloses next to nothing.
  bool EnclosesHole(const std::vector<int>& loop) const {
    const Eigen::Vector3f origin = bp_[static_cast<size_t>(loop.front())];
    Eigen::Vector3f twice_area = Eigen::Vector3f::Zero();
    for (size_t k = 0; k < loop.size(); ++k) {
      const Eigen::Vector3f a = bp_[static_cast<size_t>(loop[k])] - origin;
      const Eigen::Vector3f b = bp_[static_cast<size_t>(loop[(k + 1) % loop.size()])] - origin;
      twice_area += a.cross(b);
    }
    const float s = spacing_[static_cast<size_t>(loop.front())];
    return 0.5f * twice_area.norm() >= kMinLoopArea * s * s;
  }

  // A point no chain holds and no chain started from yet.
  bool CanStart(size_t b) const { return !consumed_[b] && !tried_[b]; }

  // Grows a chain from the free point `start`, forwards and then, if it has
  // not closed, backwards from `start`. Returns the closed loop (points in
  // linking order) or nothing.
  std::vector<int> ChainFrom(int start) {
    chain_.clear();
    arc_.clear();
    touched_.clear();
    tried_[static_cast<size_t>(start)] = 1;
    Push(start);
    int loop_from = Grow();
    if (loop_from < 0 && chain_.size() > 1) {
      std::reverse(chain_.begin(), chain_.end());
      Reindex();
      loop_from = Grow();
    }
    std::vector<int> loop;
    if (loop_from >= 0) loop.assign(chain_.begin() + loop_from, chain_.end());
    if (!loop.empty() && !EnclosesHole(loop)) loop.clear();
    for (const int b : chain_) chain_pos_[static_cast<size_t>(b)] = -1;
    if (loop.size() < static_cast<size_t>(config_.min_points) && release_budget_ > 0) {
      // A failed chain gives its points back: it may have wandered over
      // the rim of a hole whose own chain needs them (its start is not
      // tried again). Bounded, so that a cloud of open edges stays linear.
      release_budget_ -= static_cast<long>(touched_.size());
      for (const int b : touched_) consumed_[static_cast<size_t>(b)] = 0;
    }
    return loop;
  }

 private:
  void Consume(size_t b) {
    if (!consumed_[b]) touched_.push_back(static_cast<int>(b));
    consumed_[b] = 1;
  }

  void Push(int b) {
    Consume(static_cast<size_t>(b));
    chain_pos_[static_cast<size_t>(b)] = static_cast<int>(chain_.size());
    arc_.push_back(chain_.empty() ? 0.0f : arc_.back() + Distance(chain_.back(), b));
    chain_.push_back(b);
  }

  void Pop() {
    chain_pos_[static_cast<size_t>(chain_.back())] = -1;
    chain_.pop_back();
    arc_.pop_back();
  }

  // Re-indexes the chain after it was reversed.
  void Reindex() {
    arc_.resize(chain_.size());
    for (size_t c = 0; c < chain_.size(); ++c) {
      chain_pos_[static_cast<size_t>(chain_[c])] = static_cast<int>(c);
      arc_[c] = c == 0 ? 0.0f : arc_[c - 1] + Distance(chain_[c - 1], chain_[c]);
    }
  }

  float Distance(int a, int b) const {
    return (bp_[static_cast<size_t>(a)] - bp_[static_cast<size_t>(b)]).norm();
  }

  enum class Step { kClosed, kExtended, kDeadEnd };

  // One link from the chain's last point: closes the loop (*loop_from gets
  // the chain position it closes onto), extends the chain, or dead-ends.
  Step Extend(int* loop_from) {
    const int cur = chain_.back();
    const Eigen::Vector3f& p2 = bp_[static_cast<size_t>(cur)];
    const float local = spacing_[static_cast<size_t>(cur)];
    const size_t n = chain_.size();
    tree_.Radius(p2, config_.max_link_factor * local, &nn_, &d2_);
    const bool has_dir = n >= 2;
    const Eigen::Vector3f dir = has_dir ? Direction() : Eigen::Vector3f::Zero();
    auto cos_to = [&](int q) { return has_dir ? DeflectionCos(dir, p2, bp_[static_cast<size_t>(q)]) : 1.0f; };

    // Closing targets: own points far enough back along the chain. The
    // loop closes onto the earliest one (the longest loop) among those
    // reached within the deflection limit.
    int close_any = -1, close_ok = -1;
    double close_ok_d2 = std::numeric_limits<double>::infinity();
    const float min_side_loop = kSideLoopReaches * static_cast<float>(config_.max_link_factor) * local;
    ClosingTargets(cos_to, min_side_loop, &close_any, &close_ok, &close_ok_d2);

    double next_d2 = 0.0;
    const Eigen::Vector3f hand = has_dir ? Eigen::Vector3f(dir.cross(HoleSide())) : Eigen::Vector3f::Zero();
    int next = PickNext(cos_to, cos_max_, p2, hand, &next_d2);
    // Close when the way back is at least as near as the way on: free
    // points left around the start must not lead the chain past it.
    if (close_ok >= 0 && (next < 0 || close_ok_d2 <= next_d2)) {
      *loop_from = close_ok;
      return Step::kClosed;
    }
    if (next < 0) {
      // Coming back to its own earlier points is still a loop, however
      // sharp the last turn.
      if (close_any >= 0) {
        *loop_from = close_any;
        return Step::kClosed;
      }
      // A gap: look farther, for the way back or straight on.
      tree_.Radius(p2, kBridgeFactor * config_.max_link_factor * local, &nn_, &d2_);
      ClosingTargets(cos_to, min_side_loop, &close_any, &close_ok, &close_ok_d2);
      if (close_any >= 0) {
        *loop_from = close_any;
        return Step::kClosed;
      }
      next = has_dir ? PickNext(cos_to, cos_bridge_, p2, hand, &next_d2) : -1;
      if (next < 0) return Step::kDeadEnd;
    }
    Absorb(p2, next, static_cast<float>(config_.absorb_factor) * local);
    Push(next);
    return Step::kExtended;
  }

  // Extends chain_ at its back until it closes (returns the chain position
  // the loop closes onto) or dead-ends for good (returns -1). At a dead end
  // it backs up one point at a time (the points stay consumed) and tries
  // again: that cuts off a false boundary branching from a rim (a sharp
  // edge flagged by the detector). If no earlier point goes anywhere either,
  // the chain is restored and this end is final.
  int Grow() {
    int loop_from = -1;
    while (true) {
      Step step = Extend(&loop_from);
      if (step == Step::kClosed) return loop_from;
      if (step == Step::kExtended) continue;
      popped_.clear();
      while (chain_.size() > 1 && step == Step::kDeadEnd) {
        popped_.push_back(chain_.back());
        Pop();
        step = Extend(&loop_from);
      }
      if (step == Step::kClosed) return loop_from;
      if (step == Step::kDeadEnd) {
        for (auto it = popped_.rbegin(); it != popped_.rend(); ++it) Push(*it);
        return -1;
      }
    }
  }

  // Own chain points in nn_ at least min_points - 1 links back: the earliest
  // of them (*any), and the earliest (*ok) and nearest distance (*ok_d2) of
  // those within the deflection limit.
  // A loop onto a point other than the chain's first must also be longer
  // than `min_side_loop_m`: coming back near itself after a squiggle in the
  // band at a corner is no loop, a tail joining a rim is.
  template <typename CosTo>
  void ClosingTargets(const CosTo& cos_to, float min_side_loop_m, int* any, int* ok, double* ok_d2) const {
    const int last_pos = static_cast<int>(chain_.size()) - 1;
    *any = -1;
    *ok = -1;
    *ok_d2 = std::numeric_limits<double>::infinity();
    for (size_t q = 0; q < nn_.size(); ++q) {
      const int pos = chain_pos_[static_cast<size_t>(nn_[q])];
      if (pos < 0 || last_pos - pos < config_.min_points - 1) continue;
      if (pos > 0 && arc_.back() - arc_[static_cast<size_t>(pos)] < min_side_loop_m) continue;
      if (*any < 0 || pos < *any) *any = pos;
      if (cos_to(nn_[q]) >= cos_max_) {
        if (*ok < 0 || pos < *ok) *ok = pos;
        *ok_d2 = std::min(*ok_d2, d2_[q]);
      }
    }
  }

  // The side the hole lies on along the chain's last points (the sum of
  // their gap directions), or zero without gap directions.
  Eigen::Vector3f HoleSide() const {
    Eigen::Vector3f side = Eigen::Vector3f::Zero();
    if (gap_dirs_.empty()) return side;
    const size_t n = chain_.size();
    for (size_t j = 0; j <= std::min(n - 1, kDirectionLag); ++j) {
      side += gap_dirs_[static_cast<size_t>(chain_[n - 1 - j])];
    }
    return side;
  }

  // The direction the chain arrives at its last point with: P1P2 of Eq. 3,
  // P1 taken kDirectionLag links back.
  Eigen::Vector3f Direction() const {
    const size_t n = chain_.size();
    return bp_[static_cast<size_t>(chain_[n - 1])] -
           bp_[static_cast<size_t>(chain_[n - 1 - std::min(n - 1, kDirectionLag)])];
  }

  // Among the `candidates` nearest free points of nn_ whose deflection
  // cosine is at least `cos_min`, and no more than kNearRatio times as far
  // as the nearest of them, the straightest (smallest theta of Eq. 3); -1
  // if none. Fills free_near_ (all free points of nn_, the nearest first).
  // With gap directions, the hole must also stay on the same hand of the
  // chain: `hand` = dir x side (zero: no check) and the candidate's
  // link x gap must agree with it. This stops a chain from turning back on
  // its own band (the hole would switch hands) and closing a bogus loop.
  template <typename CosTo>
  int PickNext(const CosTo& cos_to, float cos_min, const Eigen::Vector3f& p2, const Eigen::Vector3f& hand,
               double* next_d2) {
    free_near_.clear();
    for (size_t q = 0; q < nn_.size(); ++q) {
      if (!consumed_[static_cast<size_t>(nn_[q])]) free_near_.emplace_back(d2_[q], nn_[q]);
    }
    const size_t num = std::min(free_near_.size(), static_cast<size_t>(config_.candidates));
    std::partial_sort(free_near_.begin(), free_near_.begin() + static_cast<std::ptrdiff_t>(num),
                      free_near_.end());
    const Eigen::Vector3f side = HoleSide();
    int next = -1;
    float best_cos = -2.0f;
    double limit_d2 = std::numeric_limits<double>::infinity();
    for (size_t c = 0; c < num; ++c) {
      if (free_near_[c].first > limit_d2) break;
      const float cos_theta = cos_to(free_near_[c].second);
      if (cos_theta < cos_min) continue;
      // A point whose hole lies on the other side belongs to another hole
      // (or to the far side of a neck between two): never link to it.
      const size_t q = static_cast<size_t>(free_near_[c].second);
      if (!SameSide(q, side)) continue;
      if (!gap_dirs_.empty() && (bp_[q] - p2).cross(gap_dirs_[q]).dot(hand) < 0.0f) continue;
      if (next < 0) {
        *next_d2 = free_near_[c].first;
        limit_d2 = static_cast<double>(kNearRatio * kNearRatio) * free_near_[c].first;
      }
      if (cos_theta > best_cos) {
        best_cos = cos_theta;
        next = free_near_[c].second;
      }
    }
    return next;
  }

  // The rest of this rim's band goes with the link P2-P: the free points of
  // free_near_ within `radius` of the segment, except those beyond P, from
  // where the chain goes on.
  void Absorb(const Eigen::Vector3f& p2, int next, float radius) {
    const Eigen::Vector3f link = bp_[static_cast<size_t>(next)] - p2;
    const float link_sq = link.squaredNorm();
    const Eigen::Vector3f side = HoleSide();
    for (const auto& pair : free_near_) {
      const size_t q = static_cast<size_t>(pair.second);
      // Points of another hole's rim stay free for its own chain.
      if (!SameSide(q, side)) continue;
      const Eigen::Vector3f rel = bp_[q] - p2;
      const float t = link_sq > 0.0f ? rel.dot(link) / link_sq : 0.0f;
      if (t <= 1.0f && (rel - std::max(t, 0.0f) * link).squaredNorm() <= radius * radius) {
        Consume(q);
      }
    }
  }

  // True when point q's hole lies on the chain's side `side` (always true
  // without gap directions).
  bool SameSide(size_t q, const Eigen::Vector3f& side) const {
    return gap_dirs_.empty() || gap_dirs_[q].dot(side) > kSideCos * side.norm();
  }

  const PointList& bp_;
  const std::vector<Eigen::Vector3f> gap_dirs_;  // per boundary point, or empty
  const NeighborIndex& tree_;
  const std::vector<float> spacing_;
  const LinkConfig& config_;
  const float cos_max_;
  const float cos_bridge_;
  std::vector<char> consumed_;
  std::vector<char> tried_;     // chains have started here
  long release_budget_;         // points failed chains may still give back
  std::vector<int> touched_;    // consumed by the current chain
  std::vector<int> chain_pos_;  // position in the current chain, or -1
  std::vector<int> chain_;
  std::vector<float> arc_;   // path length from chain_[0] to each point [m]
  std::vector<int> popped_;  // backed-up points, to restore
  // Query buffers, reused.
  std::vector<int> nn_;
  std::vector<double> d2_;
  std::vector<std::pair<double, int>> free_near_;  // (squared distance, point)
};

}  // namespace

std::vector<BoundaryLine> LinkBoundaryPoints(const PointList& points,
                                             const std::vector<int>& boundary_indices,
                                             const LinkConfig& config,
                                             const std::vector<BoundaryPointInfo>* info) {
  config.Validate();
  if (info != nullptr && info->size() != boundary_indices.size()) {
    throw std::invalid_argument("LinkBoundaryPoints: " + std::to_string(info->size()) +
                                " boundary point infos for " + std::to_string(boundary_indices.size()) +
                                " boundary points");
  }
  // Sorted, unique indices (with their gap directions, when given).
  std::vector<std::pair<int, int>> order;  // (point index, position in the input)
  order.reserve(boundary_indices.size());
  for (size_t k = 0; k < boundary_indices.size(); ++k) {
    const int i = boundary_indices[k];
    if (i < 0 || static_cast<size_t>(i) >= points.size()) {
      throw std::invalid_argument("LinkBoundaryPoints: boundary index " + std::to_string(i) +
                                  " out of range for " + std::to_string(points.size()) + " points");
    }
    order.emplace_back(i, static_cast<int>(k));
  }
  std::sort(order.begin(), order.end());
  order.erase(std::unique(order.begin(), order.end(),
                          [](const auto& a, const auto& b) { return a.first == b.first; }),
              order.end());
  std::vector<int> ids;
  std::vector<Eigen::Vector3f> gap_dirs;
  std::vector<float> cloud_spacing;
  ids.reserve(order.size());
  for (const auto& [i, k] : order) {
    ids.push_back(i);
    if (info != nullptr) {
      gap_dirs.push_back((*info)[static_cast<size_t>(k)].gap_direction);
      cloud_spacing.push_back((*info)[static_cast<size_t>(k)].spacing_m);
    }
  }
  std::vector<BoundaryLine> lines;
  if (ids.size() < static_cast<size_t>(config.min_points)) return lines;

  // Compact copy of the boundary points: the tree over them is what makes
  // "nearest boundary point" queries cheap, and it is small.
  PointList bp;
  bp.reserve(ids.size());
  for (const int i : ids) bp.push_back(points[static_cast<size_t>(i)]);
  const NeighborIndex tree(bp);
  const size_t m = bp.size();
  std::vector<float> spacing = LocalSpacing(tree, cloud_spacing);
  {
    // A point whose whole neighbourhood is duplicates gets the median
    // spacing instead of a zero reach.
    std::vector<float> sorted = spacing;
    auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(m / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    const float median = *mid;
    if (!(median > 0.0f)) return lines;  // (nearly) all points coincide
    for (float& s : spacing) {
      if (!(s > 0.0f)) s = median;
    }
  }

  Linker linker(tree, std::move(spacing), std::move(gap_dirs), config);
  for (size_t start = 0; start < m; ++start) {
    if (!linker.CanStart(start)) continue;
    const std::vector<int> loop = linker.ChainFrom(static_cast<int>(start));
    if (loop.size() < static_cast<size_t>(config.min_points)) continue;
    BoundaryLine line;
    line.closed = true;
    line.indices.reserve(loop.size());
    for (const int b : loop) line.indices.push_back(ids[static_cast<size_t>(b)]);
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace graspfill::repair
