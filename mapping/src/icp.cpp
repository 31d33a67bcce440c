#include "romo/mapping/icp.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "romo/core/check.hpp"
#include "romo/mapping/ego_motion.hpp"

namespace romo::mapping {
namespace {

// Uniform grid over the target: points sorted by cell, cell key -> [begin, end) in that order.
class HashGrid {
 public:
  HashGrid(const Eigen::Matrix3Xd& pts, double cell_m) : pts_(pts), inv_(1.0 / cell_m) {
    std::vector<std::pair<std::uint64_t, int>> keyed;
    keyed.reserve(static_cast<std::size_t>(pts.cols()));
    for (Eigen::Index i = 0; i < pts.cols(); ++i) keyed.push_back({Key(Cell(pts.col(i))), static_cast<int>(i)});
    std::sort(keyed.begin(), keyed.end());
    order_.reserve(keyed.size());
    for (std::size_t i = 0; i < keyed.size(); ++i) {
      order_.push_back(keyed[i].second);
      if (i == 0 || keyed[i].first != keyed[i - 1].first) ranges_[keyed[i].first] = {static_cast<int>(i), 0};
      ranges_[keyed[i].first].second = static_cast<int>(i + 1);
    }
  }

  // Nearest target point within the 27 cells around @p q; -1 when none. @p d2 its squared distance.
  int Nearest(const Eigen::Vector3d& q, double* d2) const {
    const Eigen::Vector3i c = Cell(q);
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = ranges_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == ranges_.end()) continue;
          for (int k = it->second.first; k < it->second.second; ++k) {
            const double d = (pts_.col(order_[static_cast<std::size_t>(k)]) - q).squaredNorm();
            if (d < best_d2) {
              best_d2 = d;
              best = order_[static_cast<std::size_t>(k)];
            }
          }
        }
      }
    }
    *d2 = best_d2;
    return best;
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
    return (p * inv_).array().floor().cast<int>().matrix();
  }
  static std::uint64_t Key(const Eigen::Vector3i& c) {
    // 21 bits per axis (offset to non-negative): +-1e6 cells, i.e. +-30 km at 3 cm.
    auto lane = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFFu; };
    return lane(c.x()) | (lane(c.y()) << 21) | (lane(c.z()) << 42);
  }

  const Eigen::Matrix3Xd& pts_;
  double inv_;
  std::vector<int> order_;
  std::unordered_map<std::uint64_t, std::pair<int, int>> ranges_;
};

void CheckFinite(const Eigen::Matrix3Xd& pts, const char* what) {
  if (!pts.allFinite()) Fail(std::string("ICP: the ") + what + " cloud has non-finite points");
}

}  // namespace

void IcpParams::Validate() const {
  if (max_iterations < 1) Fail("icp.max_iterations must be >= 1, got " + std::to_string(max_iterations));
  if (!(max_correspondence_m > 0.0)) {
    Fail("icp.max_correspondence_m must be > 0, got " + std::to_string(max_correspondence_m));
  }
  if (!(convergence_translation_m >= 0.0) || !(convergence_rotation_rad >= 0.0)) {
    Fail("icp.convergence_* must be >= 0");
  }
  if (min_pairs < 3) Fail("icp.min_pairs must be >= 3, got " + std::to_string(min_pairs));
}

std::optional<IcpResult> AlignIcp(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                                  const Eigen::Isometry3d& initial, const IcpParams& params) {
  params.Validate();
  CheckFinite(source, "source");
  CheckFinite(target, "target");
  if (source.cols() < params.min_pairs || target.cols() < params.min_pairs) return std::nullopt;
  const HashGrid grid(target, params.max_correspondence_m);
  const double gate2 = params.max_correspondence_m * params.max_correspondence_m;
  IcpResult r;
  r.T_target_source = initial;
  Eigen::Matrix3Xd a(3, source.cols()), b(3, source.cols());
  std::vector<int> all;
  for (int it = 0; it < params.max_iterations; ++it) {
    int n = 0;
    double sum2 = 0.0;
    for (Eigen::Index i = 0; i < source.cols(); ++i) {
      const Eigen::Vector3d q = r.T_target_source * source.col(i);
      double d2 = 0.0;
      const int j = grid.Nearest(q, &d2);
      if (j < 0 || d2 > gate2) continue;
      a.col(n) = source.col(i);
      b.col(n) = target.col(j);
      sum2 += d2;
      ++n;
    }
    if (n < params.min_pairs) return std::nullopt;
    all.resize(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) all[static_cast<std::size_t>(k)] = k;
    // The closed-form rigid fit of the pairs (SVD, eq. 3.12) replaces the whole transform.
    const auto T = FitRigid(a.leftCols(n), b.leftCols(n), all);
    r.pairs = n;
    r.rmse_m = std::sqrt(sum2 / n);
    r.iterations = it + 1;
    if (!T) return std::nullopt;
    const Eigen::Isometry3d step = *T * r.T_target_source.inverse();
    r.T_target_source = *T;
    if (step.translation().norm() < params.convergence_translation_m &&
        Eigen::AngleAxisd(step.linear()).angle() < params.convergence_rotation_rad) {
      r.converged = true;
      break;
    }
  }
  return r;
}

}  // namespace romo::mapping
