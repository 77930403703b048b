// SPDX-License-Identifier: BSD-3-Clause
// Planes through a point set by sequential RANSAC, and the least-squares
// refits around it. Internal to src/repair.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <utility>
#include <vector>

namespace graspfill::repair::geometry {

struct RansacPlane {
  Eigen::Vector3d normal;  ///< unit
  double offset;           ///< the plane: normal . p = offset
  int inliers;             ///< points within distance_m, among those searched
};

struct RansacPlanesConfig {
  /// A point within this of a plane is its inlier [m].
  double distance_m{0.002};
  /// Draws per plane stop once a triple of the best plane's inliers would
  /// have been drawn with this probability, or after max_iterations.
  double confidence{0.999};
  int max_iterations{600};
  /// kCut: cloud points farther than this beyond a plane are on its side [m].
  double side_band_m{0.004};
  /// kCut: a plane with at most this share of the cloud (strays) beyond it
  /// on one side has the cloud on the other.
  double stray_fraction{0.002};
  /// kCut seeds: the ring of directions tried around an up hint [rad].
  double hint_ring_rad{10.0 * M_PI / 180.0};
  /// The draws' seed (mt19937_64: the same planes on every platform).
  uint64_t seed{20210101};
};

/// Least-squares plane of points[indices] (normal, offset), solved
/// iteratively (a stray far away may be among them); false when fewer than
/// 3 points.
bool FitPlaneOf(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                Eigen::Vector3d* normal, double* offset);

/// The `candidates` (indices into points) within `distance` of the plane.
std::vector<int> PlaneInliers(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& candidates,
                              const Eigen::Vector3d& normal, double offset, double distance);

// Sequential RANSAC planes over a point set (the repair's one RANSAC: the
// virtual frame's, over the boundary points), with local optimisation
// (LO-RANSAC: a triple from a thin rim band is tilted by up to the band's
// width over the rim's span, which costs a large flat rim many inliers
// against a compact side patch; the least-squares plane of its inliers is
// not) and preemptive scoring (a hypothesis is counted on a small sample
// first, on the larger one only if it can compete).
//
// Two modes:
//  - kFresh (the paper): the best plane among the points no plane explains
//    yet; its inliers are then explained.
//  - kCut: the best plane among all boundary points that has the cloud on
//    one side (the cloud was cut there) and is not one already found, i.e.
//    does not share most of its inliers with one. Points are shared
//    because a cuboid's or prism's top rim also lies on the face planes,
//    which are found first and would otherwise explain the rim away; and
//    the side test keeps out the many planes through curved claw outlines
//    that cut through the cloud.
class RansacPlanes {
 public:
  enum class Mode { kFresh, kCut };

  /// `points` (searched) and `cloud` (kCut's side test) are kept by
  /// reference; a plane needs `min_inliers`; `hint`: the up direction, if
  /// known (kCut's seeds try it first).
  RansacPlanes(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& cloud,
               const RansacPlanesConfig& config, int min_inliers, std::optional<Eigen::Vector3d> hint);

  /// Adds the next plane; false when there is none with enough inliers.
  bool FindNext(Mode mode);
  const std::vector<RansacPlane>& planes() const { return planes_; }
  /// For a refit of plane k in place (kCut's Duplicate test keeps the
  /// inliers of the plane as found).
  RansacPlane& mutable_plane(size_t k) { return planes_[k]; }

 private:
  using Vec3 = Eigen::Vector3d;
  // Points packed as float arrays (the counting loops vectorise), with
  // their indices into points_.
  struct Packed {
    std::vector<float> x, y, z;
    std::vector<int> index;
    size_t size() const { return x.size(); }
    int Count(const Vec3& n, double d, double threshold) const {
      const float nx = static_cast<float>(n.x()), ny = static_cast<float>(n.y()),
                  nz = static_cast<float>(n.z()), df = static_cast<float>(d),
                  t = static_cast<float>(threshold);
      int count = 0;
      for (size_t k = 0; k < x.size(); ++k) {
        count += std::abs(nx * x[k] + ny * y[k] + nz * z[k] - df) <= t;
      }
      return count;
    }
    // Positions (into this pack) of the points within the threshold.
    void Within(const Vec3& n, double d, double threshold, std::vector<int>* out) const {
      out->clear();
      const float nx = static_cast<float>(n.x()), ny = static_cast<float>(n.y()),
                  nz = static_cast<float>(n.z()), df = static_cast<float>(d),
                  t = static_cast<float>(threshold);
      for (size_t k = 0; k < x.size(); ++k) {
        if (std::abs(nx * x[k] + ny * y[k] + nz * z[k] - df) <= t) out->push_back(static_cast<int>(k));
      }
    }
  };

  Packed Pack(const std::vector<int>& indices) const;
  static Packed Pack(const std::vector<Vec3>& points);
  // kCut's seed planes (see the .cpp).
  void MakeSeeds(const std::optional<Vec3>& hint);
  // True if at most the strays of the cloud sample lie beyond the plane on
  // one of its sides.
  bool OneSided(const Vec3& n, double d, double band) const;
  // True if more than kMaxSharedFraction of the plane's inliers (in the
  // scoring sample) are inliers of one plane already found.
  bool Duplicate(const Vec3& n, double d) const;

  const std::vector<Vec3>& points_;
  const RansacPlanesConfig config_;
  const int min_inliers_;
  const std::optional<Vec3> hint_;
  std::mt19937_64 rng_;
  std::vector<int> all_;
  Packed all_scoring_;
  Packed side_sample_;
  int side_limit_{0};
  std::vector<char> explained_;
  std::vector<RansacPlane> planes_;
  std::vector<std::vector<uint8_t>> masks_;  // inliers among all_scoring_
  mutable std::vector<int> scratch_;
  std::vector<std::pair<Vec3, double>> seeds_;  // cut-mode seed planes
};

}  // namespace graspfill::repair::geometry
