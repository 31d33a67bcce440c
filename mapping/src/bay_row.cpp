#include "romo/mapping/bay_row.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "romo/core/check.hpp"
#include "romo/core/statistics.hpp"

namespace romo::mapping {
namespace {

struct LineSupport {
  double covered_m = 0.0;
  std::vector<Eigen::Vector2d> points;
};

// The paint points within line_half_width_m of the line through @p point along @p direction, and
// the length of the bins along it they fill.
LineSupport SupportOf(const std::vector<Eigen::Vector2d>& paint, const Eigen::Vector2d& point,
                      const Eigen::Vector2d& direction, const BayRowParams& params) {
  const Eigen::Vector2d normal(-direction.y(), direction.x());
  LineSupport support;
  std::vector<long> bins;
  for (const Eigen::Vector2d& p : paint) {
    if (std::abs(normal.dot(p - point)) > params.line_half_width_m) continue;
    support.points.push_back(p);
    bins.push_back(static_cast<long>(std::floor(direction.dot(p - point) / params.line_bin_m)));
  }
  std::sort(bins.begin(), bins.end());
  support.covered_m =
      params.line_bin_m * static_cast<double>(std::unique(bins.begin(), bins.end()) - bins.begin());
  return support;
}

// Peaks of paint along the row (positions, ascending) among the separator band's points
// (along, depth).
std::vector<double> SeparatorsIn(const std::vector<Eigen::Vector2d>& band, const BayRowParams& params) {
  if (band.empty()) return {};
  double lo = band.front().x(), hi = lo;
  for (const Eigen::Vector2d& p : band) {
    lo = std::min(lo, p.x());
    hi = std::max(hi, p.x());
  }
  const double bin = params.separator_bin_m;
  const auto n = static_cast<std::size_t>(std::floor((hi - lo) / bin)) + 1;
  std::vector<int> counts(n, 0);
  for (const Eigen::Vector2d& p : band) ++counts[static_cast<std::size_t>(std::floor((p.x() - lo) / bin))];
  struct Peak {
    double along_m;
    int points;
  };
  std::vector<Peak> peaks;
  const int half_bins = std::max(1, static_cast<int>(std::lround(params.separator_half_width_m / bin)));
  for (std::size_t k = 0; k < n; ++k) {
    const bool local_max = (k == 0 || counts[k] >= counts[k - 1]) && (k + 1 == n || counts[k] > counts[k + 1]);
    if (!local_max || counts[k] == 0) continue;
    const double centre = lo + (static_cast<double>(k) + 0.5) * bin;
    double sum = 0.0, depth_lo = INFINITY, depth_hi = -INFINITY;
    int points = 0;
    for (const Eigen::Vector2d& p : band) {
      if (std::abs(p.x() - centre) > half_bins * bin) continue;
      sum += p.x();
      ++points;
      depth_lo = std::min(depth_lo, p.y());
      depth_hi = std::max(depth_hi, p.y());
    }
    if (points >= params.separator_min_points && depth_hi - depth_lo >= params.separator_min_depth_m) {
      peaks.push_back({sum / points, points});
    }
  }
  // The strongest first; weaker ones too close to a kept one are the same line's fringe.
  std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) { return a.points > b.points; });
  std::vector<double> kept;
  for (const Peak& p : peaks) {
    if (std::all_of(kept.begin(), kept.end(),
                    [&](double s) { return std::abs(s - p.along_m) >= params.separator_min_spacing_m; })) {
      kept.push_back(p.along_m);
    }
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

}  // namespace

void BayRowParams::Validate() const {
  const FieldCheck check("BayRowParams");
  check.Positive("max_range_m", max_range_m);
  if (!(std::isfinite(contrast) && contrast > 1)) check.Fail("contrast", contrast, "must be > 1");
  check.Positive("line_half_width_m", line_half_width_m);
  check.Positive("line_bin_m", line_bin_m);
  check.Positive("min_covered_m", min_covered_m);
  if (hypotheses < 1) check.Fail("hypotheses", hypotheses, "must be >= 1");
  check.Positive("min_pair_distance_m", min_pair_distance_m);
  if (min_paint_points < 2) check.Fail("min_paint_points", min_paint_points, "must be >= 2");
  check.NonNegative("separator_from_m", separator_from_m);
  if (!(std::isfinite(separator_to_m) && separator_to_m > separator_from_m)) {
    check.Fail("separator_to_m", separator_to_m, "must be finite and > separator_from_m");
  }
  check.Positive("separator_bin_m", separator_bin_m);
  check.Positive("separator_half_width_m", separator_half_width_m);
  if (separator_min_points < 1) check.Fail("separator_min_points", separator_min_points, "must be >= 1");
  check.NonNegative("separator_min_depth_m", separator_min_depth_m);
  check.Positive("separator_min_spacing_m", separator_min_spacing_m);
  check.NonNegative("viewer_on_line_m", viewer_on_line_m);
}

std::optional<BayRow> FindBayRow(const PointCloud& cloud, const std::vector<int>& ground,
                                 const BayRowParams& params) {
  params.Validate();
  ROMO_THROW_UNLESS(cloud.IsConsistent());
  std::vector<Eigen::Vector2d> in_range;
  std::vector<double> greys;
  for (int i : ground) {
    if (i < 0 || static_cast<std::size_t>(i) >= cloud.size()) {
      Fail("bay row: ground index " + std::to_string(i) + " outside a cloud of " + std::to_string(cloud.size()) +
           " points");
    }
    const Eigen::Vector2d p = cloud.xyz.col(i).head<2>().cast<double>();
    if (!p.allFinite() || p.norm() > params.max_range_m) continue;
    in_range.push_back(p);
    greys.push_back(cloud.intensity[static_cast<std::size_t>(i)]);
  }
  if (greys.empty()) return std::nullopt;
  const double bright = params.contrast * Median(greys);
  if (!(bright > 0)) return std::nullopt;  // no grey values: nothing to compare
  std::vector<Eigen::Vector2d> paint;
  for (std::size_t k = 0; k < in_range.size(); ++k) {
    if (greys[k] >= bright) paint.push_back(in_range[k]);
  }
  if (static_cast<int>(paint.size()) < params.min_paint_points) return std::nullopt;

  std::mt19937 rng(7);  // fixed: the same cloud gives the same row
  std::uniform_int_distribution<std::size_t> pick(0, paint.size() - 1);
  LineSupport best;
  for (int h = 0; h < params.hypotheses; ++h) {
    const Eigen::Vector2d& a = paint[pick(rng)];
    const Eigen::Vector2d& b = paint[pick(rng)];
    if ((b - a).norm() < params.min_pair_distance_m) continue;
    LineSupport support = SupportOf(paint, a, (b - a).normalized(), params);
    if (support.covered_m > best.covered_m) best = std::move(support);
  }
  if (best.covered_m < params.min_covered_m) return std::nullopt;
  BayRow row;
  row.covered_m = best.covered_m;
  for (const Eigen::Vector2d& p : best.points) row.origin += p / static_cast<double>(best.points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : best.points) scatter += (p - row.origin) * (p - row.origin).transpose();
  row.along = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvectors().col(1);
  row.into_bays = Eigen::Vector2d(-row.along.y(), row.along.x());

  // The viewer stands in the aisle: the bays lie on the side of the line away from the frame's
  // origin. A line showing more separators on the viewer's side is the bays' far end (a kerb), no
  // front. A viewer within viewer_on_line_m of the line is entering a bay: the side showing more
  // separators holds them.
  std::vector<Eigen::Vector2d> band[2];  // (along, depth) on the into_bays and the other side
  for (const Eigen::Vector2d& p : paint) {
    const double depth = row.Depth(p);
    const double d = std::abs(depth);
    if (d >= params.separator_from_m && d <= params.separator_to_m) {
      band[depth > 0 ? 0 : 1].emplace_back(row.Along(p), d);
    }
  }
  std::vector<double> separators[2] = {SeparatorsIn(band[0], params), SeparatorsIn(band[1], params)};
  const double viewer_depth = row.Depth(Eigen::Vector2d::Zero());
  const int far_side = viewer_depth > 0.0 ? 1 : 0;
  int side = far_side;
  if (std::abs(viewer_depth) <= params.viewer_on_line_m) {
    if (separators[1 - far_side].size() > separators[far_side].size()) side = 1 - far_side;
  } else if (separators[1 - far_side].size() > separators[far_side].size()) {
    return std::nullopt;
  }
  if (side == 1) row.into_bays = -row.into_bays;
  row.separators_m = std::move(separators[side]);
  return row;
}

}  // namespace romo::mapping
