#include "romo/sim/sim_source.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>
#include <thread>

#include <GeographicLib/LocalCartesian.hpp>

#include "romo/core/check.hpp"

namespace romo::sim {
namespace {

bool ParseFlag(const drivers::Uri& uri, const std::string& key, bool fallback) {
  const auto v = uri.Get(key);
  if (!v) return fallback;
  if (*v == "1" || *v == "true") return true;
  if (*v == "0" || *v == "false") return false;
  Fail("source URI " + uri.ToString() + ": '" + key + "=" + *v + "' is not 0 or 1");
}

}  // namespace

void SimParams::Validate() const {
  if (scene != "parking") Fail("unknown simulator scene '" + scene + "' (known: parking)");
  if (frames <= 0) Fail("simulator frames = " + std::to_string(frames) + " must be > 0");
  if (first_frame < 0) {
    Fail("simulator first frame = " + std::to_string(first_frame) + " must be >= 0");
  }
  if (!(rate_hz >= 0.5 && rate_hz <= 100.0)) {
    Fail("simulator rate_hz = " + std::to_string(rate_hz) + " is outside 0.5-100");
  }
  if (!(scale > 0.0 && scale <= 4.0)) {
    Fail("simulator scale = " + std::to_string(scale) + " is outside (0, 4]");
  }
  render.Validate();
}

SimParams SimParams::FromUri(const drivers::Uri& uri) {
  static const std::set<std::string> kKeys = {"seed",  "frames",     "rate_hz", "scale",
                                              "depth", "distortion", "calib",   "start_ns",
                                              "aa",    "noise",      "threads", "first"};
  for (const auto& [key, value] : uri.query) {
    if (kKeys.count(key) == 0) {
      std::string known;
      for (const auto& k : kKeys) known += (known.empty() ? "" : ", ") + k;
      Fail("source URI " + uri.ToString() + ": unknown key '" + key + "' (known: " + known + ")");
    }
  }
  SimParams p;
  p.scene = uri.path;
  if (p.scene.empty()) Fail("source URI " + uri.ToString() + ": no scene (e.g. sim://parking)");
  if (const auto v = uri.GetInt("seed")) {
    if (*v < 0) Fail("source URI " + uri.ToString() + ": 'seed=" + std::to_string(*v) + "' must be >= 0");
    p.seed = static_cast<std::uint64_t>(*v);
  }
  if (const auto v = uri.GetInt("frames")) p.frames = *v;
  if (const auto v = uri.GetInt("first")) p.first_frame = *v;
  if (const auto v = uri.GetDouble("rate_hz")) p.rate_hz = *v;
  if (const auto v = uri.GetDouble("scale")) p.scale = *v;
  p.depth = ParseFlag(uri, "depth", p.depth);
  p.distortion = ParseFlag(uri, "distortion", p.distortion);
  if (const auto v = uri.Get("calib")) p.calibration_path = *v;
  if (const auto v = uri.GetInt("start_ns")) p.start_stamp_ns = *v;
  if (const auto v = uri.GetInt32("aa")) p.render.samples_per_axis = *v;
  if (const auto v = uri.GetDouble("noise")) p.render.noise_sigma = *v;
  // Output does not depend on the thread count, so use every core unless told otherwise.
  p.render.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (const auto v = uri.GetInt("threads", 1, 256)) p.render.threads = static_cast<int>(*v);
  p.Validate();
  return p;
}

drivers::Calibration SimCalibration(const SimParams& params) {
  const std::string path =
      params.calibration_path.empty() ? drivers::SampleCalibrationPath() : params.calibration_path;
  drivers::Calibration calibration = drivers::Calibration::Load(path);
  if (!params.distortion) {
    for (auto& rig : calibration.rigs) {
      rig.left.distortion.clear();
      rig.right.distortion.clear();
    }
  }
  return params.scale == 1.0 ? calibration : ScaleCalibration(calibration, params.scale);
}

class SimSource::Impl {
 public:
  explicit Impl(const SimParams& params)
      : params_((params.Validate(), params)),
        scene_(ParkingSceneParams{params.seed}),
        calibration_(SimCalibration(params)),
        renderer_(calibration_, params.render),
        geo_(truth_origin_.latitude_deg, truth_origin_.longitude_deg, truth_origin_.altitude_m) {}

  double TimeOf(std::uint64_t index) const { return static_cast<double>(index) / params_.rate_hz; }
  std::int64_t StampOf(std::uint64_t index) const {
    return params_.start_stamp_ns + std::llround(static_cast<double>(index) * 1e9 / params_.rate_hz);
  }

  GroundTruth Truth(std::uint64_t index) const {
    const double t = TimeOf(index);
    GroundTruth truth;
    truth.stamp_ns = StampOf(index);
    truth.sequence = index;
    truth.scene = params_.scene;
    truth.seed = params_.seed;
    truth.origin = truth_origin_;
    const EgoState ego = scene_.EgoAt(t);
    truth.T_world_vehicle = ego.T_world_vehicle;
    truth.ego_speed_mps = ego.speed_mps;
    truth.ego_yaw_rate_radps = ego.yaw_rate_radps;
    truth.ego_size_m = scene_.params().ego_size_m;
    truth.ego_phase = ego.phase;
    const Eigen::Vector3d p = ego.T_world_vehicle.translation();
    truth.gnss.stamp_ns = truth.stamp_ns;
    geo_.Reverse(p.x(), p.y(), p.z(), truth.gnss.latitude_deg, truth.gnss.longitude_deg,
                 truth.gnss.altitude_m);
    truth.gnss.horizontal_sigma_m = 0.0;
    truth.gnss.valid = true;
    truth.objects = scene_.ObjectsAt(t);
    truth.bays = scene_.bays();
    return truth;
  }

  std::optional<drivers::FrameSet> Next() {
    if (next_ >= static_cast<std::uint64_t>(params_.frames)) return std::nullopt;
    const std::uint64_t index = static_cast<std::uint64_t>(params_.first_frame) + next_++;
    truth_ = Truth(index);
    const SceneSnapshot snap = scene_.At(TimeOf(index));
    drivers::FrameSet set;
    set.stamp_ns = truth_.stamp_ns;
    set.sequence = index;
    set.stereo = renderer_.Render(snap, params_.seed, index, params_.depth ? &depth_ : nullptr);
    for (auto& f : set.stereo) {
      f.left.stamp_ns = f.right.stamp_ns = set.stamp_ns;
    }
    for (auto& d : depth_) {
      d.stamp_ns = set.stamp_ns;
      d.sequence = index;
    }
    drivers::VehicleState vs;
    vs.stamp_ns = set.stamp_ns;
    vs.T_world_vehicle = truth_.T_world_vehicle;
    vs.speed_mps = truth_.ego_speed_mps;
    vs.yaw_rate_radps = truth_.ego_yaw_rate_radps;
    set.vehicle = vs;
    // The simulated receiver reports the exact position with a nominal RTK-class sigma.
    drivers::GnssFix fix = truth_.gnss;
    fix.horizontal_sigma_m = 0.02;
    set.gnss = fix;
    return set;
  }

  SimParams params_;
  GeodeticOrigin truth_origin_;
  ParkingScene scene_;
  drivers::Calibration calibration_;
  Renderer renderer_;
  GeographicLib::LocalCartesian geo_;
  std::uint64_t next_ = 0;
  GroundTruth truth_;
  std::vector<GtDepth> depth_;
};

SimSource::SimSource(const SimParams& params) : impl_(std::make_unique<Impl>(params)) {}
SimSource::~SimSource() = default;
std::optional<drivers::FrameSet> SimSource::Next() { return impl_->Next(); }
const drivers::Calibration* SimSource::calibration() const { return &impl_->calibration_; }
const GroundTruth& SimSource::ground_truth() const { return impl_->truth_; }
const std::vector<GtDepth>& SimSource::depth() const { return impl_->depth_; }
const ParkingScene& SimSource::scene() const { return impl_->scene_; }
const SimParams& SimSource::params() const { return impl_->params_; }
const Renderer& SimSource::renderer() const { return impl_->renderer_; }
GroundTruth SimSource::TruthAt(std::uint64_t index) const { return impl_->Truth(index); }

void RegisterSimSource() {
  static std::once_flag once;
  std::call_once(once, [] {
    drivers::RegisterSourceScheme("sim", [](const drivers::Uri& uri) {
      return std::unique_ptr<drivers::FrameSource>(
          std::make_unique<SimSource>(SimParams::FromUri(uri)));
    });
  });
}

}  // namespace romo::sim
