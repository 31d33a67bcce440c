#include "romo/sim/scene.hpp"

#include <algorithm>
#include <cmath>

#include "hash.hpp"
#include "romo/core/check.hpp"

namespace romo::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Row geometry (metres, world frame). The row of perpendicular-parked cars runs along x; bays
// start at the bay front line and end at the curb, the hedge stands behind the curb.
constexpr double kBayFrontY = 4.0;
constexpr double kCurbNearY = 9.4;
constexpr double kCurbWidth = 0.2;
constexpr double kCurbHeight = 0.15;
constexpr double kHedgeY = 10.5;
constexpr double kHedgeDepth = 0.6;
constexpr double kHedgeHeight = 1.4;
constexpr double kRowHalfLength = 30.0;

// Ego maneuver timing (s): approach, wait, turn, wait, sideways entry, then parked.
constexpr double kApproachS = 6.0;
constexpr double kWaitS = 0.5;
constexpr double kTurnS = 3.0;
constexpr double kEntryS = 5.0;
constexpr double kApproachLengthM = 9.0;
// The turn on the spot sweeps a circle of the half diagonal (1.61 m for 2.8 x 1.6): the spot
// keeps that plus 0.3 m from the bay front line.
constexpr double kSpotClearanceM = 0.3;
// How far the ego's near side ends up inside the bay front line.
constexpr double kEntryDepthM = 0.9;

// Object ids (also the per-pixel ids of the depth truth).
constexpr int kCurbId = 1;
constexpr int kHedgeId = 2;
constexpr int kFirstCarId = 100;

double SmoothStep(double tau) { return tau * tau * (3.0 - 2.0 * tau); }
double SmoothStepRate(double tau) { return 6.0 * tau * (1.0 - tau); }

SceneObject MakeCar(int id, double cx, double cy, double length, double width, double height,
                    double yaw, float albedo, std::uint32_t tex) {
  SceneObject car;
  car.box.id = id;
  car.box.class_name = "car";
  car.box.center_m = Eigen::Vector3d(cx, cy, height / 2);
  car.box.size_m = Eigen::Vector3d(length, width, height);
  car.box.yaw_rad = yaw;
  car.material = Material::kCar;
  car.albedo = albedo;
  car.texture_seed = tex;
  return car;
}

// x extent of a box's footprint.
std::pair<double, double> XRange(const GtBox& box) {
  double lo = 1e300, hi = -1e300;
  for (const auto& c : box.Footprint()) {
    lo = std::min(lo, c.x());
    hi = std::max(hi, c.x());
  }
  return {lo, hi};
}

}  // namespace

void ParkingSceneParams::Validate() const {
  if (!(ego_size_m.minCoeff() > 0.0)) Fail("parking scene: ego_size_m must be positive");
  if (!(bay_side_margin_m >= 0.0)) {
    Fail("parking scene: bay_side_margin_m = " + std::to_string(bay_side_margin_m) +
         " must be >= 0");
  }
}

ParkingScene::ParkingScene(const ParkingSceneParams& params) : params_(params) {
  params_.Validate();
  BuildStatic();
  BuildPedestrians();
}

void ParkingScene::BuildStatic() {
  internal::Rng rng(params_.seed, 1);
  const std::uint32_t seed32 = static_cast<std::uint32_t>(internal::Mix64(params_.seed));

  // Curb and hedge along the back of the row.
  SceneObject curb;
  curb.box = {kCurbId, "curb",
              Eigen::Vector3d(0, kCurbNearY + kCurbWidth / 2, kCurbHeight / 2),
              Eigen::Vector3d(2 * kRowHalfLength, kCurbWidth, kCurbHeight), 0.0,
              Eigen::Vector3d::Zero()};
  curb.material = Material::kCurb;
  curb.albedo = 0.62f;
  curb.texture_seed = seed32 ^ 0x1111u;
  static_objects_.push_back(curb);
  SceneObject hedge;
  hedge.box = {kHedgeId, "wall", Eigen::Vector3d(0, kHedgeY, kHedgeHeight / 2),
               Eigen::Vector3d(2 * kRowHalfLength, kHedgeDepth, kHedgeHeight), 0.0,
               Eigen::Vector3d::Zero()};
  hedge.material = Material::kHedge;
  hedge.albedo = 0.3f;
  hedge.texture_seed = seed32 ^ 0x2222u;
  static_objects_.push_back(hedge);

  // The wide bay's centre is the reference; cars are laid out from it to both sides.
  const double wide_gap = rng.Uniform(3.4, 4.0);
  const double narrow_gap = rng.Uniform(1.6, 2.1);
  const double x_wide = rng.Uniform(-1.0, 1.0);
  struct Slot {
    double length, width, height, yaw, y;
    float albedo;
  };
  auto draw_car = [&]() {
    Slot s;
    s.length = rng.Uniform(4.0, 5.0);
    s.width = rng.Uniform(1.7, 1.9);
    s.height = rng.Uniform(1.4, 1.6);
    // Parked nose in or nose out, a little skewed.
    s.yaw = (rng.Uniform(0, 1) < 0.5 ? 0.5 : -0.5) * kPi + rng.Uniform(-0.03, 0.03);
    s.y = kBayFrontY + rng.Uniform(0.2, 0.5) + s.length / 2;
    s.albedo = static_cast<float>(rng.Uniform(0.2, 0.75));
    return s;
  };
  // Cars as seen along +x: 4 west of the wide bay, then 2, the narrow gap, then 3.
  const int n_west = 4, n_mid = 2, n_east = 3;
  std::vector<SceneObject> cars;
  int next_id = kFirstCarId;
  // A car of yaw ~ +-90 deg spans about its width along x; place by its footprint exactly.
  auto place = [&](const Slot& s, double edge_x, bool east_of_edge) {
    const int id = next_id++;
    SceneObject car = MakeCar(id, 0.0, s.y, s.length, s.width, s.height, s.yaw, s.albedo,
                              seed32 ^ (0x3000u + static_cast<std::uint32_t>(id)));
    const auto [lo, hi] = XRange(car.box);
    car.box.center_m.x() = east_of_edge ? edge_x - lo : edge_x - hi;
    return car;
  };
  std::vector<SceneObject> west;
  double edge = x_wide - wide_gap / 2;
  for (int i = 0; i < n_west; ++i) {
    const SceneObject car = place(draw_car(), edge, false);
    edge = XRange(car.box).first - rng.Uniform(0.6, 1.0);
    west.push_back(car);
  }
  std::reverse(west.begin(), west.end());
  cars.insert(cars.end(), west.begin(), west.end());
  edge = x_wide + wide_gap / 2;
  for (int i = 0; i < n_mid + n_east; ++i) {
    const SceneObject car = place(draw_car(), edge, true);
    const double gap = (i == n_mid - 1) ? narrow_gap : rng.Uniform(0.6, 1.0);
    edge = XRange(car.box).second + gap;
    cars.push_back(car);
  }
  // Ids west to east.
  for (std::size_t i = 0; i < cars.size(); ++i) cars[i].box.id = kFirstCarId + static_cast<int>(i);

  // Bay separator lines halfway between neighbours, and the bay front line.
  const double line_end_y = kCurbNearY - 0.2;
  for (std::size_t i = 0; i + 1 < cars.size(); ++i) {
    const double a = XRange(cars[i].box).second;
    const double b = XRange(cars[i + 1].box).first;
    const double gap = b - a;
    if (gap > 1.2) {
      // A free bay: lines just outside both neighbours, and it is reported as truth.
      lines_.push_back({{a + 0.1, kBayFrontY}, {a + 0.1, line_end_y}, 0.12});
      lines_.push_back({{b - 0.1, kBayFrontY}, {b - 0.1, line_end_y}, 0.12});
      GtBay bay;
      bay.id = static_cast<int>(bays_.size()) + 1;
      bay.center_m = Eigen::Vector3d((a + b) / 2, (kBayFrontY + kCurbNearY) / 2, 0.0);
      bay.width_m = gap;
      bay.depth_m = kCurbNearY - kBayFrontY;
      bay.yaw_rad = 0.0;
      bay.feasible = gap >= params_.ego_size_m.x() + 2 * params_.bay_side_margin_m;
      bay.left_car_id = cars[i].box.id;
      bay.right_car_id = cars[i + 1].box.id;
      bays_.push_back(bay);
    } else {
      const double x = (a + b) / 2;
      lines_.push_back({{x, kBayFrontY}, {x, line_end_y}, 0.12});
    }
  }
  const double row_lo = XRange(cars.front().box).first - 1.0;
  const double row_hi = XRange(cars.back().box).second + 1.0;
  lines_.push_back({{row_lo, kBayFrontY - 0.06}, {row_hi, kBayFrontY - 0.06}, 0.12});
  static_objects_.insert(static_objects_.end(), cars.begin(), cars.end());

  bay_center_m_ = Eigen::Vector2d(x_wide, (kBayFrontY + kCurbNearY) / 2);
  const double half_diag = 0.5 * params_.ego_size_m.head<2>().norm();
  spot_y_m_ = kBayFrontY - half_diag - kSpotClearanceM;
  start_y_m_ = spot_y_m_ - kApproachLengthM;
  final_y_m_ = kBayFrontY + params_.ego_size_m.y() / 2 + kEntryDepthM;
}

void ParkingScene::BuildPedestrians() {
  internal::Rng rng(params_.seed, 2);
  const double xb = bay_center_m_.x();
  auto body = [&]() {
    return Eigen::Vector3d(rng.Uniform(0.35, 0.45), rng.Uniform(0.45, 0.55),
                           rng.Uniform(1.6, 1.9));
  };
  auto albedo = [&]() { return static_cast<float>(rng.Uniform(0.2, 0.7)); };

  // 11 and 12 walk in single file towards the turning spot along the ego's later line of sight:
  // the near one (taller, wider) hides the far one totally while the ego turns (Fig. 4.16c,
  // middle), then both stop, turn and walk away.
  {
    Eigen::Vector3d a = body(), b = body();
    if (a.z() < b.z()) std::swap(a.z(), b.z());
    if (a.y() < b.y()) std::swap(a.y(), b.y());
    const double line_y = spot_y_m_ + rng.Uniform(-0.1, 0.1);
    const double speed = rng.Uniform(0.95, 1.05);
    const double x0 = xb + 12.0 + rng.Uniform(-0.3, 0.3);
    const double stop = xb + 3.6 + rng.Uniform(0.0, 0.3);
    PedestrianScript near;
    near.id = 11;
    near.size_m = a;
    near.waypoints_m = {{x0, line_y}, {stop, line_y}, {xb + 4.5, -6.0}};
    near.pause_s = {0.0, rng.Uniform(2.2, 2.8), 0.0};
    near.speed_mps = speed;
    near.albedo = albedo();
    PedestrianScript far = near;
    far.id = 12;
    far.size_m = b;
    far.waypoints_m = {{x0 + 1.3, line_y}, {stop + 1.3, line_y}, {xb + 6.5, -6.0}};
    far.pause_s = {0.0, near.pause_s[1] - 0.5, 0.0};
    far.albedo = albedo();
    pedestrians_.push_back(near);
    pedestrians_.push_back(far);
  }
  // 13 and 14 walk side by side west of the ego's path; seen from the ego the far one is partly
  // hidden and their blobs merge (Fig. 4.16c, bottom). Both turn west at the same line.
  {
    const double speed = rng.Uniform(1.1, 1.3);
    const double x = xb - 4.5 + rng.Uniform(-0.3, 0.3);
    const double y0 = start_y_m_ - 0.3 + rng.Uniform(-0.3, 0.3);
    const double turn_y = kBayFrontY - 1.0;
    const double pause = rng.Uniform(0.8, 1.2);
    PedestrianScript p13;
    p13.id = 13;
    p13.size_m = body();
    p13.waypoints_m = {{x, y0}, {x, turn_y}, {x - 6.5, turn_y}};
    p13.pause_s = {0.0, pause, 0.0};
    p13.speed_mps = speed;
    p13.albedo = albedo();
    PedestrianScript p14 = p13;
    p14.id = 14;
    p14.size_m = body();
    p14.waypoints_m = {{x - 0.6, y0}, {x - 0.6, turn_y}, {x - 7.1, turn_y}};
    p14.albedo = albedo();
    pedestrians_.push_back(p13);
    pedestrians_.push_back(p14);
  }
  // 15 walks alone east of the ego: a stop and a turn on the way to its goal.
  {
    PedestrianScript p15;
    p15.id = 15;
    p15.size_m = body();
    const double x = xb + 8.5 + rng.Uniform(-0.5, 0.5);
    p15.waypoints_m = {{x, start_y_m_}, {x, spot_y_m_ - 4.5}, {x + 5.5, spot_y_m_ - 2.5}};
    p15.pause_s = {0.0, rng.Uniform(1.0, 2.0), 0.0};
    p15.start_s = rng.Uniform(0.5, 1.5);
    p15.speed_mps = rng.Uniform(1.0, 1.4);
    p15.albedo = albedo();
    pedestrians_.push_back(p15);
  }
}

double ParkingScene::maneuver_duration_s() const {
  return kApproachS + kWaitS + kTurnS + kWaitS + kEntryS;
}

EgoState ParkingScene::EgoAt(double t) const {
  const double xb = bay_center_m_.x();
  double x = xb, y = start_y_m_, yaw = kPi / 2, speed = 0.0, yaw_rate = 0.0;
  std::string phase;
  const double t_turn = kApproachS + kWaitS;
  const double t_entry = t_turn + kTurnS + kWaitS;
  if (t < kApproachS) {
    const double tau = std::max(t, 0.0) / kApproachS;
    y = start_y_m_ + kApproachLengthM * SmoothStep(tau);
    speed = kApproachLengthM * SmoothStepRate(tau) / kApproachS;
    phase = "approach";
  } else if (t < t_turn) {
    y = spot_y_m_;
    phase = "wait";
  } else if (t < t_turn + kTurnS) {
    // Turn right on the spot from heading north to heading east: the ego's left side (its
    // sideways direction) then faces the bay.
    const double tau = (t - t_turn) / kTurnS;
    y = spot_y_m_;
    yaw = kPi / 2 - (kPi / 2) * SmoothStep(tau);
    yaw_rate = -(kPi / 2) * SmoothStepRate(tau) / kTurnS;
    phase = "turn";
  } else if (t < t_entry) {
    y = spot_y_m_;
    yaw = 0.0;
    phase = "wait";
  } else if (t < t_entry + kEntryS) {
    const double tau = (t - t_entry) / kEntryS;
    y = spot_y_m_ + (final_y_m_ - spot_y_m_) * SmoothStep(tau);
    yaw = 0.0;
    speed = (final_y_m_ - spot_y_m_) * SmoothStepRate(tau) / kEntryS;
    phase = "entry";
  } else {
    y = final_y_m_;
    yaw = 0.0;
    phase = "parked";
  }
  EgoState s;
  s.T_world_vehicle = Eigen::Translation3d(x, y, 0.0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  s.speed_mps = speed;
  s.yaw_rate_radps = yaw_rate;
  s.phase = phase;
  return s;
}

PedestrianState EvaluatePedestrian(const PedestrianScript& script, double time_s) {
  ROMO_THROW_UNLESS(script.waypoints_m.size() >= 2 && script.speed_mps > 0.0);
  PedestrianState state;
  const auto& w = script.waypoints_m;
  auto heading_of = [&](std::size_t leg) {
    const Eigen::Vector2d d = w[leg + 1] - w[leg];
    return std::atan2(d.y(), d.x());
  };
  state.position_m = w[0];
  state.heading_rad = heading_of(0);
  double t = time_s - script.start_s;
  if (t <= 0.0) return state;
  for (std::size_t leg = 0; leg + 1 < w.size(); ++leg) {
    const Eigen::Vector2d d = w[leg + 1] - w[leg];
    const double duration = d.norm() / script.speed_mps;
    state.heading_rad = heading_of(leg);
    if (t < duration) {
      state.position_m = w[leg] + d * (t / duration);
      state.velocity_mps = d.normalized() * script.speed_mps;
      return state;
    }
    t -= duration;
    state.position_m = w[leg + 1];
    const double pause = leg + 1 < script.pause_s.size() ? script.pause_s[leg + 1] : 0.0;
    if (t < pause) return state;
    t -= pause;
  }
  return state;
}

std::vector<GtBox> ParkingScene::ObjectsAt(double time_s) const {
  std::vector<GtBox> boxes;
  for (const auto& o : static_objects_) boxes.push_back(o.box);
  for (const auto& p : pedestrians_) {
    const PedestrianState s = EvaluatePedestrian(p, time_s);
    GtBox box;
    box.id = p.id;
    box.class_name = "pedestrian";
    box.center_m = Eigen::Vector3d(s.position_m.x(), s.position_m.y(), p.size_m.z() / 2);
    box.size_m = p.size_m;
    box.yaw_rad = s.heading_rad;
    box.velocity_mps = Eigen::Vector3d(s.velocity_mps.x(), s.velocity_mps.y(), 0.0);
    boxes.push_back(box);
  }
  return boxes;
}

SceneSnapshot ParkingScene::At(double time_s) const {
  SceneSnapshot snap;
  snap.time_s = time_s;
  snap.ego = EgoAt(time_s);
  snap.objects = static_objects_;
  const std::vector<GtBox> boxes = ObjectsAt(time_s);
  for (std::size_t i = 0; i < pedestrians_.size(); ++i) {
    SceneObject o;
    o.box = boxes[static_objects_.size() + i];
    o.material = Material::kPedestrian;
    o.albedo = pedestrians_[i].albedo;
    o.texture_seed = static_cast<std::uint32_t>(internal::Hash(params_.seed, 0x5000u + o.box.id));
    snap.objects.push_back(o);
  }
  snap.lines = &lines_;
  snap.ground_seed = static_cast<std::uint32_t>(internal::Hash(params_.seed, 0x6000u));
  return snap;
}

}  // namespace romo::sim
