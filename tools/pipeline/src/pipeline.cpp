#include "romo/pipeline/pipeline.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include <Eigen/Eigenvalues>

#include "romo/core/angles.hpp"
#include "romo/core/check.hpp"
#include "romo/core/statistics.hpp"
#include "romo/objects/atlas.hpp"
#include "romo/objects/geo.hpp"
#include "romo/objects/view_completion.hpp"
#include "romo/stereo/multi_rig.hpp"

namespace romo::pipeline {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFullResolutionEdgeHeadingM = 1.5;

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// An axis this aligned with the sight line (cos 45 deg) is nearer it than across it.
constexpr float kCos45 = 0.7071f;

double YawOf(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d x = T.rotation().col(0);
  return std::atan2(x.y(), x.x());
}

// Turns @p box to @p yaw_rad about @p up (its length axis along the heading, level with the ground).
void SetYaw(objects::Box3* box, float yaw_rad, const Eigen::Vector3f& up) {
  box->yaw_rad = yaw_rad;
  const Eigen::Vector3f heading(std::cos(yaw_rad), std::sin(yaw_rad), 0.0f);
  box->axes.col(0) = (heading - up * up.dot(heading)).normalized();
  box->axes.col(1) = up.cross(box->axes.col(0));
}

Eigen::Vector2d Rotate(const Eigen::Vector2d& v, double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

// Whether an obstacle of @p class_name measured now (num_points > 0) has its centre within
// @p radius_m of @p xy (vehicle frame).
bool MeasuredWithin(const std::vector<planning_iface::Obstacle>& obstacles, const std::string& class_name,
                    const Eigen::Vector2d& xy, double radius_m) {
  return std::any_of(obstacles.begin(), obstacles.end(), [&](const planning_iface::Obstacle& o) {
    return o.class_name == class_name && o.num_points > 0 && (o.center_m.head<2>() - xy).norm() < radius_m;
  });
}

// A covariance turned like Rotate turns its vectors.
Eigen::Matrix2d RotateCovariance(const Eigen::Matrix2d& cov, double yaw) {
  const Eigen::Matrix2d r = Eigen::Rotation2Dd(yaw).toRotationMatrix();
  return r * cov * r.transpose();
}

// How much depth noise widens a blob's trimmed extent along the line of sight: the trimmed fit
// keeps the points between the trim and 1 - trim quantiles, +-z sigma_z of a surface seen with
// Gaussian depth noise (z = 1.88 for 3 %), sigma_z being the blob's median.
double DepthSpread(const std::vector<float>& sigma_z_m, const std::vector<int>& blob, float trim) {
  if (blob.empty() || trim <= 0.f) return 0.0;
  std::vector<float> sigmas;
  sigmas.reserve(blob.size());
  for (int i : blob) sigmas.push_back(sigma_z_m[static_cast<std::size_t>(i)]);
  std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
  double lo = 0.0, hi = 10.0;  // z with P(Z > z) = trim, by bisection on erfc
  for (int k = 0; k < 50; ++k) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > trim ? lo : hi) = mid;
  }
  return 2.0 * lo * sigmas[sigmas.size() / 2];
}

// Where a blob was seen from: the camera of the rig that delivered most of its points. Close to
// the vehicle the line of sight from the vehicle's origin is metres off the cameras' (rigs sit at
// its corners and sides), and it decides which face of the box was seen.
Eigen::Vector2f BlobViewer(const std::vector<int>& blob, const std::vector<int>& point_rig_ids,
                           const drivers::Calibration& calibration) {
  std::map<int, int> count;
  for (int i : blob) ++count[point_rig_ids[static_cast<std::size_t>(i)]];
  int rig = -1, most = 0;
  for (const auto& [id, n] : count) {
    if (n > most) {
      most = n;
      rig = id;
    }
  }
  if (rig < 0) return Eigen::Vector2f::Zero();
  return calibration.rig(rig).T_vehicle_rig.translation().head<2>().cast<float>();
}

// Whether @p offset from a footprint's centre lies inside the footprint (heading @p yaw).
bool InsideFootprint(const Eigen::Vector2d& offset, double yaw, double half_length, double half_width) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return std::abs(c * offset.x() + s * offset.y()) <= half_length &&
         std::abs(-s * offset.x() + c * offset.y()) <= half_width;
}

// How many of @p indices' points lie inside the footprint (vehicle frame) centred at @p xy with
// heading @p yaw and half extents @p half_length, @p half_width.
int PointsInsideFootprint(const PointCloud& cloud, const std::vector<int>& indices, const Eigen::Vector2d& xy,
                          double yaw, double half_length, double half_width) {
  if (half_length <= 0.0 || half_width <= 0.0) return 0;
  const double reach2 = half_length * half_length + half_width * half_width;
  int inside = 0;
  for (int i : indices) {
    const Eigen::Vector2d d = cloud.xyz.col(i).head<2>().cast<double>() - xy;
    if (d.squaredNorm() > reach2) continue;
    inside += InsideFootprint(d, yaw, half_length, half_width);
  }
  return inside;
}

// How near the vehicle (its frame's origin, on the ground) the nearest point of @p blob comes.
double NearestRange(const PointCloud& cloud, const std::vector<int>& blob) {
  double nearest = std::numeric_limits<double>::infinity();
  for (int i : blob) nearest = std::min(nearest, static_cast<double>(cloud.xyz.col(i).head<2>().norm()));
  return nearest;
}

// @p blob in two along @p axis: 1-D 2-means started from its ends.
std::array<std::vector<int>, 2> SplitAlong(const PointCloud& cloud, const std::vector<int>& blob,
                                           const Eigen::Vector3f& axis) {
  std::vector<float> along;
  along.reserve(blob.size());
  for (int i : blob) along.push_back(axis.dot(cloud.xyz.col(i)));
  const auto [lo, hi] = std::minmax_element(along.begin(), along.end());
  float mean[2] = {*lo, *hi};
  auto side = [&](float v) { return std::abs(v - mean[0]) <= std::abs(v - mean[1]) ? 0 : 1; };
  for (int iteration = 0; iteration < 10; ++iteration) {
    double sum[2] = {0.0, 0.0};
    int count[2] = {0, 0};
    for (float v : along) {
      sum[side(v)] += v;
      ++count[side(v)];
    }
    if (count[0] == 0 || count[1] == 0) break;
    for (int k = 0; k < 2; ++k) mean[k] = static_cast<float>(sum[k] / count[k]);
  }
  std::array<std::vector<int>, 2> halves;
  for (std::size_t k = 0; k < along.size(); ++k) halves[static_cast<std::size_t>(side(along[k]))].push_back(blob[k]);
  return halves;
}

// @p blob in two at @p at along @p axis: the points before it, and the rest.
std::array<std::vector<int>, 2> SplitAt(const PointCloud& cloud, const std::vector<int>& blob, const Eigen::Vector3f& axis,
                                        float at) {
  std::array<std::vector<int>, 2> parts;
  for (int p : blob) parts[axis.dot(cloud.xyz.col(p)) < at ? 0 : 1].push_back(p);
  return parts;
}

// Where along @p axis the points of @p blob thin out, at least @p margin_m inside both ends: the
// middles of the stretches (0.1 m bins, averaged over 0.3 m) holding less than @p max_density of
// the blob's median bin, sparsest first, one per stretch.
std::vector<float> SparseStretches(const PointCloud& cloud, const std::vector<int>& blob, const Eigen::Vector3f& axis,
                                   float margin_m, double max_density) {
  constexpr float kBinM = 0.1f;
  std::vector<float> along;
  along.reserve(blob.size());
  for (int i : blob) along.push_back(axis.dot(cloud.xyz.col(i)));
  const auto [lo_it, hi_it] = std::minmax_element(along.begin(), along.end());
  const float lo = *lo_it;
  const int bins = static_cast<int>((*hi_it - lo) / kBinM) + 1;
  const int margin_bins = static_cast<int>(margin_m / kBinM);
  if (bins < 2 * margin_bins + 3) return {};
  std::vector<int> count(static_cast<std::size_t>(bins), 0);
  for (float v : along) ++count[static_cast<std::size_t>((v - lo) / kBinM)];
  std::vector<int> sorted = count;
  std::nth_element(sorted.begin(), sorted.begin() + bins / 2, sorted.end());
  const double limit = max_density * sorted[static_cast<std::size_t>(bins / 2)];
  std::vector<std::pair<double, int>> sparsest;  // (density, bin) of each stretch's sparsest bin
  bool in_stretch = false;
  for (int b = margin_bins; b < bins - margin_bins; ++b) {
    const double density = (count[b - 1] + count[b] + count[b + 1]) / 3.0;
    if (density >= limit) {
      in_stretch = false;
      continue;
    }
    if (!in_stretch) sparsest.emplace_back(density, b);
    if (density < sparsest.back().first) sparsest.back() = {density, b};
    in_stretch = true;
  }
  std::sort(sparsest.begin(), sparsest.end());
  std::vector<float> out;
  for (const auto& [density, b] : sparsest) out.push_back(lo + (static_cast<float>(b) + 0.5f) * kBinM);
  return out;
}

}  // namespace

objects::ViewCompletionParams PipelineParams::CarParkCompletion() {
  objects::ViewCompletionParams p;
  p.corner_angle_deg = 50.0;
  return p;
}

mapping::SegmentationParams PipelineParams::DefaultSegmentation() {
  mapping::SegmentationParams p;
  p.leaf_size_m = 0.15f;
  p.min_blob_points = 30;
  // A car is at most ~5.5 m long: a bigger blob is several objects touching (or a hedge). Cars
  // parked side by side 0.6 m apart are bridged by stereo's stray points at 0.15 m leaves; a
  // blob wider than 3.5 m is re-clustered at half the leaf, which separates them.
  p.max_object_extent_m = 3.5f;
  p.refine_factor = 0.5f;
  p.max_refine_levels = 1;
  return p;
}

stereo::SgmParameters PipelineParams::VehicleSgm() {
  stereo::SgmParameters sgm;
  sgm.path_count = stereo::PathCount::k3;  // fastest mode; ample for obstacle boxes
  // Middlebury's best (0.95) keeps ambiguous matches that float in front of the parked cars and
  // pedestrians of the simulated scene; 0.8 halves the points off any object within 15 m (22 %
  // -> 5 % of those above the ground a few frames into the maneuver).
  sgm.uniqueness = 0.8f;
  return sgm;
}

PipelineParams PipelineParams::ForCalibration(const drivers::Calibration& calibration, int threads) {
  ROMO_THROW_UNLESS(!calibration.rigs.empty());
  return ForImageWidth(calibration.rigs.front().width_px, threads);
}

PipelineParams PipelineParams::ForImageWidth(int image_width_px, int threads) {
  if (image_width_px < 1) Fail("pipeline: image width must be >= 1 px, got " + std::to_string(image_width_px));
  PipelineParams p;
  p.threads = threads;
  const bool full_resolution = image_width_px >= 600;
  p.disparity_size = full_resolution ? 128 : 64;
  if (full_resolution) {
    // Half the depth noise makes the corner of a car seen obliquely an L, not a smear: its sides
    // give the heading (see edge_heading_min_length_m), and far parked cars remembered from such
    // views are good enough to be preferred (parked_prefer_max_range_m).
    p.edge_heading_min_length_m = kFullResolutionEdgeHeadingM;
    p.parked_prefer_max_range_m = std::numeric_limits<double>::infinity();
  }
  return p;
}

void PipelineParams::Validate() const {
  if (threads < 1 || threads > 64) Fail("pipeline: threads must be 1..64, got " + std::to_string(threads));
  if (disparity_size < 16 || disparity_size > 256 || disparity_size % 16 != 0) {
    Fail("pipeline: disparity_size must be a multiple of 16 in [16, 256], got " +
         std::to_string(disparity_size));
  }
  if (!(max_range_m > 0) || !std::isfinite(max_range_m)) {
    Fail("pipeline: max_range_m must be > 0, got " + std::to_string(max_range_m));
  }
  if (!(min_object_height_m >= 0)) {
    Fail("pipeline: min_object_height_m must be >= 0, got " + std::to_string(min_object_height_m));
  }
  if (!(box_trim_fraction >= 0 && box_trim_fraction <= 0.25f)) {
    Fail("pipeline: box_trim_fraction must be in [0, 0.25], got " + std::to_string(box_trim_fraction));
  }
  if (!(parked_speed_per_depth_spread >= 0 && std::isfinite(parked_speed_per_depth_spread))) {
    Fail("pipeline: parked_speed_per_depth_spread must be finite and >= 0, got " +
         std::to_string(parked_speed_per_depth_spread));
  }
  if (parked_free_ground_points < 0 || !(parked_max_speed_mps >= 0) || !(parked_footprint_margin_m >= 0) ||
      !(parked_max_range_m > 0) || !(parked_standing_points_ratio >= 0 && std::isfinite(parked_standing_points_ratio)) ||
      !(parked_keep_view_fraction >= 0 && std::isfinite(parked_keep_view_fraction))) {
    Fail("pipeline: parked_* out of range (ground points " + std::to_string(parked_free_ground_points) +
         " >= 0, speed " + std::to_string(parked_max_speed_mps) + " m/s >= 0, margin " +
         std::to_string(parked_footprint_margin_m) + " m >= 0, range " + std::to_string(parked_max_range_m) +
         " m > 0, standing points ratio " + std::to_string(parked_standing_points_ratio) +
         " finite >= 0, keep view fraction " + std::to_string(parked_keep_view_fraction) + " finite >= 0)");
  }
  if (!(parked_pieces_margin_m >= 0 && std::isfinite(parked_pieces_margin_m)) || !(parked_pieces_walked_m >= 0)) {
    Fail("pipeline: parked_pieces_* out of range (margin " + std::to_string(parked_pieces_margin_m) +
         " m finite >= 0, walked " + std::to_string(parked_pieces_walked_m) + " m >= 0)");
  }
  if (!(parked_prefer_offset_m >= 0) || !(parked_prefer_max_range_m >= 0)) {
    Fail("pipeline: parked_prefer_* out of range (offset " + std::to_string(parked_prefer_offset_m) +
         " m >= 0, max range " + std::to_string(parked_prefer_max_range_m) + " m >= 0)");
  }
  if (!(tandem_min_length_m >= 0) || !(aisle_pair_min_gap_m >= 0)) {
    Fail("pipeline: tandem_min_length_m and aisle_pair_min_gap_m must be >= 0, got " +
         std::to_string(tandem_min_length_m) + " m, " + std::to_string(aisle_pair_min_gap_m) + " m");
  }
  if (!(framed_min_length_m >= 0) || !(framed_occluder_margin_m >= 0) ||
      !(framed_end_gap_deg > 0 && framed_end_gap_deg < 45)) {
    Fail("pipeline: framed_* out of range (length " + std::to_string(framed_min_length_m) + " m >= 0, margin " +
         std::to_string(framed_occluder_margin_m) + " m >= 0, end gap " + std::to_string(framed_end_gap_deg) +
         " deg in (0, 45))");
  }
  if (!(edge_heading_min_length_m >= 0)) {
    Fail("pipeline: edge_heading_min_length_m must be >= 0, got " + std::to_string(edge_heading_min_length_m));
  }
  if (!(face_pair_min_length_m >= 0 && face_pair_gap_density > 0 && face_pair_gap_density <= 1)) {
    Fail("pipeline: face_pair_min_length_m must be >= 0 and face_pair_gap_density in (0, 1], got " +
         std::to_string(face_pair_min_length_m) + " m, " + std::to_string(face_pair_gap_density));
  }
  if (!(stacked_merge_xy_m >= 0 && stacked_merge_gap_m >= 0)) {
    Fail("pipeline: stacked_merge_xy_m and stacked_merge_gap_m must be >= 0, got " +
         std::to_string(stacked_merge_xy_m) + " m, " + std::to_string(stacked_merge_gap_m) + " m");
  }
  if (!(row_align_min_cars >= 0 && row_align_radius_m > 0 && row_align_max_offset_m > 0 &&
        row_align_min_range_m >= 0 && row_align_min_off_deg >= 0 && row_align_min_off_deg < 90 &&
        row_align_min_agreeing >= 0 && row_align_free_ground_margin_m >= 0 && row_align_free_ground_points >= 1)) {
    Fail("pipeline: row_align_* out of range (min cars " + std::to_string(row_align_min_cars) + " >= 0, radius " +
         std::to_string(row_align_radius_m) + " m > 0, max offset " + std::to_string(row_align_max_offset_m) +
         " m > 0, min range " + std::to_string(row_align_min_range_m) + " m >= 0, min off " +
         std::to_string(row_align_min_off_deg) + " deg in [0, 90), min agreeing " +
         std::to_string(row_align_min_agreeing) + " >= 0, free ground margin " +
         std::to_string(row_align_free_ground_margin_m) + " m >= 0, points " +
         std::to_string(row_align_free_ground_points) + " >= 1)");
  }
  if (!(ground_contact_gap_m >= 0) || !std::isfinite(ground_contact_gap_m)) {
    Fail("pipeline: ground_contact_gap_m must be finite and >= 0, got " + std::to_string(ground_contact_gap_m));
  }
  if (!(max_ground_gap_m >= 0)) {
    Fail("pipeline: max_ground_gap_m must be >= 0, got " + std::to_string(max_ground_gap_m));
  }
  if (!(completion.truncation_angle_deg >= 0 && completion.truncation_angle_deg < 45)) {
    Fail("pipeline: completion.truncation_angle_deg must be in [0, 45), got " +
         std::to_string(completion.truncation_angle_deg));
  }
  if (!(completion.corner_angle_deg >= 45 && completion.corner_angle_deg < 90)) {
    Fail("pipeline: completion.corner_angle_deg must be in [45, 90), got " +
         std::to_string(completion.corner_angle_deg));
  }
  const auto& c = completion;
  if (!(c.face_max_thickness_m >= 0 && c.face_max_aspect >= 0 && c.face_max_aspect <= 1 &&
        c.face_max_obliquity_deg >= 0 && c.face_max_obliquity_deg < 90 && c.face_min_score >= 0 &&
        c.face_min_score <= 1)) {
    Fail("pipeline: completion.face_* out of range (thickness " + std::to_string(c.face_max_thickness_m) +
         " m >= 0, aspect " + std::to_string(c.face_max_aspect) + " in [0, 1], obliquity " +
         std::to_string(c.face_max_obliquity_deg) + " deg in [0, 90), min score " +
         std::to_string(c.face_min_score) + " in [0, 1])");
  }
  sgm.Validate();
  fusion.Validate();
  ground.Validate();
  segmentation.Validate();
  tracker.Validate();
  parking.Validate();
  bay_edges.Validate();
  bay_row.Validate();
  if (!(bay_strip_margin_m >= 0)) {
    Fail("pipeline: bay_strip_margin_m must be >= 0, got " + std::to_string(bay_strip_margin_m));
  }
  const std::pair<const char*, double> bay_lengths[] = {
      {"bay_front_m", bay_front_m},
      {"bay_face_depth_m", bay_face_depth_m},
      {"bay_snap_min_width_m", bay_snap_min_width_m},
      {"bay_snap_min_offset_m", bay_snap_min_offset_m},
      {"bay_snap_min_off_deg", bay_snap_min_off_deg},
      {"bay_snap_max_face_m", bay_snap_max_face_m},
      {"bay_snap_ground_ratio", bay_snap_ground_ratio},
      {"bay_face_front_tolerance_m", bay_face_front_tolerance_m},
      {"bay_face_min_spread_m", bay_face_min_spread_m},
      {"bay_face_width_slack_m", bay_face_width_slack_m},
      {"bay_face_min_range_m", bay_face_min_range_m},
      {"bay_face_max_ground_ratio", bay_face_max_ground_ratio}};
  for (const auto& [name, value] : bay_lengths) {
    if (!(std::isfinite(value) && value >= 0)) Fail(std::string("pipeline: ") + name + " must be finite and >= 0, got " + std::to_string(value));
  }
  if (!(bay_snap_max_width_m >= bay_snap_min_width_m && std::isfinite(bay_snap_max_width_m))) {
    Fail("pipeline: bay_snap_max_width_m must be finite and >= bay_snap_min_width_m (" +
         std::to_string(bay_snap_min_width_m) + "), got " + std::to_string(bay_snap_max_width_m));
  }
  if (!(bay_face_score > 0 && bay_face_score <= 1)) {
    Fail("pipeline: bay_face_score must be in (0, 1], got " + std::to_string(bay_face_score));
  }
}

class Pipeline::Impl {
 public:
  Impl(const drivers::Calibration& c, const PipelineParams& p)
      : calibration(c),
        params(p),
        atlas(objects::Atlas::Load(p.atlas_path.empty() ? objects::Atlas::DefaultPath() : p.atlas_path)),
        tracker(atlas, p.tracker),
        slots(p.parking),
        stereo(c, StereoParamsOf(p), p.threads) {
    for (const std::string& name : p.fragment_merge_classes) merge_classes.push_back(atlas.Require(name));
    for (const std::string& name : p.stacked_merge_classes) stacked_classes.push_back(atlas.Require(name));
  }

  // Drops a remembered car with the record of how much of it was seen (a track remembered again
  // starts afresh).
  std::map<int, objects::Detection>::iterator ForgetParkedCar(std::map<int, objects::Detection>::iterator it) {
    parked_view_area.erase(it->first);
    parked_from_steady_view.erase(it->first);
    return parked.erase(it);
  }
  // Two car detections (one frame) are of one car when their centres lie within half the longer.
  static bool SameCar(const objects::Detection& a, const objects::Detection& b) {
    return (a.xy_m - b.xy_m).norm() < 0.5 * std::max(a.length_m, b.length_m);
  }
  // Remembers the static car tracks seen as cars now (PipelineParams::parked_*).
  void RememberParkedCars(const FrameResult& r, const std::vector<objects::Track>& tracks,
                          const std::vector<objects::Detection>& detections) {
    if (params.parked_free_ground_points <= 0 || car_class < 0) return;
    for (const objects::Track& tr : tracks) {
      const int i = tr.detection_index;
      if (tr.state != objects::TrackState::kConfirmed || i < 0 || tr.merged || tr.class_index != car_class ||
          detections[static_cast<std::size_t>(i)].classification.class_index != car_class) {
        continue;
      }
      const auto index = static_cast<std::size_t>(i);
      const double speed = tr.velocity_mps.norm();
      const bool steady = speed <= params.parked_max_speed_mps;
      if (!steady && (params.parked_speed_per_depth_spread <= 0.0 ||
                      speed > params.parked_max_speed_mps +
                                  params.parked_speed_per_depth_spread *
                                      DepthSpread(r.cloud.sigma_z_m, r.blobs[index], params.box_trim_fraction))) {
        continue;
      }
      objects::Detection car = detections[index];
      car.xy_m = tr.xy_m;  // the track's filtered position: steadier than one view
      const double view_area =
          static_cast<double>(r.blobs[index].size()) * r.boxes[index].center.head<2>().squaredNorm();
      const auto most_seen = parked_view_area.find(tr.id);
      if (most_seen != parked_view_area.end() && view_area < params.parked_keep_view_fraction * most_seen->second) {
        continue;
      }
      if (!steady && parked_from_steady_view.count(tr.id) > 0) continue;
      // A track seen far from where it was remembered has jumped to another car (coasting tracks
      // take the blobs of cars they pass): the car remembered stays, and this one is not
      // remembered under that track.
      const auto remembered = parked.find(tr.id);
      if (remembered != parked.end() && !SameCar(remembered->second, car)) {
        continue;
      }
      // The same car remembered under an earlier track (an ID switch, or a replay looping back)
      // is replaced, not listed twice.
      for (auto it = parked.begin(); it != parked.end();) {
        const bool same_car = it->first != tr.id && SameCar(it->second, car);
        it = same_car ? ForgetParkedCar(it) : std::next(it);
      }
      parked[tr.id] = car;
      parked_view_area[tr.id] = std::max(view_area, parked_view_area[tr.id]);
      if (steady) parked_from_steady_view.insert(tr.id);
    }
  }

  // The remembered cars (track id, world frame) not among this frame's car obstacles while the
  // ground under them stays unseen; the others are forgotten.
  std::vector<std::pair<int, objects::Detection>> HiddenParkedCars(const FrameResult& r) {
    std::vector<std::pair<int, objects::Detection>> hidden;
    const Eigen::Isometry3d T_vehicle_world = r.T_world_vehicle.inverse();
    // Every blob's points, gathered only once a memory shows ground (most frames none does).
    std::vector<int> object_points;
    auto objects_inside = [&](const Eigen::Vector2d& xy, double yaw, double half_length, double half_width) {
      if (object_points.empty()) {
        for (const auto& blob : r.blobs) object_points.insert(object_points.end(), blob.begin(), blob.end());
      }
      return PointsInsideFootprint(r.cloud, object_points, xy, yaw, half_length, half_width);
    };
    for (auto it = parked.begin(); it != parked.end();) {
      const objects::Detection& d = it->second;  // a car: only cars are remembered
      const std::string& car_name = atlas.classes()[static_cast<std::size_t>(d.classification.class_index)].name;
      const Eigen::Vector2d xy = (T_vehicle_world * Eigen::Vector3d(d.xy_m.x(), d.xy_m.y(), 0.0)).head<2>();
      const double yaw = d.yaw_rad - r.ego_world.yaw_rad;
      const double m = params.parked_footprint_margin_m;
      const int ground = GroundPointsInside(r, xy, yaw, d.length_m, d.width_m, m);
      // Ground "inside" a car whose faces are seen now is stereo's mismatches low on its side
      // beside the vehicle, not the car gone (PipelineParams::parked_standing_points_ratio).
      const bool ground_seen =
          ground >= params.parked_free_ground_points &&
          !(params.parked_standing_points_ratio > 0.0 &&
            objects_inside(xy, yaw, 0.5 * d.length_m + m, 0.5 * d.width_m + m) >=
                params.parked_standing_points_ratio * ground);
      if (ground_seen || xy.norm() > params.parked_max_range_m) {
        it = ForgetParkedCar(it);
        continue;
      }
      // (by place, not track id: a track that jumped to another car does not show this one)
      if (!MeasuredWithin(r.obstacles.obstacles, car_name, xy, 0.5 * d.length_m)) hidden.emplace_back(*it);
      ++it;
    }
    return hidden;
  }

  // Car detections (world frame) lying within a remembered parked car whose box disagrees with
  // it take the remembered footprint (PipelineParams::parked_prefer_*); @p boxes (vehicle frame)
  // follow.
  void PreferRememberedFootprints(const FrameResult& r, std::vector<objects::Box3>* boxes,
                                  std::vector<objects::Detection>* detections) const {
    if (params.parked_prefer_fraction > 1.0 || parked.empty()) return;
    const Eigen::Isometry3d T_vehicle_world = r.T_world_vehicle.inverse();
    const double m = params.parked_footprint_margin_m;
    const double mean_car_width = atlas.classes()[static_cast<std::size_t>(car_class)].width.mean_m;
    std::vector<int> taken(detections->size(), -1);  // the remembered car each detection lies in
    for (std::size_t i = 0; i < detections->size(); ++i) {
      const objects::Detection& d = (*detections)[i];
      // (the blob's nearest point last: the one test that walks its points)
      if (d.classification.class_index != car_class ||
          std::any_of(parked.begin(), parked.end(), [&](const auto& entry) {
            return (entry.second.xy_m - d.xy_m).norm() <= params.parked_prefer_offset_m;
          }) ||
          NearestRange(r.cloud, r.blobs[i]) > params.parked_prefer_max_range_m) {
        continue;
      }
      for (const auto& [id, car] : parked) {
        const Eigen::Vector2d xy = (T_vehicle_world * Eigen::Vector3d(car.xy_m.x(), car.xy_m.y(), 0.0)).head<2>();
        // A memory narrower than the Atlas car was a partial view: its side may lie beyond it.
        const double width = std::max(car.width_m, mean_car_width);
        const int inside = PointsInsideFootprint(r.cloud, r.blobs[i], xy, car.yaw_rad - r.ego_world.yaw_rad,
                                                 0.5 * car.length_m + m, 0.5 * width + m);
        if (inside < params.parked_prefer_fraction * static_cast<double>(r.blobs[i].size())) continue;
        taken[i] = id;
        break;
      }
    }
    for (std::size_t i = 0; i < detections->size(); ++i) {
      // Two cars measured inside one remembered footprint: the memory is wrong (a box across two
      // neighbours' ends), not both measurements.
      if (taken[i] < 0 || std::count(taken.begin(), taken.end(), taken[i]) > 1) continue;
      objects::Detection& d = (*detections)[i];
      const objects::Detection& car = parked.at(taken[i]);
      const Eigen::Vector2d xy = (T_vehicle_world * Eigen::Vector3d(car.xy_m.x(), car.xy_m.y(), 0.0)).head<2>();
      objects::Box3& box = (*boxes)[i];
      const float yaw = static_cast<float>(car.yaw_rad - r.ego_world.yaw_rad);
      box.center.head<2>() = xy.cast<float>();
      box.size = Eigen::Vector3f(static_cast<float>(car.length_m), static_cast<float>(car.width_m), box.size.z());
      SetYaw(&box, yaw, box.axes.col(2));
      const objects::Classification cls = d.classification;
      d = car;
      d.classification = cls;
    }
  }

  // A box as FitVerticalBox gives it, or along its de-noised heading when depth noise dominates.
  objects::Box3 FitBox(const PointCloud& cloud, const std::vector<int>& blob, const Eigen::Vector3f& up,
                       std::optional<float> hint, const Eigen::Vector2f& viewer) const {
    if (auto heading = objects::DenoisedHeading(cloud.xyz, cloud.sigma_z_m, blob, viewer,
                                                params.noise_dominated_fraction)) {
      return objects::FitVerticalBoxAtHeading(cloud.xyz, blob, up, *heading, params.box_trim_fraction);
    }
    const objects::Box3 smallest = objects::FitVerticalBox(cloud.xyz, blob, up, hint, params.box_trim_fraction);
    if (params.edge_heading_min_length_m <= 0.0 || smallest.size.x() < params.edge_heading_min_length_m) {
      return smallest;
    }
    return objects::FitVerticalBox(cloud.xyz, blob, up, hint, params.box_trim_fraction,
                                   objects::HeadingCriterion::kEdgeCloseness);
  }

  // What a box is seen as: on the ground, its class and completed box from the viewer; floating
  // above it (stereo mismatches, overhangs), unknown and as measured.
  struct Seen {
    bool on_ground = false;
    double depth_spread_m = 0.0;
    objects::ViewedBox viewed;
    bool framed = false;  // cut off by nearer objects at both ends: its extents are no evidence
    bool part_of_parked_car = false;  // a piece of a remembered parked car hidden now
  };
  Seen See(const FrameResult& r, const objects::Box3& box, const std::vector<int>& blob,
           const Eigen::Vector2f& viewer) const {
    Seen seen;
    seen.viewed.box = box;
    seen.viewed.classification = {atlas.unknown_index(), 1.0};
    seen.on_ground = objects::HeightAboveGround(box, r.ground_plane) <= params.max_ground_gap_m;
    if (!seen.on_ground) return seen;
    seen.depth_spread_m = DepthSpread(r.cloud.sigma_z_m, blob, params.box_trim_fraction);
    seen.viewed = objects::ClassifyFromViewpoint(atlas, box, viewer, params.completion, seen.depth_spread_m);
    return seen;
  }
  // Pedestrian detections (world frame) inside a remembered parked car, or within
  // parked_pieces_margin_m around it where no walker stood, are pieces of its end broken up by
  // stereo (PipelineParams::parked_pieces_*): of no class, and their tracks' votes do not make
  // them people.
  void UnclassifyPiecesOfParkedCars(std::vector<objects::Detection>* detections, std::vector<Seen>* seen) const {
    if (!params.parked_pieces_unclassified || pedestrian_class < 0) return;
    const double margin = params.parked_pieces_margin_m;
    for (const auto& [car_id, car] : parked) {
      for (std::size_t i = 0; i < detections->size(); ++i) {
        objects::Detection& d = (*detections)[i];
        if (d.classification.class_index != pedestrian_class) continue;
        const Eigen::Vector2d offset = d.xy_m - car.xy_m;
        const bool inside = InsideFootprint(offset, car.yaw_rad, 0.5 * car.length_m, 0.5 * car.width_m);
        const bool around =
            InsideFootprint(offset, car.yaw_rad, 0.5 * car.length_m + margin, 0.5 * car.width_m + margin);
        if (!inside && (!around || WalkerNear(d.xy_m))) continue;
        d.classification = {atlas.unknown_index(), 0.0};
        (*seen)[i].part_of_parked_car = true;
      }
    }
  }

  // Whether a pedestrian track that has walked parked_pieces_walked_m from where it began stood
  // within a person's stride (Atlas length max) of @p xy (world frame) last frame: a person who came
  // up to a parked car, not a piece of it.
  bool WalkerNear(const Eigen::Vector2d& xy) const {
    const double stride = atlas.classes()[static_cast<std::size_t>(pedestrian_class)].length.max_m;
    return std::any_of(walkers.begin(), walkers.end(),
                       [&](const Eigen::Vector2d& w) { return (w - xy).norm() <= stride; });
  }
  // Remembers where each track began and which pedestrian tracks have walked (WalkerNear).
  void NoteWalkers(const std::vector<objects::Track>& tracks) {
    std::map<int, Eigen::Vector2d> began;
    walkers.clear();
    for (const objects::Track& tr : tracks) {
      const auto it = track_began.find(tr.id);
      const Eigen::Vector2d start = it != track_began.end() ? it->second : tr.xy_m;
      began.emplace(tr.id, start);
      if (tr.class_index == pedestrian_class && (tr.xy_m - start).norm() >= params.parked_pieces_walked_m) {
        walkers.push_back(tr.xy_m);
      }
    }
    track_began = std::move(began);
  }

  // @p box (measured) from the ground up, when its footprint can be a person's (Atlas length within
  // bounds, width up to the most) and its top is no higher than a person is tall: a person partly
  // seen (PipelineParams::pedestrian_tracks_keep_partial_views).
  std::optional<objects::Box3> PartlySeenPerson(const FrameResult& r, const Eigen::Vector3f& up,
                                                const objects::Box3& box) const {
    const objects::ObjectClass& person = atlas.classes()[static_cast<std::size_t>(pedestrian_class)];
    const float bottom = objects::HeightAboveGround(box, r.ground_plane);
    const float top = bottom + box.size.z();
    if (!person.length.Contains(box.size.x()) || box.size.y() > person.width.max_m || top > person.height.max_m ||
        !(top > 0.f)) {
      return std::nullopt;
    }
    objects::Box3 out = box;
    out.center -= up * (0.5f * bottom);
    out.size.z() = top;
    return out;
  }

  // Whether one of @p a, @p b stands on the ground and the other floats above it, less than
  // PipelineParams::stacked_merge_gap_m over it (legs and a torso).
  bool Stacked(const FrameResult& r, const objects::Box3& a, const objects::Box3& b) const {
    const float bottom_a = objects::HeightAboveGround(a, r.ground_plane);
    const float bottom_b = objects::HeightAboveGround(b, r.ground_plane);
    const bool a_lower = bottom_a <= bottom_b;
    const float lower_bottom = a_lower ? bottom_a : bottom_b, upper_bottom = a_lower ? bottom_b : bottom_a;
    const float lower_height = (a_lower ? a : b).size.z();
    return lower_bottom <= params.max_ground_gap_m && upper_bottom > params.max_ground_gap_m &&
           upper_bottom - (lower_bottom + lower_height) <= params.stacked_merge_gap_m;
  }
  // @p box reaching down to the ground when it floats just above it (ground_contact_gap_m).
  objects::Box3 OnGround(const FrameResult& r, const objects::Box3& box) const {
    return objects::StandOnGround(box, r.ground_plane, static_cast<float>(params.ground_contact_gap_m));
  }
  // The box of @p blob, standing on the ground, seen from @p viewer.
  objects::Box3 FitStandingBox(const FrameResult& r, const std::vector<int>& blob, const Eigen::Vector3f& up,
                               const Eigen::Vector2f& viewer) const {
    return OnGround(r, FitBox(r.cloud, blob, up, std::nullopt, viewer));
  }
  bool OfNoClass(const Seen& seen) const { return seen.viewed.classification.class_index == atlas.unknown_index(); }
  bool Unclassified(const Seen& seen) const { return seen.on_ground && OfNoClass(seen); }

  // Merges pairs of blobs of no class that make a car side by side (PipelineParams::
  // fragment_merge_*), then pairs that make a person one above the other (stacked_merge_*), until
  // none is left; @p viewers and @p seen follow the boxes. Cars go first: a car's end broken into
  // bumper and rear window also stacks into something person-sized.
  void MergeFragments(FrameResult& r, const Eigen::Vector3f& up, std::vector<Eigen::Vector2f>* viewers,
                      std::vector<Seen>* seen) const {
    auto is_one_of = [](const std::vector<int>& classes, int c) {
      return std::find(classes.begin(), classes.end(), c) != classes.end();
    };
    if (params.fragment_merge_gap_m > 0.0) {
      MergePairs(r, up, viewers, seen, [&](std::size_t i, std::size_t j) {
        if (!Unclassified((*seen)[i]) || !Unclassified((*seen)[j])) return false;
        // Centre distance less both half diagonals: a lower bound of the footprints' gap.
        const float gap = (r.boxes[i].center.head<2>() - r.boxes[j].center.head<2>()).norm() -
                          0.5f * (r.boxes[i].size.head<2>().norm() + r.boxes[j].size.head<2>().norm());
        return gap <= params.fragment_merge_gap_m;
      }, [&](const objects::Box3&, const Seen& u) {
        return is_one_of(merge_classes, u.viewed.classification.class_index);
      });
    }
    if (params.stacked_merge_xy_m > 0.0) {
      // A torso floats above the ground until joined to its legs: of no class, on the ground or not.
      MergePairs(r, up, viewers, seen, [&](std::size_t i, std::size_t j) {
        return OfNoClass((*seen)[i]) && OfNoClass((*seen)[j]) &&
               (r.boxes[i].center.head<2>() - r.boxes[j].center.head<2>()).norm() <= params.stacked_merge_xy_m &&
               Stacked(r, r.boxes[i], r.boxes[j]);
      }, [&](const objects::Box3& box, const Seen& u) {
        // Pieces of no class joined are a guess: the stack must stand the class's typical height
        // (within a sigma of its mean; height is a person's steady extent).
        const int c = u.viewed.classification.class_index;
        if (!is_one_of(stacked_classes, c)) return false;
        const objects::SizePrior& height = atlas.classes()[static_cast<std::size_t>(c)].height;
        return box.size.z() >= height.mean_m - height.sigma_m;
      });
    }
  }

  // Merges pairs (i, j) of blobs that @p may_merge until none is left whose union, on the ground,
  // is what @p union_is_one accepts; @p viewers and @p seen follow the boxes.
  template <typename MayMerge, typename UnionIsOne>
  void MergePairs(FrameResult& r, const Eigen::Vector3f& up, std::vector<Eigen::Vector2f>* viewers,
                  std::vector<Seen>* seen, MayMerge may_merge, UnionIsOne union_is_one) const {
    for (bool merged = true; merged;) {
      merged = false;
      for (std::size_t i = 0; i < r.boxes.size() && !merged; ++i) {
        for (std::size_t j = i + 1; j < r.boxes.size() && !merged; ++j) {
          if (!may_merge(i, j)) continue;
          std::vector<int> blob = r.blobs[i];
          blob.insert(blob.end(), r.blobs[j].begin(), r.blobs[j].end());
          const objects::Box3 box = FitStandingBox(r, blob, up, (*viewers)[i]);
          Seen union_seen = See(r, box, blob, (*viewers)[i]);
          if (!union_seen.on_ground || !union_is_one(box, union_seen)) continue;
          r.boxes[i] = box;
          r.blobs[i] = std::move(blob);
          (*seen)[i] = std::move(union_seen);
          const auto at = static_cast<std::ptrdiff_t>(j);
          r.boxes.erase(r.boxes.begin() + at);
          r.blobs.erase(r.blobs.begin() + at);
          viewers->erase(viewers->begin() + at);
          seen->erase(seen->begin() + at);
          merged = true;
        }
      }
    }
  }

  // Whether the ends of blob @p i at its smaller and larger azimuth, seen from @p viewer, meet
  // objects nearer by PipelineParams::framed_occluder_margin_m within framed_end_gap_deg beyond.
  std::array<bool, 2> FramedEnds(const FrameResult& r, std::size_t i, const Eigen::Vector2f& viewer_f) const {
    const double gap_rad = params.framed_end_gap_deg * kPi / 180.0;
    // Azimuths relative to the blob's centre direction (no wrap-around for anything in view).
    const Eigen::Vector2d viewer = viewer_f.cast<double>();
    const Eigen::Vector2d to_centre = r.boxes[i].center.head<2>().cast<double>() - viewer;
    const double centre_azimuth = std::atan2(to_centre.y(), to_centre.x());
    auto polar = [&](int point) {
      const Eigen::Vector2d d = r.cloud.xyz.col(point).head<2>().cast<double>() - viewer;
      return std::pair<double, double>{std::remainder(std::atan2(d.y(), d.x()) - centre_azimuth, 2.0 * kPi), d.norm()};
    };
    double azimuth_at[2] = {kPi, -kPi}, range_at[2] = {0.0, 0.0}, farthest = 0.0;
    for (int p : r.blobs[i]) {
      const auto [azimuth, range] = polar(p);
      for (int e = 0; e < 2; ++e) {
        if (e == 0 ? azimuth < azimuth_at[0] : azimuth > azimuth_at[1]) {
          azimuth_at[e] = azimuth;
          range_at[e] = range;
        }
      }
      farthest = std::max(farthest, range);
    }
    int framing[2] = {0, 0};
    for (std::size_t j = 0; j < r.blobs.size(); ++j) {
      if (j == i || (r.boxes[j].center.head<2>().cast<double>() - viewer).norm() > farthest) continue;
      for (int p : r.blobs[j]) {
        const auto [azimuth, range] = polar(p);
        framing[0] += azimuth >= azimuth_at[0] - gap_rad && azimuth <= azimuth_at[0] &&
                      range < range_at[0] - params.framed_occluder_margin_m;
        framing[1] += azimuth <= azimuth_at[1] + gap_rad && azimuth >= azimuth_at[1] &&
                      range < range_at[1] - params.framed_occluder_margin_m;
      }
    }
    constexpr int kMinFramingPoints = 10;  // a few stray matches do not frame anything
    return {framing[0] >= kMinFramingPoints, framing[1] >= kMinFramingPoints};
  }

  // Unclassifies car-classed blobs whose length nearer objects cut off at both ends
  // (PipelineParams::framed_*).
  void UnclassifyFramedFaces(const FrameResult& r, const std::vector<Eigen::Vector2f>& viewers,
                             std::vector<Seen>* seen) const {
    if (params.framed_min_length_m <= 0.0 || car_class < 0) return;
    for (std::size_t i = 0; i < r.boxes.size(); ++i) {
      Seen& face = (*seen)[i];
      if (face.viewed.classification.class_index != car_class || r.boxes[i].size.x() < params.framed_min_length_m) {
        continue;
      }
      const std::array<bool, 2> framed = FramedEnds(r, i, viewers[i]);
      if (framed[0] && framed[1]) {
        face.viewed.classification = {atlas.unknown_index(), 0.0};
        face.viewed.box = r.boxes[i];
        face.framed = true;
      }
    }
  }

  // The heading of the row of parked cars car @p i stands in (PipelineParams::row_align_*): across
  // the line through the most measured car centres near it, if enough lie on one.
  std::optional<double> RowHeading(const FrameResult& r, const std::vector<std::size_t>& cars, std::size_t i) const {
    const Eigen::Vector2d ci = r.boxes[i].center.head<2>().cast<double>();
    std::vector<Eigen::Vector2d> near;
    for (std::size_t j : cars) {
      const Eigen::Vector2d cj = r.boxes[j].center.head<2>().cast<double>();
      if ((cj - ci).norm() <= params.row_align_radius_m) near.push_back(cj);
    }
    // The line through this car and another holding the most others (the row across the aisle
    // and odd boxes are not on it), then refined by the inliers' principal axis.
    std::vector<Eigen::Vector2d> row;
    for (const Eigen::Vector2d& cj : near) {
      if ((cj - ci).norm() < 1e-6) continue;
      const Eigen::Vector2d normal = Eigen::Vector2d(-(cj - ci).y(), (cj - ci).x()).normalized();
      std::vector<Eigen::Vector2d> on_line;
      for (const Eigen::Vector2d& ck : near) {
        if (std::abs(normal.dot(ck - ci)) <= params.row_align_max_offset_m) on_line.push_back(ck);
      }
      if (on_line.size() > row.size()) row = std::move(on_line);
    }
    if (static_cast<int>(row.size()) < params.row_align_min_cars) return std::nullopt;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& c : row) mean += c / static_cast<double>(row.size());
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector2d& c : row) scatter += (c - mean) * (c - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
    const Eigen::Vector2d along = eigen.eigenvectors().col(1);
    std::vector<double> positions;
    for (const Eigen::Vector2d& c : row) positions.push_back(along.dot(c));
    std::sort(positions.begin(), positions.end());
    double spacing = std::numeric_limits<double>::infinity();
    for (std::size_t k = 1; k < positions.size(); ++k) spacing = std::min(spacing, positions[k] - positions[k - 1]);
    const objects::SizePrior& length = atlas.classes()[static_cast<std::size_t>(car_class)].length;
    // Closer than a car is long: side by side, not one behind the other.
    if (spacing >= length.mean_m - length.sigma_m) return std::nullopt;
    return std::atan2(along.y(), along.x()) + kPi / 2;
  }

  // Ground points inside a footprint (vehicle frame) less @p margin_m all round.
  static int GroundPointsInside(const FrameResult& r, const Eigen::Vector2d& xy, double yaw, double length_m,
                                double width_m, double margin_m) {
    return PointsInsideFootprint(r.cloud, r.ground_indices, xy, yaw, 0.5 * length_m - margin_m,
                                 0.5 * width_m - margin_m);
  }
  // Whether at least @p min_points of them show: nothing stands there.
  static bool GroundShows(const FrameResult& r, const Eigen::Vector2d& xy, double yaw, double length_m,
                          double width_m, double margin_m, int min_points) {
    return GroundPointsInside(r, xy, yaw, length_m, width_m, margin_m) >= min_points;
  }

  // Far cars boxed off the heading of the row they stand in are refitted and completed along it
  // (PipelineParams::row_align_*); the measured boxes (r.boxes) follow.
  void AlignCarsToRow(FrameResult& r, const Eigen::Vector3f& up, const std::vector<Eigen::Vector2f>& viewers,
                      std::vector<Seen>* seen) const {
    if (params.row_align_min_cars <= 0 || car_class < 0) return;
    std::vector<std::size_t> cars;
    for (std::size_t i = 0; i < r.boxes.size(); ++i) {
      const Seen& v = (*seen)[i];
      if (v.on_ground && !v.framed && v.viewed.classification.class_index == car_class) cars.push_back(i);
    }
    const double min_off = params.row_align_min_off_deg * kPi / 180.0;
    // Every row is read off the boxes as measured; the refits are applied after.
    std::vector<std::pair<std::size_t, objects::Box3>> refits;
    std::vector<objects::ViewedBox> completed;
    for (std::size_t i : cars) {
      if ((r.boxes[i].center.head<2>() - viewers[i]).norm() < params.row_align_min_range_m) continue;
      const std::optional<double> heading = RowHeading(r, cars, i);
      if (!heading || AxisAngle((*seen)[i].viewed.box.yaw_rad, *heading) <= min_off) continue;
      const auto agreeing = std::count_if(cars.begin(), cars.end(), [&](std::size_t j) {
        return j != i &&
               (r.boxes[j].center.head<2>() - r.boxes[i].center.head<2>()).norm() <= params.row_align_radius_m &&
               AxisAngle((*seen)[j].viewed.box.yaw_rad, *heading) <= min_off;
      });
      if (agreeing < params.row_align_min_agreeing) continue;
      const objects::Box3 refit = objects::FitVerticalBoxAtHeading(r.cloud.xyz, r.blobs[i], up,
                                                                   static_cast<float>(*heading), params.box_trim_fraction);
      const objects::ViewedBox viewed = objects::CompleteAsClass(atlas, car_class, refit, viewers[i], params.completion,
                                                                 (*seen)[i].depth_spread_m, *heading);
      const objects::Box3& b = viewed.box;
      if (viewed.classification.class_index != car_class ||
          GroundShows(r, b.center.head<2>().cast<double>(), b.yaw_rad, b.size.x(), b.size.y(),
                      params.row_align_free_ground_margin_m, params.row_align_free_ground_points)) {
        continue;
      }
      refits.emplace_back(i, refit);
      completed.push_back(viewed);
    }
    for (std::size_t k = 0; k < refits.size(); ++k) {
      r.boxes[refits[k].first] = refits[k].second;
      (*seen)[refits[k].first].viewed = completed[k];
    }
  }

  // Cars placed by the paint of the row they stand in (PipelineParams::bays_from_paint).
  void PlaceCarsInRow(FrameResult& r, const Eigen::Vector3f& up, std::vector<Eigen::Vector2f>* viewers,
                      std::vector<Seen>* seen) const {
    if (!params.bays_from_paint || car_class < 0) return;
    const std::optional<mapping::BayRow> row = mapping::FindBayRow(r.cloud, r.ground_indices, params.bay_row);
    if (!row) return;
    SplitPairsInAisle(r, up, *row, viewers, seen);
    SplitRowFaces(r, up, *row, viewers, seen);
    SnapCarsToBays(r, up, *row, seen);
    CompleteFacesInRow(r, up, *row, seen);
  }

  // A blob's points as (along the row, depth into the bays).
  static std::vector<Eigen::Vector2d> RowPoints(const FrameResult& r, const std::vector<int>& blob,
                                                const mapping::BayRow& row) {
    std::vector<Eigen::Vector2d> out;
    out.reserve(blob.size());
    for (int p : blob) {
      const Eigen::Vector2d xy = r.cloud.xyz.col(p).head<2>().cast<double>();
      out.emplace_back(row.Along(xy), row.Depth(xy));
    }
    return out;
  }

  // Where a blob's face toward the aisle is: its front (10th percentile depth) and its span along
  // the row (5th to 95th percentile) over the points within bay_face_depth_m behind that front.
  struct RowFace {
    double front_m = 0.0;
    double lo_m = 0.0;
    double hi_m = 0.0;
    double spread_m() const { return hi_m - lo_m; }
  };
  RowFace FaceOf(const std::vector<Eigen::Vector2d>& points) const {
    std::vector<double> depths, alongs;
    for (const Eigen::Vector2d& q : points) depths.push_back(q.y());
    RowFace face;
    face.front_m = Percentile(depths, 0.1);
    for (const Eigen::Vector2d& q : points) {
      if (q.y() <= face.front_m + params.bay_face_depth_m) alongs.push_back(q.x());
    }
    face.lo_m = Percentile(alongs, 0.05);
    face.hi_m = Percentile(alongs, 0.95);
    return face;
  }

  // The widest a car's end seen at the row's front may be: the Atlas car width max plus
  // bay_face_width_slack_m.
  double WidestCarEnd() const {
    return atlas.classes()[static_cast<std::size_t>(car_class)].width.max_m + params.bay_face_width_slack_m;
  }

  // Whether @p face's front lies on the row's front line, from bay_face_front_tolerance_m before it
  // to bay_front_m behind it.
  bool AtRowFront(const RowFace& face) const {
    return face.front_m >= -params.bay_face_front_tolerance_m && face.front_m <= params.bay_front_m;
  }

  // @p box moved to @p xy (vehicle frame), its footprint @p length_m x @p width_m, turned to
  // @p yaw_rad about @p up.
  static void PlaceBox(objects::Box3* box, const Eigen::Vector2d& xy, double yaw_rad, double length_m,
                       double width_m, const Eigen::Vector3f& up) {
    box->center.head<2>() = xy.cast<float>();
    box->size.head<2>() = Eigen::Vector2f(static_cast<float>(length_m), static_cast<float>(width_m));
    SetYaw(box, static_cast<float>(yaw_rad), up);
  }

  // The bay between two separators (along the row) a car's width apart (bay_snap_*_width_m) where
  // most of a blob's front part (@p points as RowPoints) lies; nullopt where none holds most.
  std::optional<std::pair<double, double>> BayHolding(const std::vector<Eigen::Vector2d>& points,
                                                      const mapping::BayRow& row) const {
    const std::vector<double>& seps = row.separators_m;
    std::vector<Eigen::Vector2d> front;
    for (const Eigen::Vector2d& q : points) {
      if (q.y() <= params.bay_front_m) front.push_back(q);
    }
    const std::vector<Eigen::Vector2d>& deciding = front.empty() ? points : front;
    std::size_t best_bay = seps.size();
    std::ptrdiff_t best_count = 0;
    for (std::size_t k = 0; k + 1 < seps.size(); ++k) {
      const double bay_width = seps[k + 1] - seps[k];
      if (bay_width < params.bay_snap_min_width_m || bay_width > params.bay_snap_max_width_m) continue;
      const auto count = std::count_if(deciding.begin(), deciding.end(), [&](const Eigen::Vector2d& q) {
        return q.x() >= seps[k] && q.x() < seps[k + 1];
      });
      if (count > best_count) {
        best_count = count;
        best_bay = k;
      }
    }
    if (best_bay == seps.size() || 2 * best_count <= static_cast<std::ptrdiff_t>(deciding.size())) return std::nullopt;
    return std::make_pair(seps[best_bay], seps[best_bay + 1]);
  }

  // Car boxes whose front part lies in one bay between two separators, but off its centre line or
  // its heading, are moved onto it; car boxes off the bays' heading where no bay is seen are turned
  // to it and centred on their face (PipelineParams::bay_snap_*).
  void SnapCarsToBays(FrameResult& r, const Eigen::Vector3f& up, const mapping::BayRow& row,
                      std::vector<Seen>* seen) const {
    const objects::ObjectClass& car = atlas.classes()[static_cast<std::size_t>(car_class)];
    const double bay_heading = row.HeadingRad();
    for (std::size_t i = 0; i < r.boxes.size(); ++i) {
      Seen& v = (*seen)[i];
      if (!v.on_ground || v.framed || v.viewed.classification.class_index != car_class) continue;
      objects::Box3& box = v.viewed.box;
      const Eigen::Vector2d centre = box.center.head<2>().cast<double>();
      const double centre_depth = row.Depth(centre);
      if (centre_depth < 0.0 || centre_depth > car.length.max_m) continue;  // not in this row
      const std::vector<Eigen::Vector2d> points = RowPoints(r, r.blobs[i], row);
      const std::optional<std::pair<double, double>> bay = BayHolding(points, row);
      const bool off_heading = AxisAngle(box.yaw_rad, bay_heading) > params.bay_snap_min_off_deg * kPi / 180.0;
      const double length = std::max(box.size.x(), box.size.y());
      double width = std::min(box.size.x(), box.size.y());
      // Seen far off, the face is smeared along the sight line, and the box with it; the face's far
      // end is never hidden, its near end rarely: its middle is the car's. In a bay, it is kept
      // within the bay's lines: a bay beside a free one is wider than its car on that side, so its
      // centre line is no car's.
      const RowFace face = FaceOf(points);
      double lateral = 0.5 * (face.lo_m + face.hi_m);
      if (bay) {
        const auto [lo, hi] = *bay;
        width = std::min(width, hi - lo);
        lateral = std::clamp(lateral, lo + 0.5 * width, hi - 0.5 * width);
        if (std::abs(row.Along(centre) - lateral) <= params.bay_snap_min_offset_m && !off_heading) continue;
      } else {
        if (!off_heading || face.spread_m() > params.bay_snap_max_face_m) continue;  // (several cars' faces)
        width = std::min(width, car.width.mean_m);
      }
      std::vector<double> depths;
      for (const Eigen::Vector2d& q : points) {
        if (std::abs(q.x() - lateral) <= 0.5 * width) depths.push_back(q.y());
      }
      if (depths.empty()) continue;
      const double yaw = std::remainder(
          std::cos(box.yaw_rad - bay_heading) >= 0.0 ? bay_heading : bay_heading + kPi, 2.0 * kPi);
      const double front_depth = std::max(0.0, Percentile(depths, 0.1));
      const Eigen::Vector2d xy = row.origin + lateral * row.along + (front_depth + 0.5 * length) * row.into_bays;
      // Far off, stereo smears ground into any car's footprint: only more of it than the box as
      // seen held says the place is free.
      const int ground = GroundPointsInside(r, xy, yaw, length, width, params.row_align_free_ground_margin_m);
      if (ground >= params.row_align_free_ground_points &&
          ground > params.bay_snap_ground_ratio *
                       GroundPointsInside(r, centre, box.yaw_rad, box.size.x(), box.size.y(),
                                          params.row_align_free_ground_margin_m)) {
        continue;
      }
      PlaceBox(&box, xy, yaw, length, width, up);
    }
  }

  // A pedestrian-tall blob standing in the aisle (PipelineParams::aisle_pair_min_gap_m in front of
  // the row's front line), read as no person but as long as two people side by side, is split in
  // two along its length when both halves are people. Away from the row no parked car's end
  // stands there to be split; SplitTandems leaves blobs long across the sight line whole for that.
  void SplitPairsInAisle(FrameResult& r, const Eigen::Vector3f& up, const mapping::BayRow& row,
                         std::vector<Eigen::Vector2f>* viewers, std::vector<Seen>* seen) const {
    if (params.aisle_pair_min_gap_m <= 0.0 || params.tandem_min_length_m <= 0.0 || pedestrian_class < 0) return;
    const objects::ObjectClass& ped = atlas.classes()[static_cast<std::size_t>(pedestrian_class)];
    const std::size_t n = r.boxes.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Seen& v = (*seen)[i];
      const objects::Box3& box = r.boxes[i];
      if (!v.on_ground || v.viewed.classification.class_index == pedestrian_class ||
          !ped.height.Contains(box.size.z()) || box.size.x() - v.depth_spread_m < params.tandem_min_length_m ||
          box.size.x() > 2.0 * ped.length.max_m || box.size.y() > ped.length.max_m ||
          FaceOf(RowPoints(r, r.blobs[i], row)).front_m > -params.aisle_pair_min_gap_m) {
        continue;
      }
      SplitWhenBothAre(pedestrian_class, i, SplitAlong(r.cloud, r.blobs[i], box.axes.col(0)), r, up, viewers, seen);
    }
  }

  // A piece of no class at the row's front whose face is wider than any car's end (what
  // CompleteFacesInRow takes) and at most two of them is the ends of two neighbours seen along the
  // row, joined by stereo's smear along the sight line: it is split where its points thin out
  // along the row (the gap between the cars), each part at least a face (bay_face_min_spread_m).
  void SplitRowFaces(FrameResult& r, const Eigen::Vector3f& up, const mapping::BayRow& row,
                     std::vector<Eigen::Vector2f>* viewers, std::vector<Seen>* seen) const {
    if (!params.split_row_faces) return;
    const double widest_end = WidestCarEnd();
    const Eigen::Vector3f along(static_cast<float>(row.along.x()), static_cast<float>(row.along.y()), 0.0f);
    const double bay_heading = row.HeadingRad();
    const std::size_t n = r.boxes.size();
    for (std::size_t i = 0; i < n; ++i) {
      // Read as a car seen side-on lying along the front line it is no parked car either: parked
      // cars stand across that line.
      const Seen& v = (*seen)[i];
      const bool side_along_front =
          v.on_ground && v.viewed.classification.class_index == car_class &&
          AxisAngle(r.boxes[i].yaw_rad, bay_heading) > kPi / 2.0 - params.bay_snap_min_off_deg * kPi / 180.0;
      if (!Unclassified(v) && !side_along_front) continue;
      const RowFace face = FaceOf(RowPoints(r, r.blobs[i], row));
      const double spread = face.spread_m();
      if (!AtRowFront(face) || spread <= widest_end || spread > 2.0 * widest_end) {
        continue;
      }
      const std::vector<float> gaps = SparseStretches(r.cloud, r.blobs[i], along,
                                                      static_cast<float>(params.bay_face_min_spread_m),
                                                      params.face_pair_gap_density);
      // The sparsest stretch leaving no part wider than a car's end.
      for (float gap : gaps) {
        std::array<std::vector<int>, 2> parts = SplitAt(r.cloud, r.blobs[i], along, gap);
        if (std::any_of(parts.begin(), parts.end(), [&](const std::vector<int>& part) {
              if (part.empty()) return true;
              return FaceOf(RowPoints(r, part, row)).spread_m() > widest_end;
            })) {
          continue;
        }
        const std::optional<std::array<Part, 2>> seen_parts = SeeParts(i, parts, r, up, *viewers);
        if (!seen_parts) continue;
        ReplaceByParts(i, std::move(parts), *seen_parts, r, viewers, seen);
        break;
      }
    }
  }

  // Pieces of no class on the ground at the row's front, a car's face wide (wider than a person),
  // at least bay_face_min_range_m away and clear of the cars, are cars seen end-on between their
  // neighbours; pieces read as a person or a rider the same where no walker stood (WalkerNear).
  // Boxed along the bays from the face, of the Atlas car's mean size (PipelineParams::bay_face_*).
  void CompleteFacesInRow(FrameResult& r, const Eigen::Vector3f& up, const mapping::BayRow& row,
                          std::vector<Seen>* seen) const {
    const objects::ObjectClass& car = atlas.classes()[static_cast<std::size_t>(car_class)];
    const double bay_heading = row.HeadingRad();
    const double length = car.length.mean_m, width = car.width.mean_m;
    std::vector<Eigen::Vector2d> car_centres;
    for (const Seen& v : *seen) {
      if (v.viewed.classification.class_index == car_class) {
        car_centres.push_back(v.viewed.box.center.head<2>().cast<double>());
      }
    }
    for (std::size_t i = 0; i < r.boxes.size(); ++i) {
      Seen& v = (*seen)[i];
      const int cls = v.viewed.classification.class_index;
      // A car's end seen edge-on is as long and wide as a bicycle (the Atlas cyclist).
      const bool person_or_rider = cls >= 0 && (cls == pedestrian_class || cls == cyclist_class);
      if (!v.on_ground || (cls != atlas.unknown_index() && !person_or_rider)) continue;
      if (person_or_rider) {
        const Eigen::Vector3f c = v.viewed.box.center;
        if (WalkerNear((r.T_world_vehicle * Eigen::Vector3d(c.x(), c.y(), 0.0)).head<2>())) continue;
      }
      const RowFace face = FaceOf(RowPoints(r, r.blobs[i], row));
      const double spread = face.spread_m();
      if (!AtRowFront(face) || spread < params.bay_face_min_spread_m || spread > WidestCarEnd()) {
        continue;
      }
      const double lateral = 0.5 * (face.lo_m + face.hi_m);
      const Eigen::Vector2d xy =
          row.origin + lateral * row.along + (std::max(0.0, face.front_m) + 0.5 * length) * row.into_bays;
      if (xy.norm() < params.bay_face_min_range_m ||
          std::any_of(car_centres.begin(), car_centres.end(), [&](const Eigen::Vector2d& c) {
            return std::abs(row.Along(c) - lateral) < width && std::abs(row.into_bays.dot(c - xy)) < length;
          }) ||
          GroundPointsInside(r, xy, bay_heading, length, width, params.row_align_free_ground_margin_m) >
              params.bay_face_max_ground_ratio * static_cast<double>(r.blobs[i].size())) {
        continue;
      }
      objects::Box3 box = v.viewed.box;
      const float bottom = box.center.z() - 0.5f * box.size.z();
      box.size.z() = static_cast<float>(car.height.mean_m);
      box.center.z() = bottom + 0.5f * box.size.z();
      PlaceBox(&box, xy, bay_heading, length, width, up);
      v.viewed.box = box;
      v.viewed.classification = {car_class, params.bay_face_score};
      car_centres.push_back(xy);
    }
  }

  // Splits long blobs seen across their length at a gap when both parts are cars
  // (PipelineParams::face_pair_*): the ends of two neighbouring parked cars.
  void SplitFacePairs(FrameResult& r, const Eigen::Vector3f& up, std::vector<Eigen::Vector2f>* viewers,
                      std::vector<Seen>* seen) const {
    if (params.face_pair_min_length_m <= 0.0 || car_class < 0) return;
    const objects::ObjectClass& car = atlas.classes()[static_cast<std::size_t>(car_class)];
    const std::size_t n = r.boxes.size();
    for (std::size_t i = 0; i < n; ++i) {
      const objects::Box3& box = r.boxes[i];
      if (!(*seen)[i].on_ground || box.size.x() < params.face_pair_min_length_m) continue;
      const Eigen::Vector2f sight = (box.center.head<2>() - (*viewers)[i]).normalized();
      if (std::abs(box.axes.col(0).head<2>().dot(sight)) >= kCos45) continue;
      // Each part at least a car end's narrowest (Atlas width min) less the edge fattening.
      // The sparsest stretch can be a thin end (a corner seen obliquely): the next is tried when
      // its parts are not both cars.
      const std::vector<float> gaps = SparseStretches(
          r.cloud, r.blobs[i], box.axes.col(0), 0.5f * static_cast<float>(car.width.min_m), params.face_pair_gap_density);
      const objects::Box3 whole = box;  // (r.boxes grows on a split)
      for (float gap : gaps) {
        if (SplitWhenBothAre(car_class, i, SplitAt(r.cloud, r.blobs[i], whole.axes.col(0), gap), r, up, viewers, seen)) {
          break;
        }
      }
    }
  }

  // A part of a blob, boxed and seen from the blob's camera.
  struct Part {
    objects::Box3 box;
    Seen seen;
  };
  // Both @p parts of blob @p i boxed and seen; nullopt when either is too small for a blob
  // (min_blob_points).
  std::optional<std::array<Part, 2>> SeeParts(std::size_t i, const std::array<std::vector<int>, 2>& parts,
                                              const FrameResult& r, const Eigen::Vector3f& up,
                                              const std::vector<Eigen::Vector2f>& viewers) const {
    const auto min_points = static_cast<std::size_t>(params.segmentation.min_blob_points);
    if (parts[0].size() < min_points || parts[1].size() < min_points) return std::nullopt;
    std::array<Part, 2> out;
    for (std::size_t h = 0; h < 2; ++h) {
      out[h].box = FitStandingBox(r, parts[h], up, viewers[i]);
      out[h].seen = See(r, out[h].box, parts[h], viewers[i]);
    }
    return out;
  }
  // Replaces blob @p i by @p parts, seen as @p seen_parts; the second part is appended.
  static void ReplaceByParts(std::size_t i, std::array<std::vector<int>, 2> parts, const std::array<Part, 2>& seen_parts,
                             FrameResult& r, std::vector<Eigen::Vector2f>* viewers, std::vector<Seen>* seen) {
    r.boxes[i] = seen_parts[0].box;
    r.blobs[i] = std::move(parts[0]);
    (*seen)[i] = seen_parts[0].seen;
    r.boxes.push_back(seen_parts[1].box);
    r.blobs.push_back(std::move(parts[1]));
    seen->push_back(seen_parts[1].seen);
    viewers->push_back((*viewers)[i]);
  }
  // Replaces blob @p i by @p parts when both are blobs of class @p class_index. Whether it did.
  bool SplitWhenBothAre(int class_index, std::size_t i, std::array<std::vector<int>, 2> parts, FrameResult& r,
                        const Eigen::Vector3f& up, std::vector<Eigen::Vector2f>* viewers,
                        std::vector<Seen>* seen) const {
    const std::optional<std::array<Part, 2>> seen_parts = SeeParts(i, parts, r, up, *viewers);
    if (!seen_parts || std::any_of(seen_parts->begin(), seen_parts->end(), [&](const Part& part) {
          return part.seen.viewed.classification.class_index != class_index;
        })) {
      return false;
    }
    ReplaceByParts(i, std::move(parts), *seen_parts, r, viewers, seen);
    return true;
  }

  bool IsPerson(const Part& part) const { return part.seen.viewed.classification.class_index == pedestrian_class; }
  // When the nearer of @p halves is a person and the farther, of no class behind it, can be one
  // partly seen (no deeper than a person: a car's side behind a piece of its end is a sheet 1.1 m
  // long), the farther becomes that person, boxed from the ground up. Whether it did.
  bool SeeFarHalfPartlySeen(const FrameResult& r, const Eigen::Vector3f& up, const Eigen::Vector2f& viewer,
                            std::array<Part, 2>* halves) const {
    if (IsPerson((*halves)[0]) == IsPerson((*halves)[1])) return false;
    const Part& near = IsPerson((*halves)[0]) ? (*halves)[0] : (*halves)[1];
    Part& far = IsPerson((*halves)[0]) ? (*halves)[1] : (*halves)[0];
    const objects::ObjectClass& ped = atlas.classes()[static_cast<std::size_t>(pedestrian_class)];
    if (!Unclassified(far.seen) ||
        (far.box.center.head<2>() - viewer).norm() <= (near.box.center.head<2>() - viewer).norm() ||
        far.box.size.x() > ped.length.mean_m + ped.length.sigma_m) {
      return false;
    }
    const std::optional<objects::Box3> person = PartlySeenPerson(r, up, far.box);
    if (!person) return false;
    far.box = *person;
    far.seen.viewed.box = *person;
    far.seen.viewed.classification = near.seen.viewed.classification;
    return true;
  }

  // Splits pedestrian-tall blobs too long for one person (two people walking one behind the
  // other along the sight line) in two along their length, when both halves are pedestrians, or
  // the nearer one is and the farther one, hidden behind it in part, can be one partly seen
  // (PipelineParams::tandem_far_partly_seen).
  void SplitTandems(FrameResult& r, const Eigen::Vector3f& up, std::vector<Eigen::Vector2f>* viewers,
                    std::vector<Seen>* seen) const {
    if (params.tandem_min_length_m <= 0.0 || pedestrian_class < 0) return;
    const objects::ObjectClass& ped = atlas.classes()[static_cast<std::size_t>(pedestrian_class)];
    const std::size_t n = r.boxes.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Seen& whole = (*seen)[i];
      const objects::Box3& box = r.boxes[i];
      // Pedestrian-tall and -narrow whatever it was classed as (a pair reads as a cyclist end-on).
      if (!whole.on_ground || box.size.x() - whole.depth_spread_m < params.tandem_min_length_m ||
          !ped.height.Contains(box.size.z()) || box.size.y() > ped.width.max_m) {
        continue;
      }
      // One behind the other means long along the sight line; long across it is a face (a car's
      // end seen head-on is as tall and thin, and its halves as wide as people).
      const Eigen::Vector2f sight = box.center.head<2>() - (*viewers)[i];
      if (std::abs(box.axes.col(0).head<2>().dot(sight.normalized())) < kCos45) continue;
      std::array<std::vector<int>, 2> halves = SplitAlong(r.cloud, r.blobs[i], box.axes.col(0));
      std::optional<std::array<Part, 2>> parts = SeeParts(i, halves, r, up, *viewers);
      if (!parts) continue;
      const bool both_people = IsPerson((*parts)[0]) && IsPerson((*parts)[1]);
      if (!both_people && !(params.tandem_far_partly_seen && SeeFarHalfPartlySeen(r, up, (*viewers)[i], &*parts))) {
        continue;
      }
      ReplaceByParts(i, std::move(halves), *parts, r, viewers, seen);
    }
  }

  static stereo::StereoParams StereoParamsOf(const PipelineParams& p) {
    stereo::StereoParams sp;
    sp.disparity_size = p.disparity_size;
    sp.reprojection.max_range_m = p.max_range_m;
    sp.reprojection.max_disparity_spread = p.max_disparity_spread;
    sp.reprojection.min_outline_step_px = p.min_outline_step_px;
    sp.sgm = p.sgm;
    return sp;
  }

  drivers::Calibration calibration;
  PipelineParams params;
  objects::Atlas atlas;
  std::vector<int> merge_classes;    // fragment_merge_classes as atlas indices
  std::vector<int> stacked_classes;  // stacked_merge_classes as atlas indices
  int car_class = atlas.Find("car");  // -1 without one: no parked-car memory
  int pedestrian_class = atlas.Find("pedestrian");
  int cyclist_class = atlas.Find("cyclist");
  std::map<int, objects::Detection> parked;  // world frame, by track id
  std::map<int, double> parked_view_area;    // of the view each remembers (parked_keep_view_fraction)
  std::set<int> parked_from_steady_view;     // remembered under parked_max_speed_mps (not replaced by others)
  std::map<int, Eigen::Vector2d> track_began;  // world frame, by track id (NoteWalkers)
  std::vector<Eigen::Vector2d> walkers;        // world frame, last frame's (NoteWalkers)
  objects::Tracker tracker;
  planning_iface::ParkingSlotEstimator slots;
  planning_iface::ManeuverStageTracker stage;
  stereo::MultiRigStereo stereo;

  std::optional<std::int64_t> first_stamp_ns;
  std::optional<std::int64_t> last_stamp_ns;
  Eigen::Isometry3d last_T_world_vehicle = Eigen::Isometry3d::Identity();
  bool have_vehicle = false;
  std::optional<objects::LocalEnu> enu;
  Eigen::Isometry3d T_enu_world = Eigen::Isometry3d::Identity();
  bool gnss_gap = false;

  struct RigCounters {
    std::int64_t frames = 0;
    std::int64_t dropped = 0;
    std::optional<std::int64_t> first_stamp_ns;
    std::int64_t last_stamp_ns = 0;
  };
  std::map<int, RigCounters> rigs;
  std::int64_t frames_processed = 0;
  std::int64_t frames_dropped = 0;
  std::int64_t malformed = 0;
  std::vector<std::string> events;
  planning_iface::PerceptionStatus last_status;  // without events
};

Pipeline::Pipeline(const drivers::Calibration& calibration, const PipelineParams& params) {
  params.Validate();
  if (calibration.rigs.empty()) Fail("pipeline: the calibration has no rigs");
  impl_ = std::make_unique<Impl>(calibration, params);
}

Pipeline::~Pipeline() = default;

const drivers::Calibration& Pipeline::calibration() const { return impl_->calibration; }
const PipelineParams& Pipeline::params() const { return impl_->params; }
const objects::Atlas& Pipeline::atlas() const { return impl_->atlas; }

void Pipeline::CountDropped(int rig_id) {
  ++impl_->rigs[rig_id].dropped;
  ++impl_->frames_dropped;
}
void Pipeline::CountMalformed() { ++impl_->malformed; }
void Pipeline::ReportEvent(const std::string& event) { impl_->events.push_back(event); }

std::optional<planning_iface::PerceptionStatus> Pipeline::TakePendingStatus() {
  Impl& s = *impl_;
  if (s.events.empty()) return std::nullopt;
  planning_iface::PerceptionStatus status = s.last_status;
  status.frames_dropped = s.frames_dropped;
  status.malformed_messages = s.malformed;
  status.events.swap(s.events);
  return status;
}

namespace {

RigInput ToInput(const stereo::RigResult& rr, std::int64_t stamp_ns) {
  RigInput in;
  in.rig_id = rr.rig_id;
  in.stamp_ns = stamp_ns;
  in.cloud = rr.cloud_vehicle;
  in.stereo_ms = rr.total_ms;
  return in;
}
}  // namespace

std::optional<RigInput> Pipeline::Stereo(const drivers::StereoFrame& frame) {
  const stereo::RigResult rr = impl_->stereo.ProcessRig(frame);
  if (!rr.ok) {
    CountDropped(frame.rig_id);
    ReportEvent("rig " + std::to_string(frame.rig_id) + " stereo failed: " + rr.error);
    return std::nullopt;
  }
  return ToInput(rr, frame.stamp_ns());
}

FrameResult Pipeline::Process(const drivers::FrameSet& frames) {
  const auto t0 = Clock::now();
  const std::vector<stereo::RigResult> results = impl_->stereo.Process(frames);
  std::vector<RigInput> rigs;
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (results[i].ok) {
      rigs.push_back(ToInput(results[i], frames.stereo[i].stamp_ns()));
    } else {
      CountDropped(results[i].rig_id);
      ReportEvent("rig " + std::to_string(results[i].rig_id) + " stereo failed: " + results[i].error);
    }
  }
  const double stereo_ms = MsSince(t0);
  FrameResult r = ProcessClouds(frames.stamp_ns, static_cast<std::int64_t>(frames.sequence), rigs,
                                frames.vehicle, frames.gnss);
  r.status.stages.insert(r.status.stages.begin(), {"stereo", stereo_ms});
  r.status.total_latency_ms += stereo_ms;
  return r;
}

FrameResult Pipeline::ProcessClouds(std::int64_t stamp_ns, std::int64_t frame_sequence,
                                    const std::vector<RigInput>& rigs,
                                    const std::optional<drivers::VehicleState>& vehicle,
                                    const std::optional<drivers::GnssFix>& gnss) {
  Impl& s = *impl_;
  if (s.last_stamp_ns && stamp_ns <= *s.last_stamp_ns) {
    Fail("pipeline: frame " + std::to_string(frame_sequence) + " stamp " + std::to_string(stamp_ns) +
         " ns is not after the previous frame's " + std::to_string(*s.last_stamp_ns) +
         " ns (out-of-order input)");
  }
  if (!s.first_stamp_ns) s.first_stamp_ns = stamp_ns;
  s.last_stamp_ns = stamp_ns;
  const auto t_frame = Clock::now();
  FrameResult r;
  r.stamp_ns = stamp_ns;
  r.frame_sequence = frame_sequence;
  std::vector<std::string> events;
  events.swap(s.events);

  // Vehicle pose (world frame) from odometry; without it the last pose stands and is reported.
  if (vehicle) {
    s.last_T_world_vehicle = vehicle->T_world_vehicle;
    s.have_vehicle = true;
  } else {
    events.push_back(s.have_vehicle ? "no vehicle state: last pose kept"
                                    : "no vehicle state: world frame = first vehicle frame");
  }
  r.T_world_vehicle = s.last_T_world_vehicle;
  r.ego_world.position_m = r.T_world_vehicle.translation().head<2>();
  r.ego_world.yaw_rad = YawOf(r.T_world_vehicle);

  // Stage: fusion.
  auto t0 = Clock::now();
  std::vector<mapping::RigCloud> inputs;
  std::map<int, int> points_per_rig;
  for (const auto& in : rigs) {
    s.calibration.rig(in.rig_id);  // throws for an unknown rig id
    mapping::RigCloud m;
    m.rig_id = in.rig_id;
    m.stamp_ns = in.stamp_ns;
    m.T_vehicle_rig = Eigen::Isometry3f::Identity();  // stereo delivers vehicle-frame points
    m.cloud = in.cloud;
    inputs.push_back(std::move(m));
    points_per_rig[in.rig_id] = static_cast<int>(in.cloud.size());
    auto& counters = s.rigs[in.rig_id];
    ++counters.frames;
    if (!counters.first_stamp_ns) counters.first_stamp_ns = in.stamp_ns;
    counters.last_stamp_ns = in.stamp_ns;
  }
  for (const auto& rc : s.calibration.rigs) {
    if (!points_per_rig.count(rc.rig_id)) {
      r.missing_rigs.push_back(rc.rig_id);
      ++s.rigs[rc.rig_id].dropped;
      events.push_back("rig " + std::to_string(rc.rig_id) + " (" + rc.name +
                       ") missing: its sector is not covered");
    }
  }
  mapping::VehicleMotion motion;
  motion.reference_stamp_ns = stamp_ns;
  if (vehicle) {
    motion.speed_mps = static_cast<float>(vehicle->speed_mps);
    motion.yaw_rate_radps = static_cast<float>(vehicle->yaw_rate_radps);
  }
  std::vector<int> point_rig_ids;
  r.cloud = mapping::FuseRigClouds(inputs, motion, s.params.fusion, nullptr, &point_rig_ids);
  r.status.stages.push_back({"fusion", MsSince(t0)});

  // Stage: ground removal.
  t0 = Clock::now();
  mapping::GroundRemoval ground = mapping::RemoveGround(r.cloud, s.params.ground);
  r.ground_plane = ground.plane;
  r.ground_refined = ground.refined;
  r.ground_indices = std::move(ground.ground);
  r.status.stages.push_back({"ground", MsSince(t0)});

  // Stage: segmentation.
  t0 = Clock::now();
  mapping::Segmentation seg = mapping::SegmentBlobs(r.cloud.xyz, s.params.segmentation, &ground.obstacles);
  r.status.stages.push_back({"segmentation", MsSince(t0)});

  // Stage: boxes (vertical cuboids about the ground normal, heading hinted by the tracks).
  t0 = Clock::now();
  std::vector<Eigen::Vector2f> viewers;  // per box: the camera that saw most of it
  const Eigen::Vector3f up = r.ground_plane.normal.normalized();
  for (auto& blob : seg.blobs) {
    const Eigen::Vector3f c = r.cloud.xyz(Eigen::all, blob).rowwise().mean();
    const Eigen::Vector2d c_world =
        (r.T_world_vehicle * Eigen::Vector3d(c.x(), c.y(), 0.0)).head<2>();
    std::optional<float> hint;
    if (auto h = s.tracker.YawHint(c_world)) hint = static_cast<float>(*h - r.ego_world.yaw_rad);
    const Eigen::Vector2f viewer = BlobViewer(blob, point_rig_ids, s.calibration);
    const objects::Box3 box = s.FitBox(r.cloud, blob, up, hint, viewer);
    if (box.size.z() < s.params.min_object_height_m) continue;  // as measured: kerbs stay out
    r.boxes.push_back(s.OnGround(r, box));
    r.blobs.push_back(std::move(blob));
    viewers.push_back(viewer);
  }
  r.status.stages.push_back({"boxes", MsSince(t0)});

  // Stage: classes (Atlas priors, seen from the camera that saw each blob), unclassified pieces
  // that make a car together merged, completed boxes, detections in the world frame for tracking.
  // Cars and pedestrians stand on the ground: a blob floating above it stays of unknown class.
  t0 = Clock::now();
  std::vector<Pipeline::Impl::Seen> seen;
  for (std::size_t i = 0; i < r.boxes.size(); ++i) seen.push_back(s.See(r, r.boxes[i], r.blobs[i], viewers[i]));
  s.MergeFragments(r, up, &viewers, &seen);
  s.SplitFacePairs(r, up, &viewers, &seen);
  s.SplitTandems(r, up, &viewers, &seen);
  s.UnclassifyFramedFaces(r, viewers, &seen);
  s.AlignCarsToRow(r, up, viewers, &seen);
  s.PlaceCarsInRow(r, up, &viewers, &seen);
  std::vector<objects::Detection> detections;
  const std::vector<objects::Box3> measured_boxes = r.boxes;  // before completion
  auto world_detection = [&](const objects::Box3& box, const objects::Classification& cls) {
    objects::Detection d = objects::Detection::FromBox(box, cls);
    d.xy_m = (r.T_world_vehicle * Eigen::Vector3d(d.xy_m.x(), d.xy_m.y(), 0.0)).head<2>();
    d.yaw_rad += r.ego_world.yaw_rad;
    return d;
  };
  for (std::size_t box_index = 0; box_index < r.boxes.size(); ++box_index) {
    r.boxes[box_index] = seen[box_index].viewed.box;
    const objects::Detection d = world_detection(r.boxes[box_index], seen[box_index].viewed.classification);
    detections.push_back(d);
  }
  s.PreferRememberedFootprints(r, &r.boxes, &detections);
  s.UnclassifyPiecesOfParkedCars(&detections, &seen);
  for (const objects::Detection& d : detections) {
    r.box_classes.push_back(s.atlas.classes()[static_cast<std::size_t>(d.classification.class_index)].name);
  }
  r.status.stages.push_back({"classes", MsSince(t0)});

  // Stage: tracks.
  t0 = Clock::now();
  const double t_s = (stamp_ns - *s.first_stamp_ns) * 1e-9;
  r.tracks = s.tracker.Update(t_s, detections);
  s.NoteWalkers(r.tracks);
  // A track's class, voted over every view of it, is steadier than one frame's: a car seen whole
  // earlier and cut by the image border or seen end-on now is completed as a car, if its measured
  // extents can be one (a fragment too low for a car stays unknown). A person partly seen is still
  // the person its track says (PipelineParams::pedestrian_tracks_keep_partial_views).
  for (const objects::Track& tr : r.tracks) {
    const int i = tr.detection_index;
    if (i < 0 || i >= static_cast<int>(r.boxes.size()) || tr.merged || seen[i].framed || seen[i].part_of_parked_car) {
      continue;
    }
    if (s.params.pedestrian_tracks_keep_partial_views && s.pedestrian_class >= 0 &&
        tr.class_index == s.pedestrian_class && detections[i].classification.class_index == s.atlas.unknown_index()) {
      if (const std::optional<objects::Box3> person = s.PartlySeenPerson(r, up, measured_boxes[i])) {
        r.boxes[i] = *person;
        r.box_classes[i] = s.atlas.classes()[static_cast<std::size_t>(s.pedestrian_class)].name;
        detections[i] = world_detection(*person, {s.pedestrian_class, tr.class_score});
        continue;
      }
    }
    if (!seen[i].on_ground) continue;
    if (tr.class_index < 0 || tr.class_index == s.atlas.unknown_index() ||
        tr.class_index == detections[i].classification.class_index) {
      continue;
    }
    const objects::ViewedBox viewed = objects::CompleteAsClass(s.atlas, tr.class_index, measured_boxes[i],
                                                               viewers[i], s.params.completion, seen[i].depth_spread_m);
    if (viewed.classification.class_index != tr.class_index) continue;
    r.boxes[i] = viewed.box;
    r.box_classes[i] = s.atlas.classes()[static_cast<std::size_t>(tr.class_index)].name;
    detections[i] = world_detection(viewed.box, viewed.classification);
  }
  r.status.stages.push_back({"tracks", MsSince(t0)});

  // Stage: pedestrian predictions in vehicle frame, local ENU and WGS84.
  t0 = Clock::now();
  objects::PredictionFrames frames;
  frames.T_vehicle_track = r.T_world_vehicle.inverse();
  if (gnss && gnss->valid) {
    if (!s.enu) {
      s.enu.emplace(objects::Wgs84{gnss->latitude_deg, gnss->longitude_deg, gnss->altitude_m});
    }
    frames.T_enu_vehicle = objects::VehiclePoseInEnu(*s.enu, *gnss, r.ego_world.yaw_rad);
    s.T_enu_world = frames.T_enu_vehicle * r.T_world_vehicle.inverse();
    if (s.gnss_gap) events.push_back("GNSS fix back");
    s.gnss_gap = false;
  } else {
    if (!s.enu) {
      // Without any fix yet ENU is the odometry world frame at a placeholder origin.
      s.enu.emplace(objects::Wgs84{0.0, 0.0, 0.0});
      events.push_back("no GNSS fix yet: WGS84 relative to lat 0, lon 0");
    } else if (!s.gnss_gap) {
      events.push_back("GNSS gap: ENU bridged by odometry");
    }
    s.gnss_gap = true;
    frames.T_enu_vehicle = s.T_enu_world * r.T_world_vehicle;
  }
  r.predictions = objects::MakePedestrianPredictions(r.tracks, s.atlas, stamp_ns, *s.first_stamp_ns,
                                                     frames, *s.enu, s.params.predictor);
  r.status.stages.push_back({"predictions", MsSince(t0)});

  // Obstacles (vehicle frame): this frame's boxes with their track. A blob shared by several
  // tracks (people side by side) becomes one obstacle per track at its filtered position, and a
  // confirmed track hidden now (total occlusion) stays an obstacle at its prediction: planning
  // must not forget a pedestrian behind a car. Those carry num_points = 0 (not measured now).
  r.obstacles.stamp_ns = stamp_ns;
  r.obstacles.frame_sequence = frame_sequence;
  std::vector<int> track_of(r.boxes.size(), -1);
  std::vector<const objects::Track*> track_ptr(r.boxes.size(), nullptr);
  std::vector<std::vector<const objects::Track*>> merged_tracks(r.boxes.size());
  const Eigen::Isometry3d T_vehicle_world = r.T_world_vehicle.inverse();
  // A world-frame footprint (a track's or a remembered car's) as an obstacle in the vehicle frame.
  auto footprint_obstacle = [&](int track_id, int class_index, double score, const Eigen::Vector2d& xy_world,
                                double yaw_world, double length_m, double width_m, double height_m) {
    planning_iface::Obstacle o;
    o.track_id = track_id;
    o.class_name = s.atlas.classes()[static_cast<std::size_t>(class_index)].name;
    o.score = static_cast<float>(score);
    const Eigen::Vector3d c = T_vehicle_world * Eigen::Vector3d(xy_world.x(), xy_world.y(), 0.0);
    o.center_m = Eigen::Vector3d(c.x(), c.y(), height_m / 2.0);
    o.size_m = Eigen::Vector3d(length_m, width_m, height_m);
    o.yaw_rad = yaw_world - r.ego_world.yaw_rad;
    return o;
  };
  // A track not measured alone now (coasting, or one of a blob's several) at its filtered position
  // with the extents of the last blob it had alone, which need not be its class's: a track voted
  // a car on earlier views and fed fragments since is still something to avoid, but not a car
  // where it coasts; a person stays a person however little of them was seen last (planning must
  // not forget who walked behind a car), of a person's mean size when the last blob was not one.
  auto track_obstacle = [&](const objects::Track& tr, int num_points) {
    planning_iface::Obstacle o = footprint_obstacle(tr.id, tr.class_index, tr.class_score, tr.xy_m, tr.yaw_rad,
                                                    tr.length_m, tr.width_m, tr.height_m);
    o.velocity_mps = Rotate(tr.velocity_mps, -r.ego_world.yaw_rad);
    o.velocity_cov = RotateCovariance(tr.velocity_cov_m2ps2, -r.ego_world.yaw_rad);
    o.num_points = num_points;
    const auto& cls = s.atlas.classes()[static_cast<std::size_t>(tr.class_index)];
    if (cls.has_priors && s.atlas.Score(tr.class_index, tr.length_m, tr.width_m, tr.height_m) < s.atlas.min_score()) {
      if (cls.predict_path) {
        o.size_m = Eigen::Vector3d(cls.length.mean_m, cls.width.mean_m, cls.height.mean_m);
        o.center_m.z() = cls.height.mean_m / 2.0;
      } else {
        o.class_name = s.atlas.classes()[static_cast<std::size_t>(s.atlas.unknown_index())].name;
      }
    }
    return o;
  };
  std::vector<planning_iface::Obstacle> coasting_cars;  // listed once the measured boxes are
  for (const auto& tr : r.tracks) {
    if (tr.detection_index >= 0 && tr.detection_index < static_cast<int>(r.boxes.size())) {
      track_of[tr.detection_index] = tr.id;
      track_ptr[tr.detection_index] = &tr;
      if (tr.merged) merged_tracks[tr.detection_index].push_back(&tr);
    } else if (tr.state == objects::TrackState::kLost && tr.class_index >= 0 &&
               tr.class_index != s.atlas.unknown_index() && !s.parked.count(tr.id)) {
      // (a parked car hidden now is listed where it was seen, below, not where its track coasts)
      // A track coasting faster than its class moves (Atlas max_speed_mps) took its velocity from
      // jumps between unrelated blobs (car-end pieces read as a person): where it coasts to means
      // nothing.
      const objects::ObjectClass& cls = s.atlas.classes()[static_cast<std::size_t>(tr.class_index)];
      if (tr.velocity_mps.norm() > cls.max_speed_mps) continue;
      if (cls.predict_path) {
        r.obstacles.obstacles.push_back(track_obstacle(tr, 0));
        continue;
      }
      // A class without a path model (a car) is listed where it was last measured, not where its
      // velocity carries it: that velocity is mostly the box's centre moving as the view of the
      // car changes while the vehicle passes it (parking scene seeds 1-5: 24 of 136 coasting car
      // boxes carried off the car, none brought onto one). Its velocity still goes out.
      objects::Track shown = tr;
      shown.xy_m = tr.observed_xy_m;
      coasting_cars.push_back(track_obstacle(shown, 0));
    }
  }
  for (std::size_t i = 0; i < r.boxes.size(); ++i) {
    if (merged_tracks[i].size() > 1) {
      // A blob is shared only by people side by side (objects::TrackerParams::max_tracks_per_blob):
      // a track of a class without a path model among them (a car voted on earlier views) is not
      // one of the objects there.
      const int share = static_cast<int>(r.blobs[i].size() / merged_tracks[i].size());
      for (const objects::Track* tr : merged_tracks[i]) {
        if (tr->class_index >= 0 && s.atlas.classes()[static_cast<std::size_t>(tr->class_index)].predict_path) {
          r.obstacles.obstacles.push_back(track_obstacle(*tr, share));
        }
      }
      continue;
    }
    planning_iface::Obstacle o;
    o.track_id = track_of[i];
    o.class_name = r.box_classes[i];
    o.score = static_cast<float>(detections[i].classification.score);
    o.center_m = r.boxes[i].center.cast<double>();
    o.size_m = r.boxes[i].size.cast<double>();
    o.yaw_rad = r.boxes[i].yaw_rad;
    o.num_points = static_cast<int>(r.blobs[i].size());
    if (track_ptr[i] != nullptr) {
      o.velocity_mps = Rotate(track_ptr[i]->velocity_mps, -r.ego_world.yaw_rad);
      o.velocity_cov = RotateCovariance(track_ptr[i]->velocity_cov_m2ps2, -r.ego_world.yaw_rad);
    }
    r.obstacles.obstacles.push_back(o);
  }

  // A coasting car where a car is measured now is that car under another track (its blob went to
  // a new one): listed once, as measured. (People coasting stay: one hidden beside another is
  // still there.)
  for (const planning_iface::Obstacle& c : coasting_cars) {
    if (!MeasuredWithin(r.obstacles.obstacles, c.class_name, c.center_m.head<2>(), 0.5 * c.size_m.x())) {
      r.obstacles.obstacles.push_back(c);
    }
  }
  s.RememberParkedCars(r, r.tracks, detections);
  const std::vector<std::pair<int, objects::Detection>> hidden_cars = s.HiddenParkedCars(r);
  for (const auto& [id, d] : hidden_cars) {
    // num_points 0: not measured now
    r.obstacles.obstacles.push_back(footprint_obstacle(id, d.classification.class_index, d.classification.score,
                                                       d.xy_m, d.yaw_rad, d.length_m, d.width_m, d.height_m));
  }

  // Stage: parking slots from the parked cars (world frame, filtered over frames).
  t0 = Clock::now();
  std::vector<planning_iface::GroundBox> cars;
  auto add_car = [&](const objects::Detection& d, int id) {
    planning_iface::GroundBox b;
    b.center_m = d.xy_m;
    b.yaw_rad = d.yaw_rad;
    b.length_m = d.length_m;
    b.width_m = d.width_m;
    b.id = id;
    cars.push_back(b);
  };
  for (std::size_t i = 0; i < detections.size(); ++i) {
    if (r.box_classes[i] == "car") add_car(detections[i], track_of[i]);
  }
  // Neighbours hidden now (behind the row in front, or beside the vehicle during the entry) still
  // bound the bay.
  for (const auto& [id, d] : hidden_cars) add_car(d, id);
  r.slots.stamp_ns = stamp_ns;
  r.slots.frame_sequence = frame_sequence;
  r.slots.ego_world = r.ego_world;
  r.slots.stage = s.stage.Update(stamp_ns, r.ego_world);
  planning_iface::SlotRefiner bay_edges_on_ground;
  if (s.params.bay_edges_from_ground) {
    bay_edges_on_ground = [&](planning_iface::ParkingSlot& slot) {
      mapping::BayStrip strip;
      strip.center_m = slot.target.position_m;
      strip.depth_axis = -slot.aisle_normal;
      strip.half_width_m = slot.length_m / 2 - s.params.bay_strip_margin_m;
      strip.front_m = -slot.depth_m / 2;
      strip.rear_m = slot.depth_m / 2;
      if (!(strip.half_width_m > 0) || !(strip.rear_m > strip.front_m)) return;
      const mapping::BayEdges edges =
          mapping::FindBayEdges(r.cloud, r.ground_indices, r.T_world_vehicle, strip, s.params.bay_edges);
      const double front = edges.front_m.value_or(strip.front_m);
      const double rear = edges.rear_m.value_or(strip.rear_m);
      if (!(rear > front)) return;
      planning_iface::SetDepthEdges(&slot, front, rear);
      slot.front_from_ground = edges.front_m.has_value();
      slot.rear_from_ground = edges.rear_m.has_value();
    };
  }
  r.slots.slots = s.slots.Update(cars, r.ego_world, bay_edges_on_ground);
  r.status.stages.push_back({"parking", MsSince(t0)});

  // Status.
  ++s.frames_processed;
  r.status.stamp_ns = stamp_ns;
  r.status.frame_sequence = frame_sequence;
  for (const auto& rc : s.calibration.rigs) {
    const auto& c = s.rigs[rc.rig_id];
    planning_iface::RigStatus st;
    st.rig_id = rc.rig_id;
    st.present = points_per_rig.count(rc.rig_id) > 0;
    st.frames = c.frames;
    st.dropped = c.dropped;
    st.points = st.present ? points_per_rig[rc.rig_id] : 0;
    if (c.first_stamp_ns && c.last_stamp_ns > *c.first_stamp_ns && c.frames > 1) {
      st.frame_rate_hz = (c.frames - 1) / ((c.last_stamp_ns - *c.first_stamp_ns) * 1e-9);
    }
    r.status.rigs.push_back(st);
  }
  r.status.total_latency_ms = MsSince(t_frame);
  r.status.frames_processed = s.frames_processed;
  r.status.frames_dropped = s.frames_dropped;
  r.status.malformed_messages = s.malformed;
  s.last_status = r.status;
  r.status.events = std::move(events);
  return r;
}

}  // namespace romo::pipeline
