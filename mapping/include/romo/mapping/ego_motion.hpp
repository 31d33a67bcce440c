#pragma once
/// Rigid motion between two sets of matched 3D feature points under RANSAC with Mahalanobis
/// gating (Sec. 3.5.2, eqs. 3.12-3.13): the camera's ego-motion from the inliers; the outliers
/// that connect one blob to another give an independent object motion (Sec. 3.5.3).
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/mapping/icp.hpp"

namespace romo::mapping {

/// Column l of p1 (frame k) matches column l of p2 (frame k+1); cov1/cov2 their 3x3 covariances.
struct MatchedPoints3D {
  Eigen::Matrix3Xd p1;
  Eigen::Matrix3Xd p2;
  std::vector<Eigen::Matrix3d> cov1;
  std::vector<Eigen::Matrix3d> cov2;
  std::size_t size() const { return static_cast<std::size_t>(p1.cols()); }
  /// @throws romo::Error when the sizes disagree.
  void Validate() const;
};

/// Covariance of a point measured along its viewing ray from the camera origin: @p sigma_ray_m
/// along the ray, @p sigma_lateral_m across it.
Eigen::Matrix3d RayCovariance(const Eigen::Vector3d& p, double sigma_ray_m, double sigma_lateral_m);

struct EgoMotionParams {
  /// chi^2 gate of eq. 3.13c; 7.815 = 95% quantile for 3 degrees of freedom.
  double chi2_gate = 7.815;
  double success_probability = 0.999;
  int max_iterations = 2000;
  int min_inliers = 8;
  std::uint64_t seed = 0x5eed;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

struct RigidMotion {
  Eigen::Isometry3d T_2_1 = Eigen::Isometry3d::Identity();  ///< maps frame-k points into frame k+1
  std::vector<int> inliers;   ///< ascending
  std::vector<int> outliers;  ///< ascending: noise, mismatches and independent motions
  int iterations = 0;
};

/// Least-squares rigid transform (eq. 3.12, SVD solution) of the columns @p indices.
/// nullopt when fewer than 3 points or they are degenerate.
std::optional<Eigen::Isometry3d> FitRigid(const Eigen::Matrix3Xd& p1, const Eigen::Matrix3Xd& p2,
                                          const std::vector<int>& indices);

/// RANSAC over minimal 3-point samples scored by the Mahalanobis gate of eq. 3.13 with
/// S = R P1 R^T + P2, refit on the inliers. nullopt when fewer than min_inliers support any
/// hypothesis (an expected outcome: too little texture or overlap).
std::optional<RigidMotion> EstimateRigidMotion(const MatchedPoints3D& matches,
                                               const EgoMotionParams& params);

/// Independent motion of the outlier matches whose frame-k ends lie in @p blob_k and frame-k+1
/// ends in @p blob_k1 (point-in-set given as per-match flags); nullopt when too few.
std::optional<RigidMotion> EstimateIndependentMotion(const MatchedPoints3D& matches,
                                                     const RigidMotion& ego,
                                                     const std::vector<char>& in_blob_k,
                                                     const std::vector<char>& in_blob_k1,
                                                     const EgoMotionParams& params);

struct IndependentMotion {
  RigidMotion flows;  ///< from the outlier flows linking the blobs (coarse)
  IcpResult icp;      ///< refined on the blobs' points, started from flows.T_2_1
  /// The refined transform (frame-k object points into frame k+1): icp.T_target_source.
  const Eigen::Isometry3d& T_2_1() const { return icp.T_target_source; }
};

/// An object's independent motion: EstimateIndependentMotion on the outlier flows that connect
/// the stored blob (points @p blob_k, frame k) to the new one (@p blob_k1, frame k+1), refined by
/// point-to-point ICP of blob_k onto blob_k1. nullopt when too few flows link the blobs or ICP
/// finds too few pairs.
std::optional<IndependentMotion> EstimateIndependentMotionIcp(
    const MatchedPoints3D& matches, const RigidMotion& ego, const std::vector<char>& in_blob_k,
    const std::vector<char>& in_blob_k1, const Eigen::Matrix3Xd& blob_k, const Eigen::Matrix3Xd& blob_k1,
    const EgoMotionParams& params, const IcpParams& icp_params);

}  // namespace romo::mapping
