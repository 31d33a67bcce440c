#pragma once
/// Pedestrian prediction logs (pedestrian-prediction researcher, DESIGN.md): for every pedestrian
/// track and frame, the observed position and the predicted path in the vehicle frame, local ENU
/// and WGS84 — as CSV (PredictionCsvWriter) and as the LCM message romo_lcm.pedestrian_predictions_t
/// (EncodePedestrianPredictions; planning_iface publishes it on kPedestrianPredictionChannel).
///
/// Use: per frame, MakePedestrianPredictions(tracker.tracks(), atlas, stamp_ns, frames, enu), then
/// writer.WriteFrame(predictions) and/or publish EncodePedestrianPredictions(...).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "romo/objects/atlas.hpp"
#include "romo/objects/geo.hpp"
#include "romo/objects/tracker.hpp"

namespace romo::objects {

inline constexpr const char* kPedestrianPredictionChannel = "ROMO_PEDESTRIAN_PREDICTIONS";

/// One position of a log: vehicle frame, ENU and WGS84, with its covariance.
struct LoggedPoint {
  double dt_s = 0.0;  ///< after the observation (0 for the observed position)
  Eigen::Vector2d vehicle_xy_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d vehicle_cov_m2 = Eigen::Matrix2d::Zero();
  Eigen::Vector3d enu_m = Eigen::Vector3d::Zero();
  Eigen::Matrix2d enu_cov_m2 = Eigen::Matrix2d::Zero();  ///< east/north
  Wgs84 wgs84;
};

/// One pedestrian track's prediction at one frame.
struct PedestrianPrediction {
  std::int64_t stamp_ns = 0;
  int track_id = 0;
  TrackState state = TrackState::kTentative;
  double class_score = 0.0;
  bool merged = false;
  PredictorKind predictor = PredictorKind::kRls;
  std::int64_t observed_stamp_ns = 0;
  LoggedPoint observed;               ///< last observed position (covariance: the track's)
  Eigen::Vector2d velocity_enu_mps = Eigen::Vector2d::Zero();
  Wgs84 enu_origin;
  std::vector<LoggedPoint> path;      ///< predicted positions
};

/// Where the tracking frame sits at this frame: track positions are ground-plane xy in the
/// tracking frame (z = 0); the vehicle frame comes from T_vehicle_track, ENU from
/// T_enu_vehicle (e.g. VehiclePoseInEnu from the GNSS fix).
struct PredictionFrames {
  Eigen::Isometry3d T_enu_vehicle = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_vehicle_track = Eigen::Isometry3d::Identity();
};

/// Predictions of every track whose Atlas class has predict_path (pedestrians), tentative
/// tracks excluded. @p track_time_origin_ns: stamp_ns of tracker time 0 (tracker stamps are
/// seconds since it).
std::vector<PedestrianPrediction> MakePedestrianPredictions(
    const std::vector<Track>& tracks, const Atlas& atlas, std::int64_t stamp_ns,
    std::int64_t track_time_origin_ns, const PredictionFrames& frames, const LocalEnu& enu,
    PredictorKind predictor);

/// CSV log, one row per position: the observed position (k = 0) then each predicted point
/// (k = 1..N) of every pedestrian at every frame. Header (first line):
///   stamp_ns,track_id,state,merged,class_score,predictor,k,dt_s,
///   vehicle_x_m,vehicle_y_m,enu_e_m,enu_n_m,enu_u_m,latitude_deg,longitude_deg,altitude_m,
///   vehicle_cov_xx_m2,vehicle_cov_xy_m2,vehicle_cov_yy_m2,enu_cov_ee_m2,enu_cov_en_m2,enu_cov_nn_m2
/// stamp_ns is the frame; for k = 0, dt_s = (observed time - frame time) <= 0 (negative while
/// the pedestrian is occluded); for k >= 1, dt_s is after the observation. Latitude/longitude
/// have 1e-9 deg (0.1 mm) resolution. The file is "<path>.partial" until Close() renames it;
/// each frame is flushed when written.
class PredictionCsvWriter {
 public:
  /// @throws romo::Error when the file cannot be created.
  explicit PredictionCsvWriter(const std::string& path);
  ~PredictionCsvWriter();
  PredictionCsvWriter(const PredictionCsvWriter&) = delete;
  PredictionCsvWriter& operator=(const PredictionCsvWriter&) = delete;

  /// Appends one frame's predictions. @throws romo::Error on a write failure (e.g. disk full).
  void WriteFrame(const std::vector<PedestrianPrediction>& predictions);
  /// Flushes and renames into place. Idempotent.
  void Close();
  std::int64_t rows_written() const;
  const std::string& path() const;
  /// Where a log found at @p path.partial (left by a killed writer) was kept; "" if none.
  const std::string& kept_interrupted() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// The CSV header line (without newline).
const char* PredictionCsvHeader();

/// romo_lcm.pedestrian_predictions_t bytes for one frame.
std::vector<std::uint8_t> EncodePedestrianPredictions(
    std::int64_t stamp_ns, std::int64_t frame_sequence,
    const std::vector<PedestrianPrediction>& predictions);
/// Decodes and validates romo_lcm.pedestrian_predictions_t (e.g. from the network).
/// @throws romo::Error naming the field when malformed.
std::vector<PedestrianPrediction> DecodePedestrianPredictions(const void* data, std::size_t size,
                                                              std::int64_t* frame_sequence = nullptr);

}  // namespace romo::objects
