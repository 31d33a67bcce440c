#pragma once
/// Action labels from interpretable features of the motion profiles and hand rotation
/// (Tables 6.1/6.2): periodicity, sawtooth shape, spike rate, plane-distance peaks and their
/// inflections, rotation spread.
#include <string>
#include <utility>
#include <vector>

#include "romo/indoor_manip/fingerprint.hpp"

namespace romo::indoor_manip {

/// The ten actions: the five pairs writing/erasing, tightening/poking, hitting/pulling,
/// chopping/writing_pen, eating/drinking ("writing" is on a whiteboard, "writing_pen" with a pen
/// on a table).
const std::vector<std::string>& ActionNames();
/// The partner of @p action in its pair; @throws romo::Error for an unknown name.
std::string ActionPartner(const std::string& action);

struct ActionFeatures {
  double duration_s = 0.0;
  double x_range_m = 0.0;  ///< 5-95 percentile spans
  double y_range_m = 0.0;
  double r_range_m = 0.0;
  double r_median_m = 0.0;
  double periodicity_x = 0.0;  ///< highest normalised autocorrelation peak (0..1)
  double periodicity_y = 0.0;
  double periodicity_r = 0.0;
  double period_r_s = 0.0;  ///< lag of that peak for r
  double sawtooth = 0.0;  ///< |skewness| of the in-plane velocity along the sawtooth axis
  double spike_rate_hz = 0.0;  ///< prominent r peaks per second
  double peak_height_m = 0.0;  ///< median r at prominent peaks
  double descent_speed_mps = 0.0;  ///< 95th percentile of the downward r speed
  double peak_inflection_fraction = 0.0;  ///< share of high peaks with a slow segment on a flank
  double rotation_spread_z_deg = 0.0;  ///< std of the per-step angle about the plane normal (deg)
  double rotation_spread_xy_deg = 0.0;  ///< same about the in-plane axes (larger of the two)

  std::vector<std::pair<std::string, double>> Named() const;
};

/// @param rotation_z_deg / rotation_xy_deg per-step angles (may be empty).
ActionFeatures ComputeActionFeatures(const MotionProfiles& profiles,
                                     const std::vector<Eigen::Vector3d>& rotation_steps_rad);

/// Decision thresholds, chosen on sim-manip seeds 0-9 (`romo eval manip --seeds 0-9
/// --features`) and tested on disjoint seeds.
struct ActionThresholds {
  /// Tightening: wrist turns (per-step rotation spread, deg) with only short translations (m)
  /// and no strokes towards the plane (spikes per second).
  double tightening_rotation_deg = 1.5;
  double tightening_max_xy_range_m = 0.032;
  double tightening_max_spike_rate_hz = 0.5;
  /// Peaks higher than this lift the hand far off the plane (hammer, fork, glass).
  double high_peak_m = 0.19;
  double hitting_descent_mps = 1.0;
  double drinking_peak_m = 0.29;
  double drinking_inflection_fraction = 0.5;
  /// Writing: a skewed row velocity (sawtooth) that repeats; board rows are longer than pen rows.
  double sawtooth = 1.4;
  double sawtooth_periodicity = 0.5;
  double board_row_length_m = 0.27;
  /// Strokes towards the plane: spikes per second; irregular ones poke, regular ones chop.
  double stroke_spike_rate_hz = 1.0;
  double regular_periodicity = 0.85;
  /// Pulling: a regular rocking of the distance to the plane with this span at least (m).
  double pulling_min_r_range_m = 0.04;
  void Validate() const;
};

struct ActionDecision {
  std::string label;
  std::vector<std::string> reasons;  ///< the rules that fired, with the values compared
};

ActionDecision ClassifyAction(const ActionFeatures& features, const ActionThresholds& thresholds);

}  // namespace romo::indoor_manip
