// SPDX-License-Identifier: BSD-3-Clause
// Step 2 of the hole repair (Cui et al. 2021, section 2.2.1): hole-boundary
// points by the maximum-angle criterion.
//
// For each point P: P and its k nearest neighbours; their least-squares
// tangent plane through the centroid, whose normal is the eigenvector of
// the SMALLEST eigenvalue of the centred covariance (the paper writes "the
// largest eigenvalue of A^T A", a slip: that vector is the direction of
// largest spread, inside the plane); the directions P'Q'_i of the projected
// neighbours seen from the projected P, sorted by angle around the normal;
// P is a boundary point when the largest angle between two consecutive
// directions (the wrap-around pair included) exceeds the threshold.
//
// Own code vs Open3D's tensor PointCloud::ComputeBoundaryPoints(radius,
// max_nn, angle_deg) (0.16; PCL's BoundaryEstimation: the same criterion
// over a hybrid radius/kNN neighbourhood, normals required). Measured by
// boundary_detection_test.cc (OwnVsOpen3dOn50k) on a 49.9k-point paper-
// protocol cylinder (7 x 7 x 14 cm, ~0.8 mm spacing, top cut, three claw
// holes, random pose), Release, one core (OMP_THREAD_LIMIT=1), CPU time,
// best of 3, on a shared 2-core VM whose load made runs vary by up to 2x:
// ranges over 5 sessions. Open3D got max_nn = k + 1 = 21 and radius = 4
// spacings (the radius rarely binds: both see the same neighbourhoods).
//   kNN(21) for every point through NeighborIndex (the floor):  145-250 ms
//   own, paper criterion only (confirm_k = 0), normals included: 265-380 ms
//   Open3D with our normals (tensor copies, its own tree):      365-420 ms
//   Open3D with its own EstimateNormals:                        635-810 ms
//   own default (k 20 + confirm 50):                            285-430 ms
// Agreement of own paper criterion and Open3D, same normals or Open3D's:
// IoU of the flagged sets 1.000 (4811 points each). Both flag 9.6% of the
// cloud and only 17% of that lies within 3.5 spacings of a true rim; the own
// default flags 713 points, 99.9% of them on a rim (see confirm_k). Same
// answer, own code faster, sharing the tree and giving the normals and the
// BoundaryPointInfo to the later steps; so there is no method switch.
// Where the time goes (perf, own default): ~70% in Open3D's KDTreeFlann
// (nanoflann with a run-time dimension over doubles, ~3 us per kNN(21)),
// ~20% in this file (plane fit, the sorted directions: no atan2 but for
// the few flagged points). A faster NeighborIndex is what would speed it up.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

/// Parameters of the maximum-angle criterion.
struct BoundaryConfig {
  /// Neighbours of each point (the point itself excluded; the local set
  /// Omega of the paper has k + 1 points). 20 is PCL's and the paper's
  /// usual choice: enough for a stable plane, local enough for small holes.
  int k{20};
  /// A point is a boundary point when the largest angular gap between
  /// consecutive projected neighbour directions exceeds this [rad]. The
  /// paper's value pi/2: an interior point's largest gap is ~2*pi/k on
  /// average and rarely above pi/2; a point on a straight rim has a gap of
  /// ~pi.
  double angle_threshold_rad{M_PI / 2};
  /// Second, wider look (not in the paper; 0 turns it off): a point that
  /// passes with k neighbours is kept only if it also passes with
  /// confirm_k. Why: on a random (Poisson-like) sample, as the synthetic
  /// protocol's, the k = 20 directions of an interior point are nearly
  /// independent uniform angles, and P(largest of 20 gaps > pi/2) ~ 20 *
  /// (3/4)^19 ~ 8.5%: the paper's criterion alone flags ~9% of a closed
  /// sphere (measured 8.8%), scattered micro-voids that would swamp the
  /// rims for RANSAC and linking. With 50 neighbours the odds are
  /// 50 * (3/4)^49 ~ 4e-5 (measured: 0.005% of the sphere; 0.09% with 40),
  /// while a true rim point keeps its ~pi gap at both scales (the band
  /// along a rim gets thinner: 1.12 instead of 1.29 points per spacing of
  /// rim). Only the ~9% flagged points pay the second query (+10-20%
  /// time). The paper's method as written: confirm_k = 0.
  int confirm_k{50};

  /// Throws std::invalid_argument unless k >= 3, confirm_k is 0 or > k,
  /// and the threshold is in (0, 2*pi).
  void Validate() const;
};

/// What the detection learnt about one boundary point, for the linking.
struct BoundaryPointInfo {
  /// Unit vector in the tangent plane bisecting the widest gap: from the
  /// rim into the hole.
  Eigen::Vector3f gap_direction{Eigen::Vector3f::Zero()};
  /// Local point spacing of the cloud there [m]: 1/sqrt(density), the
  /// density measured on the covered part of the neighbourhood disc.
  float spacing_m{0.0f};
};

/// Indices (increasing) of the points of index.points() that lie on a hole
/// boundary (or on the cloud's outer edge: the criterion cannot tell them
/// apart; linking and classification do). Points must be finite.
/// If `normals` is not null it receives, for every point of the index, the
/// unit normal of its least-squares tangent plane (unoriented: its sign is
/// arbitrary), so that later steps need not estimate normals again; a point
/// whose neighbours all coincide with it gets the zero vector and is not
/// flagged.
/// If `info` is not null it receives, for every returned boundary point
/// (same order), its gap direction and local spacing: LinkBoundaryPoints
/// uses them to keep two close holes apart and to scale its reach.
/// Cost: one k+1 nearest-neighbour query per point, and one confirm_k+1
/// query per point that passes the first test; no allocation per point
/// here (Open3D's KDTreeFlann allocates one small vector inside each query).
/// Throws std::invalid_argument on an invalid config.
/// `table`, if given, is index.AllKnn(>= k + 1) (shared with the outlier
/// filter): the first pass reads it instead of querying (same answers).
/// `candidates`, if given (increasing indices), are the only points tested
/// (e.g. those near the boundary found on a coarser copy); the result is
/// in their order and `normals` is set for them only. Without `table`
/// their first queries run as one batch (NeighborIndex::KnnOf).
std::vector<int> DetectBoundaryPoints(const NeighborIndex& index, const BoundaryConfig& config,
                                      std::vector<Eigen::Vector3f>* normals = nullptr,
                                      std::vector<BoundaryPointInfo>* info = nullptr,
                                      const KnnTable* table = nullptr,
                                      const std::vector<int>* candidates = nullptr);

}  // namespace graspfill::repair
