#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "romo/core/point_cloud.hpp"
#include "romo/core/check.hpp"
#include "romo/objects/box.hpp"

namespace romo::objects {
namespace {

constexpr float kPi = 3.14159265358979f;
// Footprints whose sides differ by less than this fraction are "nearly square": their length
// axis is ambiguous, so a hint's continuity beats the length >= width rule.
constexpr float kNearSquareFraction = 0.1f;

/// Wraps to [-pi, pi).
float WrapPi(float a) { return a - 2.f * kPi * std::floor((a + kPi) / (2.f * kPi)); }
/// Wraps to [-pi/2, pi/2).
float WrapHalfPi(float a) { return a - kPi * std::floor((a + 0.5f * kPi) / kPi); }

void CheckIndices(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices, const char* who) {
  if (indices.empty()) {
    std::ostringstream msg;
    msg << who << ": no points (empty index list)";
    Fail(msg.str());
  }
  for (int i : indices) {
    if (i < 0 || i >= xyz.cols() || !xyz.col(i).allFinite()) {
      std::ostringstream msg;
      msg << who << ": point index " << i << (i < 0 || i >= xyz.cols() ? " out of range for " : " is non-finite in ")
          << "a cloud of " << xyz.cols() << " points";
      Fail(msg.str());
    }
  }
}

using Point2 = Eigen::Vector2f;

float Cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, no collinear points.
std::vector<Point2> ConvexHull(std::vector<Point2> pts) {
  std::sort(pts.begin(), pts.end(), [](const Point2& a, const Point2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  std::vector<Point2> hull(2 * pts.size());
  std::size_t k = 0;
  for (const auto& p : pts) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], p) <= 0.f) --k;
    hull[k++] = p;
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], pts[i]) <= 0.f) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  return hull;
}

/// [lo, hi] of @p values without the @p trim fraction at each end (min and max for 0).
/// Reorders @p values.
std::pair<float, float> TrimmedRange(std::vector<float>& values, float trim) {
  if (trim <= 0.f) {
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    return {*lo, *hi};
  }
  const std::size_t n = values.size();
  const auto k = static_cast<std::size_t>(trim * static_cast<float>(n - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  const float lo = values[k];
  std::nth_element(values.begin(), values.begin() + (n - 1 - k), values.end());
  return {lo, values[n - 1 - k]};
}

}  // namespace

bool Box3::Contains(const Eigen::Vector3f& p, float margin_m) const {
  const Eigen::Vector3f local = axes.transpose() * (p - center);
  return (local.cwiseAbs().array() <= (0.5f * size.array() + margin_m)).all();
}

Eigen::Matrix<float, 3, 8> Box3::Corners() const {
  Eigen::Matrix<float, 3, 8> c;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3f s((k & 1) ? 0.5f : -0.5f, (k & 2) ? 0.5f : -0.5f, (k & 4) ? 0.5f : -0.5f);
    c.col(k) = center + axes * s.cwiseProduct(size);
  }
  return c;
}

namespace {

// Of a footprint's four names (turned by k * 90 deg, length and width swapped for odd k), the k
// whose heading is nearest @p hint_yaw_rad, keeping length >= width unless it is nearly square.
int NearestQuarterTurn(float yaw_rad, float length_m, float width_m, float hint_yaw_rad) {
  const bool near_square = std::abs(length_m - width_m) < kNearSquareFraction * std::max(length_m, width_m);
  int best_k = -1;
  float best_err = 1e9f;
  for (int k = 0; k < 4; ++k) {
    const bool swapped = (k % 2) == 1;
    if (!near_square && (swapped ? width_m < length_m : length_m < width_m)) continue;
    const float err = std::abs(WrapPi(yaw_rad + static_cast<float>(k) * 0.5f * kPi - hint_yaw_rad));
    if (err < best_err) {
      best_err = err;
      best_k = k;
    }
  }
  ROMO_DEMAND(best_k >= 0);
  return best_k;
}

}  // namespace

float CanonicalYaw(float yaw_rad, float* length_m, float* width_m, std::optional<float> hint_yaw_rad) {
  ROMO_THROW_UNLESS(length_m != nullptr && width_m != nullptr);
  if (!std::isfinite(yaw_rad)) Fail("CanonicalYaw: yaw_rad is not finite");
  float l = *length_m, w = *width_m;
  if (!hint_yaw_rad) {
    if (l < w) {
      std::swap(l, w);
      yaw_rad += 0.5f * kPi;
    }
    *length_m = l;
    *width_m = w;
    return WrapHalfPi(yaw_rad);
  }
  if (!std::isfinite(*hint_yaw_rad)) Fail("CanonicalYaw: hint_yaw_rad is not finite");
  const int k = NearestQuarterTurn(yaw_rad, l, w, *hint_yaw_rad);
  if (k % 2 == 1) std::swap(l, w);
  *length_m = l;
  *width_m = w;
  const float cand = yaw_rad + static_cast<float>(k) * 0.5f * kPi;
  return WrapPi(*hint_yaw_rad + WrapPi(cand - *hint_yaw_rad));
}

namespace {

/// Rotates @p axes about col(2) by k * 90 deg (k = 0..3), permuting @p size's first two extents
/// with them: the same box under another name.
void TurnAboutThirdAxis(int k, Eigen::Matrix3f* axes, Eigen::Vector3f* size) {
  for (int q = 0; q < k; ++q) {
    const Eigen::Vector3f c0 = axes->col(0);
    axes->col(0) = axes->col(1);
    axes->col(1) = -c0;
    std::swap(size->x(), size->y());
  }
}

/// Heading of @p axes' col(0) projected onto the xy plane, radians.
float HeadingOf(const Eigen::Matrix3f& axes) { return std::atan2(axes(1, 0), axes(0, 0)); }

}  // namespace

Box3 FitPcaBox(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices, std::optional<float> hint_yaw_rad) {
  CheckIndices(xyz, indices, "FitPcaBox");
  if (hint_yaw_rad && !std::isfinite(*hint_yaw_rad)) Fail("FitPcaBox: hint_yaw_rad is not finite");
  const PointScatter stats = ComputeScatter(xyz, indices);
  const Eigen::Vector3d& mean = stats.mean;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(stats.scatter);
  Eigen::Matrix3f axes;
  axes.col(0) = eig.eigenvectors().col(2).cast<float>().normalized();  // largest variance
  axes.col(1) = eig.eigenvectors().col(1).cast<float>().normalized();
  axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();
  if (axes(2, 2) < 0.f) {  // third axis up; flipping two columns keeps the rotation proper
    axes.col(2) = -axes.col(2);
    axes.col(1) = -axes.col(1);
  }
  const Eigen::Vector3f m = mean.cast<float>();
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
  for (int i : indices) {
    const Eigen::Vector3f local = axes.transpose() * (xyz.col(i) - m);
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
  }
  Box3 box;
  box.size = hi - lo;
  box.center = m + axes * (0.5f * (hi + lo));
  if (!hint_yaw_rad) {
    if (box.size.x() < box.size.y()) TurnAboutThirdAxis(1, &axes, &box.size);  // length first
    if (const float yaw = HeadingOf(axes); yaw < -0.5f * kPi || yaw >= 0.5f * kPi) {
      // Heading outside [-pi/2, pi/2): turn the box 180 deg about col(2) (same box, other name).
      TurnAboutThirdAxis(2, &axes, &box.size);
    }
    box.axes = axes;
    box.yaw_rad = HeadingOf(axes);
    return box;
  }
  // With a hint: the name of the box nearest it, as CanonicalYaw chooses for vertical boxes.
  TurnAboutThirdAxis(NearestQuarterTurn(HeadingOf(axes), box.size.x(), box.size.y(), *hint_yaw_rad), &axes,
                     &box.size);
  box.axes = axes;
  box.yaw_rad = WrapPi(HeadingOf(axes));
  return box;
}

namespace {

// FitVerticalBox, or with @p fixed_yaw_rad the rectangle along that heading (no search).
Box3 FitVertical(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices, const Eigen::Vector3f& up,
                 std::optional<float> hint_yaw_rad, float trim_fraction, std::optional<float> fixed_yaw_rad,
                 HeadingCriterion criterion = HeadingCriterion::kSmallestArea) {
  CheckIndices(xyz, indices, "FitVerticalBox");
  if (!(up.allFinite() && std::abs(up.norm() - 1.f) < 1e-3f)) {
    std::ostringstream msg;
    msg << "FitVerticalBox: up must be a unit vector, got (" << up.transpose() << ")";
    Fail(msg.str());
  }
  if (!(trim_fraction >= 0.f && trim_fraction <= 0.25f)) {
    Fail("FitVerticalBox: trim_fraction must be in [0, 0.25], got " + std::to_string(trim_fraction));
  }
  // Ground-plane basis: the frame's x (or y when x is nearly vertical) projected onto the plane.
  Eigen::Vector3f e1 = Eigen::Vector3f::UnitX() - up.x() * up;
  if (e1.norm() < 0.1f) e1 = Eigen::Vector3f::UnitY() - up.y() * up;
  e1.normalize();
  const Eigen::Vector3f e2 = up.cross(e1);

  std::vector<Point2> footprint;
  footprint.reserve(indices.size());
  float h_lo = 1e30f, h_hi = -1e30f;
  for (int i : indices) {
    const Eigen::Vector3f p = xyz.col(i);
    footprint.emplace_back(p.dot(e1), p.dot(e2));
    h_lo = std::min(h_lo, p.dot(up));
    h_hi = std::max(h_hi, p.dot(up));
  }
  if (trim_fraction > 0.f) {
    std::vector<float> heights;
    heights.reserve(indices.size());
    for (int i : indices) heights.push_back(xyz.col(i).dot(up));
    const auto [lo, hi] = TrimmedRange(heights, trim_fraction);
    h_lo = lo;
    h_hi = hi;
  }
  float best_area = 1e30f, best_yaw = 0.f;
  Point2 best_center = footprint.front();
  float best_l = 0.f, best_w = 0.f;
  // One heading candidate: the rectangle of the footprint's extents along it (trimmed or exact).
  std::vector<float> along, across;
  auto try_heading = [&](float angle, const std::vector<Point2>& pts, float trim) {
    const float c = std::cos(angle), s = std::sin(angle);
    along.clear();
    across.clear();
    for (const auto& p : pts) {
      along.push_back(c * p.x() + s * p.y());
      across.push_back(-s * p.x() + c * p.y());
    }
    const auto [a_lo, a_hi] = TrimmedRange(along, trim);
    const auto [b_lo, b_hi] = TrimmedRange(across, trim);
    float area = (a_hi - a_lo) * (b_hi - b_lo);
    if (criterion == HeadingCriterion::kEdgeCloseness) {
      // Closeness (L-shape fitting): sum of 1 / distance to the nearest side, floored so that
      // points within the noise of a side count alike; the cost minimised is its negative.
      constexpr float kNoiseFloorM = 0.1f;
      float closeness = 0.f;
      for (std::size_t k = 0; k < along.size(); ++k) {
        const float to_side = std::min(std::min(along[k] - a_lo, a_hi - along[k]),
                                       std::min(across[k] - b_lo, b_hi - across[k]));
        closeness += 1.f / std::max(to_side, kNoiseFloorM);
      }
      area = -closeness;
    }
    // Ties (and degenerate, zero-area footprints) keep the longest side as the heading.
    if (area < best_area - 1e-9f || (std::abs(area - best_area) <= 1e-9f && a_hi - a_lo > best_l)) {
      best_area = area;
      best_yaw = angle;
      best_l = a_hi - a_lo;
      best_w = b_hi - b_lo;
      const float am = 0.5f * (a_lo + a_hi), bm = 0.5f * (b_lo + b_hi);
      best_center = Point2(c * am - s * bm, s * am + c * bm);
    }
    return area;
  };
  if (fixed_yaw_rad) {
    try_heading(*fixed_yaw_rad, footprint, trim_fraction);
  } else if (trim_fraction > 0.f) {
    // Outliers make the exact hull's rectangle follow them; the trimmed rectangle does not. A
    // rectangle's heading repeats every 90 degrees.
    // The search runs on at most ~1000 points (evenly strided); the extents use all of them.
    std::vector<Point2> sample;
    const std::size_t stride = footprint.size() / 1000 + 1;
    for (std::size_t i = 0; i < footprint.size(); i += stride) sample.push_back(footprint[i]);
    std::array<float, 90> cost{};
    for (int deg = -45; deg < 45; ++deg) {
      cost[static_cast<std::size_t>(deg + 45)] = try_heading(static_cast<float>(deg) * kPi / 180.f, sample, trim_fraction);
    }
    float heading = best_yaw;
    if (criterion == HeadingCriterion::kEdgeCloseness) {
      // Between the degree steps: the vertex of the parabola through the best step and its two
      // neighbours (the heading repeats every 90 degrees). The closeness sum is flat near its
      // peak, and a whole-degree pick jumps between neighbours for a millimetre's change in the
      // points (the same cloud sent over LCM as int16 mm turned a bay's heading by 3 degrees).
      const int best = static_cast<int>(std::lround(best_yaw * 180.f / kPi)) + 45;
      const float before = cost[static_cast<std::size_t>((best + 89) % 90)];
      const float at = cost[static_cast<std::size_t>(best)];
      const float after = cost[static_cast<std::size_t>((best + 1) % 90)];
      const float curvature = before - 2.f * at + after;
      if (curvature > 0.f) heading += std::clamp(0.5f * (before - after) / curvature, -0.5f, 0.5f) * kPi / 180.f;
    }
    best_area = 1e30f;
    try_heading(heading, footprint, trim_fraction);
  } else {
    const std::vector<Point2> hull = ConvexHull(footprint);
    // Minimum-area rectangle: one side lies on a hull edge (rotating calipers, O(h^2) is plenty
    // for the hull sizes of single objects).
    const std::size_t edges = hull.size() < 2 ? 1 : hull.size();
    for (std::size_t e = 0; e < edges; ++e) {
      float angle = 0.f;
      if (hull.size() >= 2) {
        const Point2 d = hull[(e + 1) % hull.size()] - hull[e];
        angle = std::atan2(d.y(), d.x());
      }
      try_heading(angle, hull, 0.f);
    }
  }

  Box3 box;
  float l = best_l, w = best_w;
  box.yaw_rad = CanonicalYaw(best_yaw, &l, &w, hint_yaw_rad);
  box.size = Eigen::Vector3f(l, w, h_hi - h_lo);
  box.center = best_center.x() * e1 + best_center.y() * e2 + 0.5f * (h_lo + h_hi) * up;
  const Eigen::Vector3f heading = std::cos(box.yaw_rad) * e1 + std::sin(box.yaw_rad) * e2;
  box.axes.col(0) = heading;
  box.axes.col(1) = up.cross(heading);
  box.axes.col(2) = up;
  return box;
}

}  // namespace

Box3 FitVerticalBox(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices, const Eigen::Vector3f& up,
                    std::optional<float> hint_yaw_rad, float trim_fraction, HeadingCriterion criterion) {
  return FitVertical(xyz, indices, up, hint_yaw_rad, trim_fraction, std::nullopt, criterion);
}

float HeightAboveGround(const Box3& box, const mapping::Plane& ground) {
  return ground.SignedDistance(box.center - ground.normal.normalized() * (0.5f * box.size.z()));
}

Box3 StandOnGround(Box3 box, const mapping::Plane& ground, float max_gap_m) {
  if (!(max_gap_m >= 0.f) || !std::isfinite(max_gap_m)) {
    Fail("StandOnGround: max_gap_m must be finite and >= 0, got " + std::to_string(max_gap_m));
  }
  const float bottom = HeightAboveGround(box, ground);
  if (bottom > 0.f && bottom <= max_gap_m) {
    box.center -= ground.normal.normalized() * (0.5f * bottom);
    box.size.z() += bottom;
  }
  return box;
}

Box3 FitVerticalBoxAtHeading(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices, const Eigen::Vector3f& up,
                             float yaw_rad, float trim_fraction) {
  if (!std::isfinite(yaw_rad)) Fail("FitVerticalBoxAtHeading: yaw_rad must be finite, got " + std::to_string(yaw_rad));
  return FitVertical(xyz, indices, up, yaw_rad, trim_fraction, yaw_rad);
}

std::optional<float> DenoisedHeading(const Eigen::Matrix3Xf& xyz, const std::vector<float>& sigma_z_m,
                                     const std::vector<int>& indices, const Eigen::Vector2f& viewer_xy,
                                     double noise_dominated_fraction) {
  CheckIndices(xyz, indices, "DenoisedHeading");
  if (sigma_z_m.size() != static_cast<std::size_t>(xyz.cols())) {
    Fail("DenoisedHeading: " + std::to_string(sigma_z_m.size()) + " sigma_z values for " +
         std::to_string(xyz.cols()) + " points");
  }
  if (!viewer_xy.allFinite() || !(noise_dominated_fraction >= 0.0)) {
    Fail("DenoisedHeading: the viewer must be finite and noise_dominated_fraction >= 0, got " +
         std::to_string(noise_dominated_fraction));
  }
  if (indices.size() < 3) return std::nullopt;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int i : indices) mean += xyz.col(i).head<2>().cast<double>();
  mean /= static_cast<double>(indices.size());
  Eigen::Matrix2d points = Eigen::Matrix2d::Zero(), noise = Eigen::Matrix2d::Zero();
  for (int i : indices) {
    const Eigen::Vector2d p = xyz.col(i).head<2>().cast<double>();
    points += (p - mean) * (p - mean).transpose();
    const Eigen::Vector2d sight = p - viewer_xy.cast<double>();
    const double range = sight.norm();
    if (range < 1e-6) continue;
    const double sigma = sigma_z_m[static_cast<std::size_t>(i)];
    noise += (sigma * sigma / (range * range)) * sight * sight.transpose();
  }
  points /= static_cast<double>(indices.size());
  noise /= static_cast<double>(indices.size());
  const Eigen::Vector2d sight = mean - viewer_xy.cast<double>();
  if (sight.norm() < 1e-6) return std::nullopt;
  const Eigen::Vector2d u = sight.normalized();
  if (!(u.dot(noise * u) > noise_dominated_fraction * u.dot(points * u))) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> shape(points - noise);
  const Eigen::Vector2d axis = shape.eigenvectors().col(1);  // eigenvalues ascend: the longest
  return static_cast<float>(std::atan2(axis.y(), axis.x()));
}

}  // namespace romo::objects
