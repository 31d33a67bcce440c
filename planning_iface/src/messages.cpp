#include "romo/planning_iface/messages.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "romo/core/check.hpp"
#include "romo/drivers/lcm_walker.hpp"
#include "romo_lcm/obstacle_list_t.hpp"
#include "romo_lcm/parking_slots_t.hpp"
#include "romo_lcm/perception_status_t.hpp"
#include "romo_lcm/rig_cloud_t.hpp"

namespace romo::planning_iface {
namespace {

constexpr int kMaxRigs = 64;
constexpr std::size_t kMaxNameLength = 64;

template <typename Msg>
std::vector<std::uint8_t> EncodeMessage(const Msg& msg) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(msg.getEncodedSize()));
  const int n = msg.encode(out.data(), 0, static_cast<int>(out.size()));
  ROMO_DEMAND(n == static_cast<int>(out.size()));
  return out;
}

void SetWhy(std::string* why, const std::string& text) {
  if (why != nullptr) *why = text;
}

// LCM's generated decoders size their arrays from the counts in the message before checking the
// buffer, so a corrupt count could ask for gigabytes: each message is walked first with the
// shared bounds checks (drivers::LcmWalker, as the sensor and prediction decoders do).
using drivers::LcmWalker;

bool WalkObstacleList(LcmWalker& w) {
  std::int32_t n = 0;
  if (!(w.Skip(8 + 16) && w.Count(4 + 5 + 4 + 8 * 13 + 4, &n, "num_obstacles"))) return false;
  for (std::int32_t i = 0; i < n; ++i) {
    if (!(w.Skip(4) && w.String("class_name") && w.Skip(4 + 8 * 13 + 4))) return false;
  }
  return true;
}

bool WalkParkingSlots(LcmWalker& w) {
  std::int32_t n = 0;
  if (!(w.Skip(8 + 16 + 1 + 24) && w.Count(150, &n, "num_slots"))) return false;
  for (std::int32_t i = 0; i < n; ++i) {
    std::int32_t points = 0;
    if (!(w.Skip(4 + 1) && w.String("reason") && w.Skip(4 + 4 + 4 + 8 * 12) &&
          w.Count(16, &points, "num_path_points") && w.Skip(16 * static_cast<std::size_t>(points)) &&
          w.Skip(8 + 24))) {
      return false;
    }
  }
  return true;
}

bool WalkPerceptionStatus(LcmWalker& w) {
  std::int32_t n = 0;
  if (!(w.Skip(8 + 16) && w.Count(29, &n, "num_rigs") && w.Skip(29 * static_cast<std::size_t>(n)) &&
        w.Count(9, &n, "num_stages"))) {
    return false;
  }
  for (std::int32_t i = 0; i < n; ++i) {
    if (!(w.String("stages.name") && w.Skip(4))) return false;
  }
  if (!(w.Skip(4 + 24) && w.Count(5, &n, "num_events"))) return false;
  for (std::int32_t i = 0; i < n; ++i) {
    if (!w.String("events")) return false;
  }
  return true;
}

bool WalkRigCloud(LcmWalker& w) {
  std::int32_t points = 0, coords = 0;
  return w.Skip(8 + 24 + 8) && w.Count(3, &points, "num_points") && w.Count(2, &coords, "num_coords") &&
         w.Skip(2 * static_cast<std::size_t>(coords)) && w.Skip(3 * static_cast<std::size_t>(points)) &&
         w.Skip(8 + 1 + 8 * 9 + 4);
}

bool Walk(const void* data, std::size_t size, bool (*walk)(LcmWalker&), const char* type,
          std::string* why) {
  if (data == nullptr) {
    SetWhy(why, std::string(type) + ": no data");
    return false;
  }
  LcmWalker w(data, size);
  if (!walk(w)) {
    SetWhy(why, w.Reason(type));
    return false;
  }
  return true;
}

template <typename Msg>
bool DecodeMessage(const void* data, std::size_t size, const char* type, Msg* msg, std::string* why) {
  if (data == nullptr || size < 8 || size > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    SetWhy(why, std::string(type) + ": empty or oversized message (" + std::to_string(size) + " bytes)");
    return false;
  }
  int n = -1;
  try {
    n = msg->decode(data, 0, static_cast<int>(size));
  } catch (const std::exception& e) {  // a negative count makes the generated code throw
    SetWhy(why, std::string(type) + ": corrupt counts (" + e.what() + ")");
    return false;
  }
  if (n < 0) {
    SetWhy(why, std::string(type) + ": wrong type hash or truncated (" + std::to_string(size) + " bytes)");
    return false;
  }
  if (static_cast<std::size_t>(n) != size) {
    SetWhy(why, std::string(type) + ": " + std::to_string(size - n) + " trailing bytes");
    return false;
  }
  return true;
}

bool Finite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

bool NameOk(const std::string& s) {
  if (s.empty() || s.size() > kMaxNameLength) return false;
  for (char c : s) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) return false;
  }
  return true;
}

Eigen::Vector2d Rotate(const Eigen::Vector2d& v, double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

Eigen::Vector2d ToVehicle(const Eigen::Vector2d& p_world, const Pose2& ego) {
  return Rotate(p_world - ego.position_m, -ego.yaw_rad);
}

Eigen::Vector2d ToWorld(const Eigen::Vector2d& p_vehicle, const Pose2& ego) {
  return ego.position_m + Rotate(p_vehicle, ego.yaw_rad);
}

}  // namespace

std::string RigCloudChannel(int rig_id) { return kRigCloudChannelPrefix + std::to_string(rig_id); }

ParkingSlot SlotInVehicleFrame(const ParkingSlot& s, const Pose2& ego) {
  ParkingSlot v = s;
  v.target.position_m = ToVehicle(s.target.position_m, ego);
  v.target.yaw_rad = WrapAngle(s.target.yaw_rad - ego.yaw_rad);
  v.approach.position_m = ToVehicle(s.approach.position_m, ego);
  v.approach.yaw_rad = WrapAngle(s.approach.yaw_rad - ego.yaw_rad);
  for (auto& p : v.entry_path_m) p = ToVehicle(p, ego);
  v.row_axis = Rotate(s.row_axis, -ego.yaw_rad);
  v.aisle_normal = Rotate(s.aisle_normal, -ego.yaw_rad);
  for (GroundBox* b : {&v.prev_box, &v.next_box}) {
    b->center_m = ToVehicle(b->center_m, ego);
    b->yaw_rad = WrapAngle(b->yaw_rad - ego.yaw_rad);
  }
  return v;
}

std::vector<std::uint8_t> Encode(const ObstacleList& list) {
  romo_lcm::obstacle_list_t msg;
  msg.stamp_ns = list.stamp_ns;
  msg.frame_sequence = list.frame_sequence;
  msg.num_obstacles = static_cast<std::int32_t>(list.obstacles.size());
  for (const auto& o : list.obstacles) {
    romo_lcm::obstacle_t m;
    m.track_id = o.track_id;
    m.class_name = o.class_name;
    m.score = o.score;
    for (int k = 0; k < 3; ++k) {
      m.center_m[k] = o.center_m[k];
      m.size_m[k] = o.size_m[k];
    }
    m.yaw_rad = o.yaw_rad;
    m.velocity_mps[0] = o.velocity_mps.x();
    m.velocity_mps[1] = o.velocity_mps.y();
    for (int k = 0; k < 4; ++k) m.velocity_cov[k] = o.velocity_cov(k / 2, k % 2);
    m.num_points = o.num_points;
    msg.obstacles.push_back(std::move(m));
  }
  return EncodeMessage(msg);
}

std::optional<ObstacleList> DecodeObstacleList(const void* data, std::size_t size, std::string* why) {
  romo_lcm::obstacle_list_t msg;
  if (!Walk(data, size, WalkObstacleList, "obstacle_list_t", why) ||
      !DecodeMessage(data, size, "obstacle_list_t", &msg, why)) {
    return std::nullopt;
  }
  ObstacleList out;
  out.stamp_ns = msg.stamp_ns;
  out.frame_sequence = msg.frame_sequence;
  for (std::size_t i = 0; i < msg.obstacles.size(); ++i) {
    const auto& m = msg.obstacles[i];
    const std::string where = "obstacle_list_t.obstacles[" + std::to_string(i) + "]";
    if (!NameOk(m.class_name)) {
      SetWhy(why, where + ".class_name is empty, too long or not printable");
      return std::nullopt;
    }
    if (!Finite(m.center_m, 3) || !Finite(m.size_m, 3) || !std::isfinite(m.yaw_rad) ||
        !Finite(m.velocity_mps, 2) || !Finite(m.velocity_cov, 4) || !std::isfinite(m.score)) {
      SetWhy(why, where + " has a non-finite value");
      return std::nullopt;
    }
    if (m.size_m[0] < 0 || m.size_m[1] < 0 || m.size_m[2] < 0 || m.num_points < 0) {
      SetWhy(why, where + " has a negative size or point count");
      return std::nullopt;
    }
    Obstacle o;
    o.track_id = m.track_id;
    o.class_name = m.class_name;
    o.score = m.score;
    o.center_m = Eigen::Vector3d(m.center_m[0], m.center_m[1], m.center_m[2]);
    o.size_m = Eigen::Vector3d(m.size_m[0], m.size_m[1], m.size_m[2]);
    o.yaw_rad = m.yaw_rad;
    o.velocity_mps = Eigen::Vector2d(m.velocity_mps[0], m.velocity_mps[1]);
    for (int k = 0; k < 4; ++k) o.velocity_cov(k / 2, k % 2) = m.velocity_cov[k];
    o.num_points = m.num_points;
    out.obstacles.push_back(std::move(o));
  }
  return out;
}

std::vector<std::uint8_t> Encode(const ParkingSlotReport& report) {
  romo_lcm::parking_slots_t msg;
  msg.stamp_ns = report.stamp_ns;
  msg.frame_sequence = report.frame_sequence;
  msg.stage = static_cast<std::int8_t>(report.stage);
  msg.ego_world_m[0] = report.ego_world.position_m.x();
  msg.ego_world_m[1] = report.ego_world.position_m.y();
  msg.ego_yaw_world_rad = report.ego_world.yaw_rad;
  msg.num_slots = static_cast<std::int32_t>(report.slots.size());
  for (const auto& w : report.slots) {
    const ParkingSlot v = SlotInVehicleFrame(w, report.ego_world);
    romo_lcm::parking_slot_t m;
    m.slot_id = w.slot_id;
    m.feasible = w.feasible;
    m.reason = w.reason;
    m.confidence = static_cast<float>(w.confidence);
    m.seen_frames = w.seen_frames;
    m.missed_frames = w.missed_frames;
    m.center_m[0] = v.target.position_m.x();
    m.center_m[1] = v.target.position_m.y();
    m.yaw_rad = v.target.yaw_rad;
    m.center_world_m[0] = w.target.position_m.x();
    m.center_world_m[1] = w.target.position_m.y();
    m.yaw_world_rad = w.target.yaw_rad;
    m.length_m = w.length_m;
    m.depth_m = w.depth_m;
    m.approach_m[0] = v.approach.position_m.x();
    m.approach_m[1] = v.approach.position_m.y();
    m.approach_yaw_rad = v.approach.yaw_rad;
    m.rotation_rad = w.rotation_rad;
    m.num_path_points = static_cast<std::int32_t>(v.entry_path_m.size());
    for (const auto& p : v.entry_path_m) m.entry_path_m.push_back({p.x(), p.y()});
    m.prev_track_id = w.prev_id;
    m.next_track_id = w.next_id;
    m.clearance_prev_m = w.clearance_prev_m;
    m.clearance_next_m = w.clearance_next_m;
    m.clearance_other_m = w.clearance_other_m;
    msg.slots.push_back(std::move(m));
  }
  return EncodeMessage(msg);
}

std::optional<ParkingSlotReport> DecodeParkingSlots(const void* data, std::size_t size,
                                                    std::string* why) {
  romo_lcm::parking_slots_t msg;
  if (!Walk(data, size, WalkParkingSlots, "parking_slots_t", why) ||
      !DecodeMessage(data, size, "parking_slots_t", &msg, why)) {
    return std::nullopt;
  }
  if (msg.stage < 0 || msg.stage > static_cast<int>(ManeuverStage::kStopped)) {
    SetWhy(why, "parking_slots_t.stage = " + std::to_string(msg.stage) + " is not 0..4");
    return std::nullopt;
  }
  if (!Finite(msg.ego_world_m, 2) || !std::isfinite(msg.ego_yaw_world_rad)) {
    SetWhy(why, "parking_slots_t.ego_world has a non-finite value");
    return std::nullopt;
  }
  ParkingSlotReport out;
  out.stamp_ns = msg.stamp_ns;
  out.frame_sequence = msg.frame_sequence;
  out.stage = static_cast<ManeuverStage>(msg.stage);
  out.ego_world.position_m = Eigen::Vector2d(msg.ego_world_m[0], msg.ego_world_m[1]);
  out.ego_world.yaw_rad = msg.ego_yaw_world_rad;
  for (std::size_t i = 0; i < msg.slots.size(); ++i) {
    const auto& m = msg.slots[i];
    const std::string where = "parking_slots_t.slots[" + std::to_string(i) + "]";
    bool finite = Finite(m.center_m, 2) && Finite(m.center_world_m, 2) && Finite(m.approach_m, 2) &&
                  std::isfinite(m.yaw_rad) && std::isfinite(m.yaw_world_rad) &&
                  std::isfinite(m.length_m) && std::isfinite(m.depth_m) &&
                  std::isfinite(m.approach_yaw_rad) && std::isfinite(m.rotation_rad) &&
                  std::isfinite(m.clearance_prev_m) && std::isfinite(m.clearance_next_m) &&
                  std::isfinite(m.clearance_other_m);
    for (const auto& p : m.entry_path_m) finite = finite && Finite(p.data(), 2);
    if (!finite) {
      SetWhy(why, where + " has a non-finite value");
      return std::nullopt;
    }
    if (!(m.confidence >= 0.f && m.confidence <= 1.f) || m.length_m < 0 || m.depth_m < 0) {
      SetWhy(why, where + ": confidence " + std::to_string(m.confidence) + " not in [0, 1] or negative size");
      return std::nullopt;
    }
    ParkingSlot s;
    s.slot_id = m.slot_id;
    s.feasible = m.feasible;
    s.reason = m.reason;
    s.confidence = m.confidence;
    s.seen_frames = m.seen_frames;
    s.missed_frames = m.missed_frames;
    s.target.position_m = Eigen::Vector2d(m.center_world_m[0], m.center_world_m[1]);
    s.target.yaw_rad = m.yaw_world_rad;
    s.length_m = m.length_m;
    s.depth_m = m.depth_m;
    s.approach.position_m = ToWorld(Eigen::Vector2d(m.approach_m[0], m.approach_m[1]), out.ego_world);
    s.approach.yaw_rad = WrapAngle(m.approach_yaw_rad + out.ego_world.yaw_rad);
    s.rotation_rad = m.rotation_rad;
    for (const auto& p : m.entry_path_m) {
      s.entry_path_m.push_back(ToWorld(Eigen::Vector2d(p[0], p[1]), out.ego_world));
    }
    const Eigen::Vector2d to_aisle = s.approach.position_m - s.target.position_m;
    if (to_aisle.norm() > 1e-9) {
      s.aisle_normal = to_aisle.normalized();
      s.row_axis = Eigen::Vector2d(s.aisle_normal.y(), -s.aisle_normal.x());
    }
    s.prev_id = m.prev_track_id;
    s.next_id = m.next_track_id;
    s.clearance_prev_m = m.clearance_prev_m;
    s.clearance_next_m = m.clearance_next_m;
    s.clearance_other_m = m.clearance_other_m;
    out.slots.push_back(std::move(s));
  }
  return out;
}

std::vector<std::uint8_t> Encode(const PerceptionStatus& status) {
  romo_lcm::perception_status_t msg;
  msg.stamp_ns = status.stamp_ns;
  msg.frame_sequence = status.frame_sequence;
  msg.num_rigs = static_cast<std::int32_t>(status.rigs.size());
  for (const auto& r : status.rigs) {
    romo_lcm::rig_status_t m;
    m.rig_id = r.rig_id;
    m.present = r.present;
    m.frame_rate_hz = static_cast<float>(r.frame_rate_hz);
    m.frames = r.frames;
    m.dropped = r.dropped;
    m.points = r.points;
    msg.rigs.push_back(m);
  }
  msg.num_stages = static_cast<std::int32_t>(status.stages.size());
  for (const auto& s : status.stages) {
    romo_lcm::stage_latency_t m;
    m.name = s.name;
    m.latency_ms = static_cast<float>(s.latency_ms);
    msg.stages.push_back(m);
  }
  msg.total_latency_ms = static_cast<float>(status.total_latency_ms);
  msg.frames_processed = status.frames_processed;
  msg.frames_dropped = status.frames_dropped;
  msg.malformed_messages = status.malformed_messages;
  msg.num_events = static_cast<std::int32_t>(status.events.size());
  msg.events = status.events;
  return EncodeMessage(msg);
}

std::optional<PerceptionStatus> DecodePerceptionStatus(const void* data, std::size_t size,
                                                       std::string* why) {
  romo_lcm::perception_status_t msg;
  if (!Walk(data, size, WalkPerceptionStatus, "perception_status_t", why) ||
      !DecodeMessage(data, size, "perception_status_t", &msg, why)) {
    return std::nullopt;
  }
  PerceptionStatus out;
  out.stamp_ns = msg.stamp_ns;
  out.frame_sequence = msg.frame_sequence;
  for (const auto& m : msg.rigs) {
    if (m.rig_id < 0 || m.rig_id >= kMaxRigs || !std::isfinite(m.frame_rate_hz)) {
      SetWhy(why, "perception_status_t.rigs: rig_id " + std::to_string(m.rig_id) +
                      " out of range or non-finite rate");
      return std::nullopt;
    }
    out.rigs.push_back({m.rig_id, m.present != 0, m.frame_rate_hz, m.frames, m.dropped, m.points});
  }
  for (const auto& m : msg.stages) {
    if (!NameOk(m.name) || !std::isfinite(m.latency_ms)) {
      SetWhy(why, "perception_status_t.stages: bad name or non-finite latency");
      return std::nullopt;
    }
    out.stages.push_back({m.name, m.latency_ms});
  }
  out.total_latency_ms = msg.total_latency_ms;
  out.frames_processed = msg.frames_processed;
  out.frames_dropped = msg.frames_dropped;
  out.malformed_messages = msg.malformed_messages;
  out.events = msg.events;
  return out;
}

std::vector<std::uint8_t> Encode(const RigCloud& rc, double scale_m) {
  ROMO_THROW_UNLESS(scale_m > 0 && std::isfinite(scale_m));
  ROMO_THROW_UNLESS(rc.cloud.IsConsistent());
  romo_lcm::rig_cloud_t msg;
  msg.stamp_ns = rc.stamp_ns;
  msg.frame_sequence = rc.frame_sequence;
  msg.capture_stamp_ns = rc.capture_stamp_ns;
  msg.rig_id = rc.rig_id;
  msg.scale_m = static_cast<float>(scale_m);
  msg.stereo_ms = static_cast<float>(rc.stereo_ms);
  const double limit = 32767.0;
  const std::size_t n = rc.cloud.size();
  msg.xyz_q.reserve(3 * n);
  msg.sigma_q.reserve(n);
  msg.intensity.reserve(n);
  int dropped = rc.dropped_out_of_range;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f p = rc.cloud.xyz.col(static_cast<Eigen::Index>(i));
    const double qx = std::round(p.x() / scale_m), qy = std::round(p.y() / scale_m),
                 qz = std::round(p.z() / scale_m);
    const double qs = std::round(std::min<double>(rc.cloud.sigma_z_m[i] / scale_m, limit));
    if (!(std::abs(qx) <= limit && std::abs(qy) <= limit && std::abs(qz) <= limit && qs >= 0)) {
      ++dropped;
      continue;
    }
    msg.xyz_q.push_back(static_cast<std::int16_t>(qx));
    msg.xyz_q.push_back(static_cast<std::int16_t>(qy));
    msg.xyz_q.push_back(static_cast<std::int16_t>(qz));
    msg.sigma_q.push_back(static_cast<std::int16_t>(qs));
    msg.intensity.push_back(static_cast<std::uint8_t>(std::clamp(rc.cloud.intensity[i], 0.f, 255.f)));
  }
  msg.num_points = static_cast<std::int32_t>(msg.sigma_q.size());
  msg.num_coords = 3 * msg.num_points;
  msg.dropped_out_of_range = dropped;
  ROMO_THROW_UNLESS(rc.image_width_px >= 0);
  msg.image_width_px = rc.image_width_px;
  msg.has_vehicle = rc.vehicle.has_value();
  if (rc.vehicle) {
    const Eigen::Vector3d t = rc.vehicle->T_world_vehicle.translation();
    const Eigen::Quaterniond q(rc.vehicle->T_world_vehicle.rotation());
    for (int k = 0; k < 3; ++k) msg.position_m[k] = t[k];
    msg.orientation_wxyz[0] = q.w();
    msg.orientation_wxyz[1] = q.x();
    msg.orientation_wxyz[2] = q.y();
    msg.orientation_wxyz[3] = q.z();
    msg.speed_mps = rc.vehicle->speed_mps;
    msg.yaw_rate_radps = rc.vehicle->yaw_rate_radps;
  }
  return EncodeMessage(msg);
}

std::optional<RigCloud> DecodeRigCloud(const void* data, std::size_t size, std::string* why) {
  romo_lcm::rig_cloud_t msg;
  if (!Walk(data, size, WalkRigCloud, "rig_cloud_t", why) ||
      !DecodeMessage(data, size, "rig_cloud_t", &msg, why)) {
    return std::nullopt;
  }
  if (msg.num_coords != 3 * msg.num_points) {
    SetWhy(why, "rig_cloud_t.num_coords = " + std::to_string(msg.num_coords) + " is not 3 x num_points (" +
                    std::to_string(msg.num_points) + ")");
    return std::nullopt;
  }
  if (msg.rig_id < 0 || msg.rig_id >= kMaxRigs) {
    SetWhy(why, "rig_cloud_t.rig_id = " + std::to_string(msg.rig_id) + " out of range 0.." +
                    std::to_string(kMaxRigs - 1));
    return std::nullopt;
  }
  if (!(msg.scale_m > 0.f) || !std::isfinite(msg.scale_m) || msg.scale_m > 1.f) {
    SetWhy(why, "rig_cloud_t.scale_m = " + std::to_string(msg.scale_m) + " not in (0, 1] m");
    return std::nullopt;
  }
  // Overflow-free |capture - stamp| <= the limit.
  const bool capture_near = msg.capture_stamp_ns >= msg.stamp_ns
                                ? msg.capture_stamp_ns - kMaxCaptureOffsetNs <= msg.stamp_ns
                                : msg.stamp_ns - kMaxCaptureOffsetNs <= msg.capture_stamp_ns;
  if (!capture_near) {
    SetWhy(why, "rig_cloud_t.capture_stamp_ns = " + std::to_string(msg.capture_stamp_ns) +
                    " is more than 1 s from the frame's stamp_ns = " + std::to_string(msg.stamp_ns));
    return std::nullopt;
  }
  if (msg.image_width_px < 0) {
    SetWhy(why, "rig_cloud_t.image_width_px = " + std::to_string(msg.image_width_px) + " is negative");
    return std::nullopt;
  }
  for (std::int16_t s : msg.sigma_q) {
    if (s < 0) {
      SetWhy(why, "rig_cloud_t.sigma_q has a negative value " + std::to_string(s));
      return std::nullopt;
    }
  }
  RigCloud out;
  if (msg.has_vehicle) {
    const Eigen::Quaterniond q(msg.orientation_wxyz[0], msg.orientation_wxyz[1], msg.orientation_wxyz[2],
                               msg.orientation_wxyz[3]);
    if (!Finite(msg.position_m, 3) || !Finite(msg.orientation_wxyz, 4) || !std::isfinite(msg.speed_mps) ||
        !std::isfinite(msg.yaw_rate_radps) || std::abs(q.norm() - 1.0) > 1e-3) {
      SetWhy(why, "rig_cloud_t vehicle state is not finite or its quaternion is not unit");
      return std::nullopt;
    }
    drivers::VehicleState v;
    v.stamp_ns = msg.stamp_ns;
    v.T_world_vehicle = Eigen::Translation3d(msg.position_m[0], msg.position_m[1], msg.position_m[2]) *
                        q.normalized();
    v.speed_mps = msg.speed_mps;
    v.yaw_rate_radps = msg.yaw_rate_radps;
    out.vehicle = v;
  }
  out.stamp_ns = msg.stamp_ns;
  out.frame_sequence = msg.frame_sequence;
  out.capture_stamp_ns = msg.capture_stamp_ns;
  out.rig_id = msg.rig_id;
  out.dropped_out_of_range = msg.dropped_out_of_range;
  out.stereo_ms = msg.stereo_ms;
  out.image_width_px = msg.image_width_px;
  const std::size_t n = static_cast<std::size_t>(msg.num_points);
  out.cloud.Resize(n);
  const float scale = msg.scale_m;
  for (std::size_t i = 0; i < n; ++i) {
    out.cloud.xyz(0, static_cast<Eigen::Index>(i)) = msg.xyz_q[3 * i] * scale;
    out.cloud.xyz(1, static_cast<Eigen::Index>(i)) = msg.xyz_q[3 * i + 1] * scale;
    out.cloud.xyz(2, static_cast<Eigen::Index>(i)) = msg.xyz_q[3 * i + 2] * scale;
    out.cloud.sigma_z_m[i] = msg.sigma_q[i] * scale;
    out.cloud.intensity[i] = msg.intensity[i];
  }
  return out;
}

}  // namespace romo::planning_iface
