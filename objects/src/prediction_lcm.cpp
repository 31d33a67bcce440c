// LCM adapter for prediction logs: the generated romo_lcm types stay in this file.
#include <cmath>
#include <limits>
#include <string>

#include "romo/core/check.hpp"
#include "romo/drivers/lcm_walker.hpp"
#include "romo/objects/prediction_log.hpp"
#include "romo_lcm/pedestrian_predictions_t.hpp"

namespace romo::objects {
namespace {

void Put2(const Eigen::Vector2d& v, double* out) {
  out[0] = v.x();
  out[1] = v.y();
}
void Put3(const Eigen::Vector3d& v, double* out) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}
void PutCov(const Eigen::Matrix2d& m, double* out) {
  out[0] = m(0, 0);
  out[1] = m(0, 1);
  out[2] = m(1, 0);
  out[3] = m(1, 1);
}
Eigen::Matrix2d GetCov(const double* in) {
  Eigen::Matrix2d m;
  m << in[0], in[1], in[2], in[3];
  return m;
}

void CheckFinite(bool ok, const std::string& field) {
  if (!ok) Fail("romo_lcm.pedestrian_predictions_t: field '" + field + "' is not finite");
}

TrackState ParseState(const std::string& s, const std::string& field) {
  if (s == "tentative") return TrackState::kTentative;
  if (s == "confirmed") return TrackState::kConfirmed;
  if (s == "lost") return TrackState::kLost;
  Fail("romo_lcm.pedestrian_predictions_t: field '" + field + "' = '" + s +
       "' (expected tentative, confirmed or lost)");
}

}  // namespace

std::vector<std::uint8_t> EncodePedestrianPredictions(
    std::int64_t stamp_ns, std::int64_t frame_sequence,
    const std::vector<PedestrianPrediction>& predictions) {
  romo_lcm::pedestrian_predictions_t msg;
  msg.stamp_ns = stamp_ns;
  msg.frame_sequence = frame_sequence;
  msg.num_predictions = static_cast<int32_t>(predictions.size());
  for (const PedestrianPrediction& p : predictions) {
    romo_lcm::pedestrian_prediction_t m;
    m.stamp_ns = p.stamp_ns;
    m.track_id = p.track_id;
    m.track_state = ToString(p.state);
    m.class_score = static_cast<float>(p.class_score);
    m.merged = p.merged;
    m.predictor = ToString(p.predictor);
    m.observed_stamp_ns = p.observed_stamp_ns;
    Put2(p.observed.vehicle_xy_m, m.observed_vehicle_xy_m);
    Put3(p.observed.enu_m, m.observed_enu_m);
    m.observed_latitude_deg = p.observed.wgs84.latitude_deg;
    m.observed_longitude_deg = p.observed.wgs84.longitude_deg;
    m.observed_altitude_m = p.observed.wgs84.altitude_m;
    Put2(p.velocity_enu_mps, m.velocity_enu_mps);
    m.enu_origin_latitude_deg = p.enu_origin.latitude_deg;
    m.enu_origin_longitude_deg = p.enu_origin.longitude_deg;
    m.enu_origin_altitude_m = p.enu_origin.altitude_m;
    m.num_points = static_cast<int32_t>(p.path.size());
    for (const LoggedPoint& q : p.path) {
      romo_lcm::predicted_point_t pt;
      pt.dt_s = q.dt_s;
      Put2(q.vehicle_xy_m, pt.vehicle_xy_m);
      PutCov(q.vehicle_cov_m2, pt.vehicle_cov_m2);
      Put3(q.enu_m, pt.enu_m);
      PutCov(q.enu_cov_m2, pt.enu_cov_m2);
      pt.latitude_deg = q.wgs84.latitude_deg;
      pt.longitude_deg = q.wgs84.longitude_deg;
      pt.altitude_m = q.wgs84.altitude_m;
      m.points.push_back(pt);
    }
    msg.predictions.push_back(std::move(m));
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  const int n = msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  ROMO_DEMAND(n == static_cast<int>(bytes.size()));
  return bytes;
}

namespace {

// LCM's generated decoder sizes arrays from the counts before checking the bytes (a negative count
// throws std::length_error, a large one allocates gigabytes), so the counts are walked first.
// Minimum encoded sizes: pedestrian_prediction_t 143 bytes (strings of at least their NUL),
// predicted_point_t 17 doubles.
void CheckPredictionCounts(const void* data, std::size_t size) {
  if (!drivers::LcmHashMatches(data, size, romo_lcm::pedestrian_predictions_t::getHash())) return;
  drivers::LcmWalker w(data, size);
  std::int32_t n = 0;
  bool fits = w.Skip(8 + 8 + 8) && w.Count(143, &n, "num_predictions");
  for (std::int32_t i = 0; fits && i < n; ++i) {
    fits = w.Skip(8 + 4) && w.String("track_state") && w.Skip(4 + 1) && w.String("predictor") &&
           w.Skip(8 + 2 * 8 + 3 * 8 + 3 * 8 + 2 * 8 + 3 * 8) && w.FixedArray(17 * 8, "num_points");
  }
  if (!fits) Fail(w.Reason("romo_lcm.pedestrian_predictions_t"));
}

bool DecodeInto(const void* data, std::size_t size, romo_lcm::pedestrian_predictions_t* msg) {
  if (data == nullptr || size > static_cast<std::size_t>(std::numeric_limits<int>::max())) return false;
  try {
    return msg->decode(data, 0, static_cast<int>(size)) >= 0;
  } catch (const std::exception&) {  // std::length_error from a count the walk let through
    return false;
  }
}

}  // namespace

std::vector<PedestrianPrediction> DecodePedestrianPredictions(const void* data, std::size_t size,
                                                              std::int64_t* frame_sequence) {
  CheckPredictionCounts(data, size);
  romo_lcm::pedestrian_predictions_t msg;
  if (!DecodeInto(data, size, &msg)) {
    Fail("romo_lcm.pedestrian_predictions_t: cannot decode " + std::to_string(size) +
         " bytes (wrong type or truncated)");
  }
  if (frame_sequence != nullptr) *frame_sequence = msg.frame_sequence;
  std::vector<PedestrianPrediction> out;
  out.reserve(msg.predictions.size());
  for (std::size_t i = 0; i < msg.predictions.size(); ++i) {
    const auto& m = msg.predictions[i];
    const std::string at = "predictions[" + std::to_string(i) + "].";
    PedestrianPrediction p;
    p.stamp_ns = m.stamp_ns;
    p.track_id = m.track_id;
    p.state = ParseState(m.track_state, at + "track_state");
    p.class_score = m.class_score;
    CheckFinite(std::isfinite(p.class_score), at + "class_score");
    p.merged = m.merged;
    p.predictor = ParsePredictorKind(m.predictor);
    p.observed_stamp_ns = m.observed_stamp_ns;
    p.observed.dt_s = static_cast<double>(p.observed_stamp_ns - p.stamp_ns) * 1e-9;
    p.observed.vehicle_xy_m = Eigen::Vector2d(m.observed_vehicle_xy_m[0], m.observed_vehicle_xy_m[1]);
    p.observed.enu_m = Eigen::Vector3d(m.observed_enu_m[0], m.observed_enu_m[1], m.observed_enu_m[2]);
    p.observed.wgs84 = {m.observed_latitude_deg, m.observed_longitude_deg, m.observed_altitude_m};
    CheckFinite(p.observed.vehicle_xy_m.allFinite() && p.observed.enu_m.allFinite() &&
                    std::isfinite(m.observed_latitude_deg) && std::isfinite(m.observed_longitude_deg) &&
                    std::isfinite(m.observed_altitude_m),
                at + "observed_*");
    p.velocity_enu_mps = Eigen::Vector2d(m.velocity_enu_mps[0], m.velocity_enu_mps[1]);
    p.enu_origin = {m.enu_origin_latitude_deg, m.enu_origin_longitude_deg, m.enu_origin_altitude_m};
    for (std::size_t k = 0; k < m.points.size(); ++k) {
      const auto& pt = m.points[k];
      LoggedPoint q;
      q.dt_s = pt.dt_s;
      q.vehicle_xy_m = Eigen::Vector2d(pt.vehicle_xy_m[0], pt.vehicle_xy_m[1]);
      q.vehicle_cov_m2 = GetCov(pt.vehicle_cov_m2);
      q.enu_m = Eigen::Vector3d(pt.enu_m[0], pt.enu_m[1], pt.enu_m[2]);
      q.enu_cov_m2 = GetCov(pt.enu_cov_m2);
      q.wgs84 = {pt.latitude_deg, pt.longitude_deg, pt.altitude_m};
      CheckFinite(std::isfinite(q.dt_s) && q.vehicle_xy_m.allFinite() && q.vehicle_cov_m2.allFinite() &&
                      q.enu_m.allFinite() && q.enu_cov_m2.allFinite() && std::isfinite(pt.latitude_deg) &&
                      std::isfinite(pt.longitude_deg) && std::isfinite(pt.altitude_m),
                  at + "points[" + std::to_string(k) + "]");
      p.path.push_back(q);
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace romo::objects
