#include "romo/mapping/ego_motion.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <Eigen/SVD>

#include "romo/core/check.hpp"
#include "romo/mapping/plane_ransac.hpp"

namespace romo::mapping {

void MatchedPoints3D::Validate() const {
  if (p1.cols() != p2.cols() || cov1.size() != size() || cov2.size() != size()) {
    Fail("matched points: " + std::to_string(p1.cols()) + " / " + std::to_string(p2.cols()) +
         " points and " + std::to_string(cov1.size()) + " / " + std::to_string(cov2.size()) +
         " covariances must agree");
  }
}

Eigen::Matrix3d RayCovariance(const Eigen::Vector3d& p, double sigma_ray_m, double sigma_lateral_m) {
  const double n = p.norm();
  const Eigen::Vector3d r = n > 0 ? Eigen::Vector3d(p / n) : Eigen::Vector3d::UnitZ();
  const double lat2 = sigma_lateral_m * sigma_lateral_m;
  return lat2 * Eigen::Matrix3d::Identity() + (sigma_ray_m * sigma_ray_m - lat2) * r * r.transpose();
}

void EgoMotionParams::Validate() const {
  if (!(chi2_gate > 0)) Fail("ego_motion.chi2_gate must be > 0, got " + std::to_string(chi2_gate));
  if (!(success_probability > 0 && success_probability < 1)) {
    Fail("ego_motion.success_probability must be in (0, 1), got " + std::to_string(success_probability));
  }
  if (max_iterations < 1) Fail("ego_motion.max_iterations must be >= 1, got " + std::to_string(max_iterations));
  if (min_inliers < 3) Fail("ego_motion.min_inliers must be >= 3, got " + std::to_string(min_inliers));
}

std::optional<Eigen::Isometry3d> FitRigid(const Eigen::Matrix3Xd& p1, const Eigen::Matrix3Xd& p2,
                                          const std::vector<int>& idx) {
  if (idx.size() < 3) return std::nullopt;
  Eigen::Vector3d c1 = Eigen::Vector3d::Zero(), c2 = Eigen::Vector3d::Zero();
  for (int i : idx) {
    c1 += p1.col(i);
    c2 += p2.col(i);
  }
  c1 /= idx.size();
  c2 /= idx.size();
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (int i : idx) H += (p1.col(i) - c1) * (p2.col(i) - c2).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // Two vanishing singular values: collinear points leave a rotation about their line free.
  if (svd.singularValues()(1) < 1e-9 * std::max(1.0, svd.singularValues()(0))) return std::nullopt;
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) D(2, 2) = -1;  // no reflection
  const Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = c2 - R * c1;
  return T;
}

namespace {

// Indices passing the chi^2 gate of eq. 3.13 under @p T.
std::vector<int> Gate(const MatchedPoints3D& m, const Eigen::Isometry3d& T, double gate,
                      const std::vector<int>* subset) {
  std::vector<int> in;
  const Eigen::Matrix3d R = T.linear();
  auto test = [&](int i) {
    const Eigen::Vector3d v = m.p2.col(i) - T * m.p1.col(i).eval();
    const Eigen::Matrix3d S = R * m.cov1[i] * R.transpose() + m.cov2[i];
    if (v.dot(S.ldlt().solve(v)) < gate) in.push_back(i);
  };
  if (subset) {
    for (int i : *subset) test(i);
  } else {
    for (int i = 0; i < static_cast<int>(m.size()); ++i) test(i);
  }
  return in;
}

std::optional<RigidMotion> Ransac(const MatchedPoints3D& m, const std::vector<int>& candidates,
                                  const EgoMotionParams& params) {
  const int n = static_cast<int>(candidates.size());
  if (n < std::max(3, params.min_inliers)) return std::nullopt;
  std::mt19937_64 rng(params.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  RigidMotion best;
  int needed = params.max_iterations;
  int it = 0;
  for (; it < needed && it < params.max_iterations; ++it) {
    int a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || b == c || a == c) continue;
    const auto T = FitRigid(m.p1, m.p2, {candidates[a], candidates[b], candidates[c]});
    if (!T) continue;
    auto in = Gate(m, *T, params.chi2_gate, &candidates);
    if (in.size() > best.inliers.size()) {
      best.inliers = std::move(in);
      best.T_2_1 = *T;
      // Eq. 3.2 with the outlier fraction seen so far (sample size 3).
      const double eps = 1.0 - static_cast<double>(best.inliers.size()) / n;
      needed = RansacIterations(params.success_probability, std::min(eps, 0.999), 3, params.max_iterations);
    }
  }
  if (static_cast<int>(best.inliers.size()) < params.min_inliers) return std::nullopt;
  // Refit on the inliers and re-gate twice: the minimal sample's transform is noisy.
  for (int round = 0; round < 2; ++round) {
    const auto T = FitRigid(m.p1, m.p2, best.inliers);
    if (!T) break;
    auto in = Gate(m, *T, params.chi2_gate, &candidates);
    if (static_cast<int>(in.size()) < params.min_inliers) break;
    best.T_2_1 = *T;
    best.inliers = std::move(in);
  }
  std::sort(best.inliers.begin(), best.inliers.end());
  std::vector<char> is_in(m.size(), 0);
  for (int i : best.inliers) is_in[i] = 1;
  for (int i : candidates) {
    if (!is_in[i]) best.outliers.push_back(i);
  }
  std::sort(best.outliers.begin(), best.outliers.end());
  best.iterations = it;
  return best;
}

}  // namespace

std::optional<RigidMotion> EstimateRigidMotion(const MatchedPoints3D& matches,
                                               const EgoMotionParams& params) {
  matches.Validate();
  params.Validate();
  std::vector<int> all(matches.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  return Ransac(matches, all, params);
}

std::optional<RigidMotion> EstimateIndependentMotion(const MatchedPoints3D& matches,
                                                     const RigidMotion& ego,
                                                     const std::vector<char>& in_blob_k,
                                                     const std::vector<char>& in_blob_k1,
                                                     const EgoMotionParams& params) {
  matches.Validate();
  params.Validate();
  if (in_blob_k.size() != matches.size() || in_blob_k1.size() != matches.size()) {
    Fail("independent motion: blob flags must have one entry per match");
  }
  std::vector<int> linking;
  for (int i : ego.outliers) {
    if (in_blob_k[i] && in_blob_k1[i]) linking.push_back(i);
  }
  return Ransac(matches, linking, params);
}

std::optional<IndependentMotion> EstimateIndependentMotionIcp(
    const MatchedPoints3D& matches, const RigidMotion& ego, const std::vector<char>& in_blob_k,
    const std::vector<char>& in_blob_k1, const Eigen::Matrix3Xd& blob_k, const Eigen::Matrix3Xd& blob_k1,
    const EgoMotionParams& params, const IcpParams& icp_params) {
  icp_params.Validate();
  auto flows = EstimateIndependentMotion(matches, ego, in_blob_k, in_blob_k1, params);
  if (!flows) return std::nullopt;
  auto icp = AlignIcp(blob_k, blob_k1, flows->T_2_1, icp_params);
  if (!icp) return std::nullopt;
  return IndependentMotion{std::move(*flows), *icp};
}

}  // namespace romo::mapping
