#include "romo/objects/prediction_log.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "romo/core/check.hpp"
#include "romo/core/partial_file.hpp"

namespace romo::objects {
namespace {

LoggedPoint ToLogged(double dt_s, const Eigen::Vector2d& xy_track, const Eigen::Matrix2d& cov_track,
                     const PredictionFrames& frames, const LocalEnu& enu) {
  LoggedPoint p;
  p.dt_s = dt_s;
  const Eigen::Vector3d track_point(xy_track.x(), xy_track.y(), 0.0);
  const Eigen::Vector3d vehicle = frames.T_vehicle_track * track_point;
  p.vehicle_xy_m = vehicle.head<2>();
  // Ground-plane covariances turn with the yaw part of each transform.
  const Eigen::Matrix2d r_vt = frames.T_vehicle_track.linear().topLeftCorner<2, 2>();
  const Eigen::Matrix2d r_ev = frames.T_enu_vehicle.linear().topLeftCorner<2, 2>();
  p.vehicle_cov_m2 = r_vt * cov_track * r_vt.transpose();
  p.enu_m = frames.T_enu_vehicle * vehicle;
  p.enu_cov_m2 = r_ev * p.vehicle_cov_m2 * r_ev.transpose();
  p.wgs84 = enu.ToWgs84(p.enu_m);
  return p;
}

}  // namespace

std::vector<PedestrianPrediction> MakePedestrianPredictions(
    const std::vector<Track>& tracks, const Atlas& atlas, std::int64_t stamp_ns,
    std::int64_t track_time_origin_ns, const PredictionFrames& frames, const LocalEnu& enu,
    PredictorKind predictor) {
  std::vector<PedestrianPrediction> out;
  const Eigen::Matrix2d r_et =
      (frames.T_enu_vehicle.linear() * frames.T_vehicle_track.linear()).topLeftCorner<2, 2>();
  for (const Track& t : tracks) {
    if (t.state == TrackState::kTentative || t.class_index < 0) continue;
    if (!atlas.classes()[static_cast<std::size_t>(t.class_index)].predict_path) continue;
    PedestrianPrediction p;
    p.stamp_ns = stamp_ns;
    p.track_id = t.id;
    p.state = t.state;
    p.class_score = t.class_score;
    p.merged = t.merged;
    p.predictor = predictor;
    p.observed_stamp_ns = track_time_origin_ns + static_cast<std::int64_t>(std::llround(t.observed_s * 1e9));
    p.observed = ToLogged(static_cast<double>(p.observed_stamp_ns - stamp_ns) * 1e-9, t.observed_xy_m,
                          t.position_cov_m2, frames, enu);
    p.velocity_enu_mps = r_et * t.velocity_mps;
    p.enu_origin = enu.origin();
    p.path.reserve(t.predicted_path.size());
    for (const PredictedPoint& q : t.predicted_path) {
      p.path.push_back(ToLogged(q.dt_s, q.xy_m, q.cov_m2, frames, enu));
    }
    out.push_back(std::move(p));
  }
  return out;
}

const char* PredictionCsvHeader() {
  return "stamp_ns,track_id,state,merged,class_score,predictor,k,dt_s,"
         "vehicle_x_m,vehicle_y_m,enu_e_m,enu_n_m,enu_u_m,latitude_deg,longitude_deg,altitude_m,"
         "vehicle_cov_xx_m2,vehicle_cov_xy_m2,vehicle_cov_yy_m2,enu_cov_ee_m2,enu_cov_en_m2,"
         "enu_cov_nn_m2";
}

class PredictionCsvWriter::Impl {
 public:
  std::string path;
  std::string partial;
  std::string kept_interrupted;
  std::FILE* file = nullptr;
  std::int64_t rows = 0;

  void Check(int rc) {
    if (rc < 0) Fail("prediction log '" + partial + "': write failed: " + std::strerror(errno));
  }
};

PredictionCsvWriter::PredictionCsvWriter(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->partial = path + ".partial";
  impl_->kept_interrupted = KeepInterruptedPartial(path);
  impl_->file = std::fopen(impl_->partial.c_str(), "w");
  if (impl_->file == nullptr) {
    Fail("prediction log '" + impl_->partial + "': cannot create: " + std::strerror(errno));
  }
  impl_->Check(std::fprintf(impl_->file, "%s\n", PredictionCsvHeader()));
  impl_->Check(std::fflush(impl_->file) == 0 ? 0 : -1);
}

PredictionCsvWriter::~PredictionCsvWriter() {
  try {
    Close();
  } catch (const Error& e) {
    std::fprintf(stderr, "romo: %s\n", e.what());  // destructor: report, cannot throw
  }
}

void PredictionCsvWriter::WriteFrame(const std::vector<PedestrianPrediction>& predictions) {
  if (impl_->file == nullptr) Fail("prediction log '" + impl_->path + "': already closed");
  for (const PedestrianPrediction& p : predictions) {
    auto row = [&](int k, const LoggedPoint& q) {
      impl_->Check(std::fprintf(
          impl_->file,
          "%lld,%d,%s,%d,%.4f,%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.9f,%.9f,%.4f,%.6g,%.6g,%.6g,"
          "%.6g,%.6g,%.6g\n",
          static_cast<long long>(p.stamp_ns), p.track_id, ToString(p.state), p.merged ? 1 : 0,
          p.class_score, ToString(p.predictor), k, q.dt_s, q.vehicle_xy_m.x(), q.vehicle_xy_m.y(),
          q.enu_m.x(), q.enu_m.y(), q.enu_m.z(), q.wgs84.latitude_deg, q.wgs84.longitude_deg,
          q.wgs84.altitude_m, q.vehicle_cov_m2(0, 0), q.vehicle_cov_m2(0, 1), q.vehicle_cov_m2(1, 1),
          q.enu_cov_m2(0, 0), q.enu_cov_m2(0, 1), q.enu_cov_m2(1, 1)));
      ++impl_->rows;
    };
    row(0, p.observed);
    for (std::size_t k = 0; k < p.path.size(); ++k) row(static_cast<int>(k + 1), p.path[k]);
  }
  // A crash loses at most the frame being written.
  impl_->Check(std::fflush(impl_->file) == 0 ? 0 : -1);
}

void PredictionCsvWriter::Close() {
  if (impl_->file == nullptr) return;
  const bool ok = std::fflush(impl_->file) == 0 && std::fclose(impl_->file) == 0;
  impl_->file = nullptr;
  if (!ok) Fail("prediction log '" + impl_->partial + "': cannot flush: " + std::strerror(errno));
  if (std::rename(impl_->partial.c_str(), impl_->path.c_str()) != 0) {
    Fail("prediction log: cannot rename '" + impl_->partial + "' to '" + impl_->path +
         "': " + std::strerror(errno));
  }
}

std::int64_t PredictionCsvWriter::rows_written() const { return impl_->rows; }
const std::string& PredictionCsvWriter::path() const { return impl_->path; }
const std::string& PredictionCsvWriter::kept_interrupted() const { return impl_->kept_interrupted; }

}  // namespace romo::objects
