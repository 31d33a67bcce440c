#pragma once
/// The contiguous point cloud that stereo produces and mapping consumes: structure of arrays,
/// one entry per point, all in one frame (which one is the owner's business: name it).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace romo {

struct PointCloud {
  /// 3 x N positions in metres.
  Eigen::Matrix3Xf xyz;
  /// Depth standard deviation per point in metres (eq. 2.3); 0 where unknown.
  std::vector<float> sigma_z_m;
  /// Grey value per point (0-255); 0 where unknown.
  std::vector<float> intensity;

  std::size_t size() const { return static_cast<std::size_t>(xyz.cols()); }
  bool empty() const { return xyz.cols() == 0; }

  /// Reserves room for @p n points, keeping the current ones.
  void Reserve(std::size_t n);
  /// Resizes all channels to @p n points (new entries are uninitialised positions, zero extras).
  void Resize(std::size_t n);
  /// Appends one point: O(size()) per call, since an Eigen matrix keeps no spare capacity (a loop
  /// of PushBack is quadratic wherever realloc cannot grow in place, e.g. under ASan). For many
  /// points, Resize once and fill the channels.
  void PushBack(const Eigen::Vector3f& p, float sigma_z_m_value = 0.f, float intensity_value = 0.f);
  /// Appends all points of @p other.
  void Append(const PointCloud& other);
  /// The points at @p indices, in that order.
  PointCloud Select(const std::vector<int>& indices) const;
  /// Applies @p T_to_from to every position (sigma and intensity unchanged).
  void Transform(const Eigen::Isometry3f& T_to_from);
  /// True when every channel has size() entries.
  bool IsConsistent() const;
};

/// Mean and scatter matrix (sum of outer products about the mean) of the columns of @p xyz at
/// @p indices, accumulated in double: the input of every PCA in romo (planes, boxes).
struct PointScatter {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
};
/// @pre @p indices is not empty and every index is a column of @p xyz.
PointScatter ComputeScatter(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices);

}  // namespace romo
