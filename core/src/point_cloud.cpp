#include "romo/core/point_cloud.hpp"

#include "romo/core/check.hpp"

namespace romo {

void PointCloud::Reserve(std::size_t n) {
  // Eigen matrices cannot reserve capacity; only the side channels can.
  sigma_z_m.reserve(n);
  intensity.reserve(n);
}

void PointCloud::Resize(std::size_t n) {
  xyz.conservativeResize(3, static_cast<Eigen::Index>(n));
  sigma_z_m.resize(n, 0.f);
  intensity.resize(n, 0.f);
}

void PointCloud::PushBack(const Eigen::Vector3f& p, float sigma_z_m_value, float intensity_value) {
  const auto n = static_cast<Eigen::Index>(size());
  xyz.conservativeResize(3, n + 1);
  xyz.col(n) = p;
  sigma_z_m.push_back(sigma_z_m_value);
  intensity.push_back(intensity_value);
}

void PointCloud::Append(const PointCloud& other) {
  ROMO_THROW_UNLESS(other.IsConsistent());
  const auto n = xyz.cols();
  xyz.conservativeResize(3, n + other.xyz.cols());
  xyz.rightCols(other.xyz.cols()) = other.xyz;
  sigma_z_m.insert(sigma_z_m.end(), other.sigma_z_m.begin(), other.sigma_z_m.end());
  intensity.insert(intensity.end(), other.intensity.begin(), other.intensity.end());
}

PointCloud PointCloud::Select(const std::vector<int>& indices) const {
  PointCloud out;
  out.Resize(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const int k = indices[i];
    ROMO_THROW_UNLESS(k >= 0 && static_cast<std::size_t>(k) < size());
    out.xyz.col(static_cast<Eigen::Index>(i)) = xyz.col(k);
    out.sigma_z_m[i] = sigma_z_m[k];
    out.intensity[i] = intensity[k];
  }
  return out;
}

void PointCloud::Transform(const Eigen::Isometry3f& T_to_from) {
  xyz = (T_to_from.linear() * xyz).colwise() + T_to_from.translation();
}

PointScatter ComputeScatter(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices) {
  ROMO_THROW_UNLESS(!indices.empty());
  PointScatter s;
  for (int i : indices) s.mean += xyz.col(i).cast<double>();
  s.mean /= static_cast<double>(indices.size());
  for (int i : indices) {
    const Eigen::Vector3d q = xyz.col(i).cast<double>() - s.mean;
    s.scatter.noalias() += q * q.transpose();
  }
  return s;
}

bool PointCloud::IsConsistent() const {
  return sigma_z_m.size() == size() && intensity.size() == size();
}

}  // namespace romo
