#include "romo/mapping/bay_edges.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "romo/core/check.hpp"
#include "romo/core/statistics.hpp"

namespace romo::mapping {
namespace {

struct Sample {
  double s;  // along the depth axis
  float intensity;
};

// Positions along the depth axis of the samples in bins [first, last] passing @p keep.
template <typename Keep>
std::vector<double> PositionsIn(const std::vector<Sample>& samples, double origin, double bin,
                                long first, long last, const Keep& keep) {
  std::vector<double> out;
  for (const Sample& p : samples) {
    const long k = static_cast<long>(std::floor((p.s - origin) / bin));
    if (k >= first && k <= last && keep(p.intensity)) out.push_back(p.s);
  }
  return out;
}

}  // namespace

void BayEdgeParams::Validate() const {
  const FieldCheck check("BayEdgeParams");
  check.Positive("bin_m", bin_m);
  if (min_bin_points < 1) check.Fail("min_bin_points", min_bin_points, "must be >= 1");
  if (min_reference_points < 1) check.Fail("min_reference_points", min_reference_points, "must be >= 1");
  if (!(std::isfinite(paint_contrast) && paint_contrast > 1)) check.Fail("paint_contrast", paint_contrast, "must be > 1");
  check.Positive("max_paint_width_m", max_paint_width_m);
  check.NonNegative("front_search_m", front_search_m);
  check.NonNegative("front_behind_m", front_behind_m);
  if (!(std::isfinite(surface_contrast) && surface_contrast > 1)) {
    check.Fail("surface_contrast", surface_contrast, "must be > 1");
  }
  if (surface_min_bins < 1) check.Fail("surface_min_bins", surface_min_bins, "must be >= 1");
  check.NonNegative("rear_search_before_m", rear_search_before_m);
  check.NonNegative("rear_search_after_m", rear_search_after_m);
}

BayEdges FindBayEdges(const PointCloud& cloud, const std::vector<int>& ground,
                      const Eigen::Isometry3d& T_frame_cloud, const BayStrip& strip,
                      const BayEdgeParams& params) {
  params.Validate();
  ROMO_THROW_UNLESS(cloud.IsConsistent());
  if (!(std::abs(strip.depth_axis.norm() - 1.0) < 1e-6) || !strip.center_m.allFinite() ||
      !(strip.half_width_m > 0) || !(strip.rear_m > strip.front_m)) {
    std::ostringstream msg;
    msg << "bay edges: invalid strip (depth axis (" << strip.depth_axis.transpose() << "), half width "
        << strip.half_width_m << " m, front " << strip.front_m << " m, rear " << strip.rear_m << " m)";
    Fail(msg.str());
  }
  const Eigen::Vector2d lateral(-strip.depth_axis.y(), strip.depth_axis.x());
  const double lo = strip.front_m - params.front_search_m;
  const double hi = strip.rear_m + params.rear_search_after_m;
  const double ref_lo = strip.front_m + params.front_behind_m;
  const double ref_hi = strip.rear_m - params.rear_search_before_m;

  std::vector<Sample> samples;
  std::vector<double> reference;
  for (int i : ground) {
    if (i < 0 || static_cast<std::size_t>(i) >= cloud.size()) {
      Fail("bay edges: ground index " + std::to_string(i) + " outside a cloud of " +
           std::to_string(cloud.size()) + " points");
    }
    const Eigen::Vector2d p = (T_frame_cloud * cloud.xyz.col(i).cast<double>()).head<2>() - strip.center_m;
    if (!p.allFinite() || std::abs(p.dot(lateral)) > strip.half_width_m) continue;
    const double s = p.dot(strip.depth_axis);
    if (s < lo || s > hi) continue;
    samples.push_back({s, cloud.intensity[i]});
    if (s >= ref_lo && s <= ref_hi) reference.push_back(cloud.intensity[i]);
  }
  BayEdges out;
  out.reference_points = static_cast<int>(reference.size());
  if (out.reference_points < params.min_reference_points) return out;
  const double ref = Median(reference);
  out.reference_intensity = ref;
  if (!(ref > 0)) return out;  // no grey values: nothing to compare

  // Median grey value of every bin dense enough to say.
  const double bin = params.bin_m;
  std::map<long, std::vector<double>> by_bin;
  for (const Sample& p : samples) by_bin[static_cast<long>(std::floor((p.s - lo) / bin))].push_back(p.intensity);
  std::map<long, double> profile;
  for (auto& [k, values] : by_bin) {
    if (static_cast<int>(values.size()) >= params.min_bin_points) profile[k] = Median(std::move(values));
  }
  const auto centre_of = [&](long k) { return lo + (k + 0.5) * bin; };

  // Front: the run of bright bins nearest the bay, narrow enough to be a line; its bay-side edge
  // from the bright points themselves, finer than a bin.
  const double paint_min = params.paint_contrast * ref;
  std::vector<std::pair<long, long>> runs;
  for (const auto& [k, value] : profile) {
    if (centre_of(k) > strip.front_m + params.front_behind_m) break;
    if (value < paint_min) continue;
    if (!runs.empty() && runs.back().second == k - 1) {
      runs.back().second = k;
    } else {
      runs.emplace_back(k, k);
    }
  }
  for (auto run = runs.rbegin(); run != runs.rend(); ++run) {
    if ((run->second - run->first + 1) * bin > params.max_paint_width_m + 1e-9) continue;
    const auto bright = PositionsIn(samples, lo, bin, run->first - 1, run->second + 1,
                                    [&](float v) { return v >= paint_min; });
    if (!bright.empty()) out.front_m = Percentile(bright, 0.9);
    break;
  }

  // Rear: the first bins in a row whose surface is not the bay's; the edge from the first of
  // those points.
  const auto off_surface = [&](double v) { return v >= params.surface_contrast * ref || v * params.surface_contrast <= ref; };
  long run_start = 0, run_length = 0, last = 0;
  for (const auto& [k, value] : profile) {
    if (centre_of(k) < strip.rear_m - params.rear_search_before_m) continue;
    if (!off_surface(value)) {
      run_length = 0;
      continue;
    }
    if (run_length == 0 || k != last + 1) {
      run_start = k;
      run_length = 0;
    }
    ++run_length;
    last = k;
    if (run_length >= params.surface_min_bins) {
      const auto off = PositionsIn(samples, lo, bin, run_start - 1, run_start,
                                   [&](float v) { return off_surface(v); });
      if (!off.empty()) out.rear_m = Percentile(off, 0.1);
      break;
    }
  }
  return out;
}

}  // namespace romo::mapping
