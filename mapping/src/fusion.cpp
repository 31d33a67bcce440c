#include "romo/mapping/fusion.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "internal/voxel_keys.hpp"
#include "romo/core/check.hpp"

namespace romo::mapping {

void FusionParams::Validate() const {
  if (!std::isfinite(overlap_voxel_m)) {
    std::ostringstream msg;
    msg << "FusionParams.overlap_voxel_m = " << overlap_voxel_m << ": must be finite";
    Fail(msg.str());
  }
  if (!(max_stamp_offset_s > 0.0)) {
    std::ostringstream msg;
    msg << "FusionParams.max_stamp_offset_s = " << max_stamp_offset_s << ": must be > 0";
    Fail(msg.str());
  }
}

Eigen::Isometry3f VehicleDisplacement(const VehicleMotion& motion, std::int64_t stamp_ns) {
  const double dt = static_cast<double>(stamp_ns - motion.reference_stamp_ns) * 1e-9;
  const double v = motion.speed_mps, w = motion.yaw_rate_radps;
  const double heading = w * dt;
  double x, y;
  if (std::abs(heading) < 1e-9) {
    x = v * dt;
    y = 0.0;
  } else {
    // Exact arc of the constant-turn-rate model.
    x = v / w * std::sin(heading);
    y = v / w * (1.0 - std::cos(heading));
  }
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::AngleAxisf(static_cast<float>(heading), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), 0.f);
  return T;
}

PointCloud FuseRigClouds(const std::vector<RigCloud>& rigs, const VehicleMotion& motion,
                         const FusionParams& params, FusionStats* stats, std::vector<int>* point_rig_ids) {
  params.Validate();
  if (!std::isfinite(motion.speed_mps) || !std::isfinite(motion.yaw_rate_radps)) {
    std::ostringstream msg;
    msg << "VehicleMotion: speed_mps = " << motion.speed_mps << ", yaw_rate_radps = " << motion.yaw_rate_radps
        << ": must be finite";
    Fail(msg.str());
  }
  FusionStats local;
  PointCloud fused;
  std::vector<int> rig_of_point;
  std::size_t total = 0;
  for (const RigCloud& rig : rigs) {
    if (!rig.cloud.IsConsistent()) {
      std::ostringstream msg;
      msg << "rig " << rig.rig_id << ": point cloud channels have different sizes";
      Fail(msg.str());
    }
    const double offset_s = std::abs(static_cast<double>(rig.stamp_ns - motion.reference_stamp_ns)) * 1e-9;
    if (offset_s > params.max_stamp_offset_s) {
      std::ostringstream msg;
      msg << "rig " << rig.rig_id << ": stamp " << rig.stamp_ns << " ns is " << offset_s
          << " s from the reference stamp (max_stamp_offset_s = " << params.max_stamp_offset_s << ")";
      Fail(msg.str());
    }
    total += rig.cloud.size();
  }
  local.input_points = total;
  fused.Resize(total);
  rig_of_point.reserve(total);
  Eigen::Index n = 0;
  for (std::size_t r = 0; r < rigs.size(); ++r) {
    const RigCloud& rig = rigs[r];
    const Eigen::Isometry3f T_ref_rig = VehicleDisplacement(motion, rig.stamp_ns) * rig.T_vehicle_rig;
    const Eigen::Matrix3f R = T_ref_rig.linear();
    const Eigen::Vector3f t = T_ref_rig.translation();
    for (Eigen::Index i = 0; i < rig.cloud.xyz.cols(); ++i) {
      const Eigen::Vector3f p = rig.cloud.xyz.col(i);
      if (!p.allFinite()) {
        ++local.skipped_non_finite;
        continue;
      }
      fused.xyz.col(n) = R * p + t;
      fused.sigma_z_m[n] = rig.cloud.sigma_z_m[i];
      fused.intensity[n] = rig.cloud.intensity[i];
      rig_of_point.push_back(static_cast<int>(r));
      ++n;
    }
  }
  fused.Resize(static_cast<std::size_t>(n));

  if (params.overlap_voxel_m > 0.f && n > 0) {
    // Group points by voxel; where several rigs share a voxel, keep only the rig that sees it
    // with the lowest sigma_z (the surface is counted once, at its best measurement).
    internal::FinitePoints finite = internal::GatherFinite(fused.xyz, nullptr);
    const Eigen::Vector3f origin = internal::SnappedOrigin(finite.lo, params.overlap_voxel_m);
    const int depth = internal::VoxelDepthFor(origin, finite.hi, params.overlap_voxel_m, "fusion overlap thinning");
    std::vector<std::uint64_t> codes = internal::VoxelCodes(fused.xyz, finite.indices, origin, params.overlap_voxel_m);
    std::vector<int> order = std::move(finite.indices);
    internal::RadixSortPairs(&codes, &order, 3 * depth);
    std::vector<char> keep(static_cast<std::size_t>(n), 1);
    for (std::size_t begin = 0; begin < order.size();) {
      std::size_t end = begin + 1;
      bool mixed = false;
      while (end < order.size() && codes[end] == codes[begin]) {
        mixed |= rig_of_point[order[end]] != rig_of_point[order[begin]];
        ++end;
      }
      if (mixed) {
        int best_rig = -1;
        float best_sigma = std::numeric_limits<float>::infinity();
        for (std::size_t k = begin; k < end; ++k) {
          const int i = order[k];
          if (fused.sigma_z_m[i] < best_sigma || best_rig < 0) {
            best_sigma = fused.sigma_z_m[i];
            best_rig = rig_of_point[i];
          }
        }
        for (std::size_t k = begin; k < end; ++k) {
          if (rig_of_point[order[k]] != best_rig) keep[order[k]] = 0;
        }
      }
      begin = end;
    }
    Eigen::Index m = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!keep[i]) continue;
      fused.xyz.col(m) = fused.xyz.col(i);
      fused.sigma_z_m[m] = fused.sigma_z_m[i];
      fused.intensity[m] = fused.intensity[i];
      rig_of_point[m] = rig_of_point[i];
      ++m;
    }
    local.thinned = static_cast<std::size_t>(n - m);
    fused.Resize(static_cast<std::size_t>(m));
    rig_of_point.resize(static_cast<std::size_t>(m));
  }
  if (stats) *stats = local;
  if (point_rig_ids) {
    point_rig_ids->resize(rig_of_point.size());
    for (std::size_t i = 0; i < rig_of_point.size(); ++i) (*point_rig_ids)[i] = rigs[rig_of_point[i]].rig_id;
  }
  return fused;
}

}  // namespace romo::mapping
