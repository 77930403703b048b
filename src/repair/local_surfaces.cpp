// SPDX-License-Identifier: BSD-3-Clause
#include "local_surfaces.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace graspfill::repair::fill {

bool FitHeightField(const PointList& points, const std::vector<int>& support, const HoleFrame& frame,
                    int degree, int iterations, double sigma_floor_m, HeightField* hf) {
  const int terms = HeightField::NumTerms(degree);
  const std::vector<int> used = Thin(support, 2000);
  const int m = static_cast<int>(used.size());
  if (m < 3 * terms) return false;
  hf->frame = frame;
  hf->degree = degree;
  Eigen::VectorXd u(m), v(m), w(m);
  double scale = 0.0;
  for (int k = 0; k < m; ++k) {
    const Eigen::Vector3d l = frame.Local(points[used[k]].cast<double>());
    u(k) = l.x();
    v(k) = l.y();
    w(k) = l.z();
    scale = std::max({scale, std::abs(u(k)), std::abs(v(k))});
  }
  hf->scale = scale > 0.0 ? scale : 1.0;
  Eigen::MatrixXd a(m, terms);
  BasisVec f;
  for (int k = 0; k < m; ++k) {
    hf->Basis(u(k), v(k), &f, nullptr, nullptr);
    a.row(k) = f.transpose();
  }
  Eigen::VectorXd weights(m);
  std::vector<double> abs_residual(m);
  const auto reweight = [&](const Eigen::VectorXd& residual) {
    for (int k = 0; k < m; ++k) abs_residual[k] = std::abs(residual(k));
    hf->sigma_m = 1.4826 * Median(abs_residual);
    const double c = 4.685 * std::max(hf->sigma_m, sigma_floor_m);
    for (int k = 0; k < m; ++k) {
      const double r = residual(k) / c;
      weights(k) = std::abs(r) < 1.0 ? (1.0 - r * r) * (1.0 - r * r) : 0.0;
    }
  };
  reweight(w);  // residuals to the rim's plane
  hf->coeffs = Eigen::VectorXd::Zero(terms);
  const int plane_terms = HeightField::NumTerms(std::min(1, degree));
  for (int it = 0; it < iterations; ++it) {
    const int t = it < 2 ? plane_terms : terms;
    const Eigen::MatrixXd aw = a.leftCols(t).array().colwise() * weights.array();
    Eigen::MatrixXd normal = aw.transpose() * a.leftCols(t);
    // A whisper of ridge keeps the solve defined when the weights leave
    // too few points for some monomial.
    normal.diagonal().array() += 1e-12 * (normal.trace() / t + 1.0);
    hf->coeffs.setZero();
    hf->coeffs.head(t) = normal.ldlt().solve(aw.transpose() * w);
    reweight(w - a * hf->coeffs);
  }
  return hf->coeffs.allFinite();
}

bool FitQuadric(const PointList& points, const std::vector<int>& support, std::vector<double> weights,
                int iterations, double sigma_floor_m, Quadric* out) {
  const size_t m = support.size();
  if (m < 30) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : support) mean += points[i].cast<double>();
  mean /= static_cast<double>(m);
  double rms = 0.0;
  for (int i : support) rms += (points[i].cast<double>() - mean).squaredNorm();
  out->mean = mean;
  out->scale = std::sqrt(rms / static_cast<double>(m));
  if (!(out->scale > 0.0)) return false;
  std::vector<Eigen::Vector3d> y(m);
  for (size_t k = 0; k < m; ++k) y[k] = (points[support[k]].cast<double>() - mean) / out->scale;
  std::vector<double> abs_residual(m);
  for (int it = 0; it < iterations; ++it) {
    double wsum = 0.0;
    Eigen::Matrix<double, 9, 1> vbar = Eigen::Matrix<double, 9, 1>::Zero();
    for (size_t k = 0; k < m; ++k) {
      wsum += weights[k];
      vbar += weights[k] * Quadric::V(y[k]).head<9>();
    }
    if (!(wsum > 0.0)) return false;
    vbar /= wsum;
    Eigen::Matrix<double, 9, 9> mm = Eigen::Matrix<double, 9, 9>::Zero();
    Eigen::Matrix<double, 9, 9> nn = Eigen::Matrix<double, 9, 9>::Zero();
    for (size_t k = 0; k < m; ++k) {
      if (weights[k] <= 0.0) continue;
      const Eigen::Matrix<double, 9, 1> v = Quadric::V(y[k]).head<9>() - vbar;
      const Eigen::Matrix<double, 3, 9> j = Quadric::J(y[k]).leftCols<9>();
      mm += weights[k] * v * v.transpose();
      // Coefficient by coefficient: a 9 x 3 x 9 product is past the size at
      // which Eigen calls its general matrix product, whose setup cost more
      // than the product.
      nn += weights[k] * j.transpose().lazyProduct(j);
    }
    nn.diagonal().array() += 1e-12 * nn.trace();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> ges(mm, nn);
    if (ges.info() != Eigen::Success) return false;
    const Eigen::Matrix<double, 9, 1> q9 = ges.eigenvectors().col(0);
    out->q.head<9>() = q9;
    out->q(9) = -vbar.dot(q9);
    if (!out->q.allFinite()) return false;
    for (size_t k = 0; k < m; ++k) {
      abs_residual[k] = std::abs(out->Distance(points[support[k]].cast<double>()));
    }
    std::vector<double> sorted = abs_residual;
    out->sigma_m = 1.4826 * Median(sorted);
    const double c = 4.685 * std::max(out->sigma_m, sigma_floor_m);
    for (size_t k = 0; k < m; ++k) {
      const double r = abs_residual[k] / c;
      weights[k] = r < 1.0 ? (1.0 - r * r) * (1.0 - r * r) : 0.0;
    }
  }
  return true;
}

namespace {
// The thin plate's acceptance (see FitThinPlate).
constexpr double kMinFacingShare = 0.12;
constexpr double kMaxHeightSpread = 1.0;
// A quadric within this robust residual scale of the facing points [m]
// (a fused cloud's noise is ~0.3 mm) carries the fill over a curved face.
constexpr double kQuadricNoiseM = 0.0005;
}  // namespace

bool FitThinPlate(const NeighborIndex& index, const std::vector<int>& support, const HoleFrame& frame,
                  const Eigen::Vector3f& centroid, double d, int max_centres, ThinPlateSheet* out) {
  // Only the points that face the way the hole does (their normals within
  // 60 degrees of n): the support box also catches the faces beside the
  // hole's, which are no graph over its plane.
  const PointList& points = index.points();
  const std::vector<int> sample = Thin(support, 1500);
  const std::vector<Eigen::Vector3f> normals = EstimateNormals(index, sample, 10, centroid);
  const Eigen::Vector3f n = frame.n.cast<float>();
  std::vector<Eigen::Vector3d> local;
  std::vector<int> facing;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (size_t k = 0; k < sample.size(); ++k) {
    if (normals[k].dot(n) < 0.5f) continue;
    facing.push_back(sample[k]);
    local.push_back(frame.Local(points[sample[k]].cast<double>()));
    lo = lo.cwiseMin(local.back().head<2>());
    hi = hi.cwiseMax(local.back().head<2>());
  }
  // Enough of the support must face the hole's way (12%: a hole over a
  // rounded edge has ~16%) and its heights spread over less than the
  // support's smaller side: else it is no sheet over the plane (a boundary
  // around a large part of the object: 8% facing, 70 mm of heights over
  // 64 mm), and a spline through it would invent a surface. The caller
  // falls back to Poisson then.
  if (local.size() < 30 || local.size() < kMinFacingShare * static_cast<double>(sample.size())) {
    return false;
  }
  out->w_lo = std::numeric_limits<double>::infinity();
  out->w_hi = -out->w_lo;
  for (const Eigen::Vector3d& l : local) {
    out->w_lo = std::min(out->w_lo, l.z());
    out->w_hi = std::max(out->w_hi, l.z());
  }
  if (out->w_hi - out->w_lo > kMaxHeightSpread * (hi - lo).minCoeff()) return false;
  out->frame = frame;
  const Eigen::Vector2d size = (hi - lo).cwiseMax(d);
  // Cells of ~1/max_centres of the box's area (the hole leaves some
  // empty), never finer than 2 D.
  const double cell = std::max(2.0 * d, std::sqrt(size.x() * size.y() / max_centres));
  const int nu = static_cast<int>(size.x() / cell) + 1, nv = static_cast<int>(size.y() / cell) + 1;
  std::vector<Eigen::Vector4d> sums(static_cast<size_t>(nu) * nv, Eigen::Vector4d::Zero());
  for (const Eigen::Vector3d& l : local) {
    const int iu = std::min(nu - 1, static_cast<int>((l.x() - lo.x()) / cell));
    const int iv = std::min(nv - 1, static_cast<int>((l.y() - lo.y()) / cell));
    sums[static_cast<size_t>(iv) * nu + iu] += Eigen::Vector4d(l.x(), l.y(), l.z(), 1.0);
  }
  out->scale = std::max(size.maxCoeff(), 1e-6);
  std::vector<Eigen::Vector3d> data;  // cell means, scaled
  for (const Eigen::Vector4d& s : sums) {
    if (s(3) >= 1.0) data.push_back(s.head<3>() / (s(3) * out->scale));
  }
  // Twice: a fit, then again without the cells it leaves far off (a curl
  // of the TSDF at the rim, a stray patch of the finger).
  std::vector<char> use(data.size(), 1);
  for (int pass = 0; pass < 2; ++pass) {
    out->centres.clear();
    std::vector<double> w;
    for (size_t i = 0; i < data.size(); ++i) {
      if (!use[i]) continue;
      out->centres.push_back(data[i].head<2>());
      w.push_back(data[i].z());
    }
    const long count = static_cast<long>(out->centres.size());
    if (count < 10) return false;
    // Smoothing: the cells' mean heights carry noise of a fraction of D.
    const double lambda = 1e-6;
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(count + 3, count + 3);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(count + 3);
    for (long i = 0; i < count; ++i) {
      for (long j = 0; j < i; ++j) {
        a(i, j) = a(j, i) = ThinPlateSheet::Phi((out->centres[i] - out->centres[j]).squaredNorm());
      }
      a(i, i) = lambda * static_cast<double>(count);
      a(i, count) = a(count, i) = 1.0;
      a(i, count + 1) = a(count + 1, i) = out->centres[i].x();
      a(i, count + 2) = a(count + 2, i) = out->centres[i].y();
      b(i) = w[i];
    }
    const Eigen::VectorXd x = a.partialPivLu().solve(b);
    if (!x.allFinite()) return false;
    out->c = x.head(count);
    out->affine = x.tail<3>();
    if (pass == 1) break;
    std::vector<double> r(data.size());
    for (size_t i = 0; i < data.size(); ++i) {
      r[i] = std::abs(data[i].z() * out->scale -
                      out->Height(data[i].x() * out->scale, data[i].y() * out->scale));
    }
    std::vector<double> sorted = r;
    const double cut = std::max(3.0 * 1.4826 * Median(sorted), d);
    bool dropped = false;
    for (size_t i = 0; i < data.size(); ++i) {
      if (r[i] > cut) use[i] = 0, dropped = true;
    }
    if (!dropped) break;
  }
  out->w_pad = 2.0 * d;  // the caller may widen it
  out->use_quadric =
      FitQuadric(points, facing, std::vector<double>(facing.size(), 1.0), 6, 0.05 * d, &out->quadric) &&
      !out->quadric.IsPlanePair() && out->quadric.sigma_m <= kQuadricNoiseM;
  out->grid_lo = lo;
  out->grid_cell = cell;
  out->nu = nu;
  out->nv = nv;
  out->column_top.assign(static_cast<size_t>(nu) * nv, std::numeric_limits<double>::quiet_NaN());
  for (int i : support) {
    const Eigen::Vector3d l = frame.Local(points[i].cast<double>());
    const double fu = std::floor((l.x() - lo.x()) / cell), fv = std::floor((l.y() - lo.y()) / cell);
    if (!(fu >= 0.0 && fu < nu && fv >= 0.0 && fv < nv)) continue;
    double& top = out->column_top[static_cast<size_t>(fv) * nu + static_cast<size_t>(fu)];
    if (std::isnan(top) || l.z() > top) top = l.z();
  }
  out->column_tol_m = std::max(0.0015, 3.0 * d);
  return true;
}

bool Quadric::IsPlanePair() const {
  Eigen::Matrix4d m;
  m << q(0), q(3) / 2, q(4) / 2, q(6) / 2,  //
      q(3) / 2, q(1), q(5) / 2, q(7) / 2,   //
      q(4) / 2, q(5) / 2, q(2), q(8) / 2,   //
      q(6) / 2, q(7) / 2, q(8) / 2, q(9);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(m, Eigen::EigenvaluesOnly);
  Eigen::Vector4d a = eig.eigenvalues().cwiseAbs();
  std::sort(a.data(), a.data() + 4);
  return a(1) < 1e-3 * a(3);
}

}  // namespace graspfill::repair::fill
