#include "romo/sim/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "romo/core/check.hpp"
#include "romo/drivers/lcm_walker.hpp"
#include "romo_lcm/ground_truth_t.hpp"
#include "romo_lcm/gt_depth_t.hpp"

namespace romo::sim {

std::string DepthChannel(int rig_id) { return "ROMO_GT_DEPTH_RIG" + std::to_string(rig_id); }

bool GtBox::Contains(const Eigen::Vector3d& p, double margin_m) const {
  const Eigen::Vector3d d = p - center_m;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const double lx = c * d.x() + s * d.y();
  const double ly = -s * d.x() + c * d.y();
  return std::abs(lx) <= size_m.x() / 2 + margin_m && std::abs(ly) <= size_m.y() / 2 + margin_m &&
         std::abs(d.z()) <= size_m.z() / 2 + margin_m;
}

std::vector<Eigen::Vector2d> GtBox::Footprint() const {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const Eigen::Vector2d ax(c, s), ay(-s, c);
  const Eigen::Vector2d o = center_m.head<2>();
  const double hl = size_m.x() / 2, hw = size_m.y() / 2;
  return {o - hl * ax - hw * ay, o + hl * ax - hw * ay, o + hl * ax + hw * ay,
          o - hl * ax + hw * ay};
}

bool FootprintsOverlap(const GtBox& a, const GtBox& b) {
  const auto pa = a.Footprint(), pb = b.Footprint();
  // Two convex rectangles are disjoint iff some edge normal of either separates them.
  for (const auto* poly : {&pa, &pb}) {
    for (std::size_t i = 0; i < 4; ++i) {
      const Eigen::Vector2d e = (*poly)[(i + 1) % 4] - (*poly)[i];
      const Eigen::Vector2d n(-e.y(), e.x());
      double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
      for (const auto& p : pa) {
        amin = std::min(amin, n.dot(p));
        amax = std::max(amax, n.dot(p));
      }
      for (const auto& p : pb) {
        bmin = std::min(bmin, n.dot(p));
        bmax = std::max(bmax, n.dot(p));
      }
      if (amax < bmin || bmax < amin) return false;
    }
  }
  return true;
}

GtBox GtBay::AsBox(double height_m) const {
  GtBox box;
  box.id = id;
  box.class_name = "bay";
  box.center_m = Eigen::Vector3d(center_m.x(), center_m.y(), height_m / 2);
  box.size_m = Eigen::Vector3d(width_m, depth_m, height_m);
  box.yaw_rad = yaw_rad;
  return box;
}

const GtBox* GroundTruth::Find(int id) const {
  for (const auto& o : objects) {
    if (o.id == id) return &o;
  }
  return nullptr;
}

namespace {

// LCM's generated decoders allocate arrays from the counts before checking the bytes, so the
// counts are walked first (drivers/lcm_walker.hpp), from the 8-byte type hash on. Minimum
// encoded sizes: gt_object_t 89 bytes (id, class_name of at least its NUL, 10 doubles),
// gt_bay_t 61, one gt_depth_t pixel 12.
bool WalkGroundTruth(drivers::LcmWalker& w) {
  std::int32_t objects = 0;
  if (!(w.Skip(8 + 8 + 8) && w.String("scene") && w.Skip(8 + 3 * 8 + 3 * 8 + 4 * 8 + 8 + 8 + 3 * 8) &&
        w.String("ego_phase") && w.Skip(3 * 8) && w.Count(4 + 5 + 10 * 8, &objects, "num_objects"))) {
    return false;
  }
  for (std::int32_t i = 0; i < objects; ++i) {
    if (!(w.Skip(4) && w.String("objects.class_name") && w.Skip(10 * 8))) return false;
  }
  return w.FixedArray(4 + 6 * 8 + 1 + 4 + 4, "num_bays");
}

bool WalkGtDepth(drivers::LcmWalker& w) {
  return w.Skip(8 + 8 + 8 + 4 + 4 + 4) && w.FixedArray(4 + 4 + 2 + 2, "size");
}

void CheckCounts(const void* data, std::size_t size, std::int64_t hash,
                 bool (*walk)(drivers::LcmWalker&), const char* type, const std::string& origin) {
  if (!drivers::LcmHashMatches(data, size, hash)) return;  // the decoder names the wrong type
  drivers::LcmWalker w(data, size);
  if (!walk(w)) Fail(origin + ": " + w.Reason(std::string("romo_lcm.") + type));
}

template <typename Msg>
bool DecodeInto(const void* data, std::size_t size, Msg* m) {
  if (data == nullptr || size > static_cast<std::size_t>(std::numeric_limits<int>::max())) return false;
  try {
    return m->decode(data, 0, static_cast<int>(size)) >= 0;
  } catch (const std::exception&) {  // std::length_error from a count the walk let through
    return false;
  }
}

}  // namespace

std::vector<std::uint8_t> Encode(const GroundTruth& t) {
  romo_lcm::ground_truth_t m;
  m.stamp_ns = t.stamp_ns;
  m.frame_sequence = static_cast<std::int64_t>(t.sequence);
  m.scene = t.scene;
  m.seed = static_cast<std::int64_t>(t.seed);
  m.origin_latitude_deg = t.origin.latitude_deg;
  m.origin_longitude_deg = t.origin.longitude_deg;
  m.origin_altitude_m = t.origin.altitude_m;
  const Eigen::Vector3d p = t.T_world_vehicle.translation();
  const Eigen::Quaterniond q(t.T_world_vehicle.rotation());
  for (int i = 0; i < 3; ++i) m.ego_position_m[i] = p[i];
  m.ego_orientation_wxyz[0] = q.w();
  m.ego_orientation_wxyz[1] = q.x();
  m.ego_orientation_wxyz[2] = q.y();
  m.ego_orientation_wxyz[3] = q.z();
  m.ego_speed_mps = t.ego_speed_mps;
  m.ego_yaw_rate_radps = t.ego_yaw_rate_radps;
  for (int i = 0; i < 3; ++i) m.ego_size_m[i] = t.ego_size_m[i];
  m.ego_phase = t.ego_phase;
  m.latitude_deg = t.gnss.latitude_deg;
  m.longitude_deg = t.gnss.longitude_deg;
  m.altitude_m = t.gnss.altitude_m;
  m.num_objects = static_cast<std::int32_t>(t.objects.size());
  for (const auto& o : t.objects) {
    romo_lcm::gt_object_t mo;
    mo.id = o.id;
    mo.class_name = o.class_name;
    for (int i = 0; i < 3; ++i) {
      mo.center_m[i] = o.center_m[i];
      mo.size_m[i] = o.size_m[i];
      mo.velocity_mps[i] = o.velocity_mps[i];
    }
    mo.yaw_rad = o.yaw_rad;
    m.objects.push_back(mo);
  }
  m.num_bays = static_cast<std::int32_t>(t.bays.size());
  for (const auto& b : t.bays) {
    romo_lcm::gt_bay_t mb;
    mb.id = b.id;
    for (int i = 0; i < 3; ++i) mb.center_m[i] = b.center_m[i];
    mb.width_m = b.width_m;
    mb.depth_m = b.depth_m;
    mb.yaw_rad = b.yaw_rad;
    mb.feasible = b.feasible;
    mb.left_car_id = b.left_car_id;
    mb.right_car_id = b.right_car_id;
    m.bays.push_back(mb);
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  ROMO_DEMAND(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())) ==
              static_cast<int>(bytes.size()));
  return bytes;
}

GroundTruth DecodeGroundTruth(const void* data, std::size_t size, const std::string& origin) {
  CheckCounts(data, size, romo_lcm::ground_truth_t::getHash(), WalkGroundTruth, "ground_truth_t",
              origin);
  romo_lcm::ground_truth_t m;
  if (!DecodeInto(data, size, &m)) {
    Fail(origin + ": not a valid romo_lcm.ground_truth_t message (" + std::to_string(size) +
         " bytes)");
  }
  GroundTruth t;
  t.stamp_ns = m.stamp_ns;
  t.sequence = static_cast<std::uint64_t>(m.frame_sequence);
  t.scene = m.scene;
  t.seed = static_cast<std::uint64_t>(m.seed);
  t.origin = {m.origin_latitude_deg, m.origin_longitude_deg, m.origin_altitude_m};
  const Eigen::Quaterniond q(m.ego_orientation_wxyz[0], m.ego_orientation_wxyz[1],
                             m.ego_orientation_wxyz[2], m.ego_orientation_wxyz[3]);
  if (std::abs(q.norm() - 1.0) > 1e-6) {
    Fail(origin + ": ground truth ego_orientation_wxyz is not a unit quaternion (norm " +
         std::to_string(q.norm()) + ")");
  }
  t.T_world_vehicle = Eigen::Isometry3d::Identity();
  t.T_world_vehicle.linear() = q.toRotationMatrix();
  t.T_world_vehicle.translation() =
      Eigen::Vector3d(m.ego_position_m[0], m.ego_position_m[1], m.ego_position_m[2]);
  t.ego_speed_mps = m.ego_speed_mps;
  t.ego_yaw_rate_radps = m.ego_yaw_rate_radps;
  t.ego_size_m = Eigen::Vector3d(m.ego_size_m[0], m.ego_size_m[1], m.ego_size_m[2]);
  t.ego_phase = m.ego_phase;
  t.gnss.stamp_ns = m.stamp_ns;
  t.gnss.latitude_deg = m.latitude_deg;
  t.gnss.longitude_deg = m.longitude_deg;
  t.gnss.altitude_m = m.altitude_m;
  t.gnss.valid = true;
  for (const auto& mo : m.objects) {
    GtBox o;
    o.id = mo.id;
    o.class_name = mo.class_name;
    o.center_m = Eigen::Vector3d(mo.center_m[0], mo.center_m[1], mo.center_m[2]);
    o.size_m = Eigen::Vector3d(mo.size_m[0], mo.size_m[1], mo.size_m[2]);
    o.velocity_mps = Eigen::Vector3d(mo.velocity_mps[0], mo.velocity_mps[1], mo.velocity_mps[2]);
    o.yaw_rad = mo.yaw_rad;
    t.objects.push_back(o);
  }
  for (const auto& mb : m.bays) {
    GtBay b;
    b.id = mb.id;
    b.center_m = Eigen::Vector3d(mb.center_m[0], mb.center_m[1], mb.center_m[2]);
    b.width_m = mb.width_m;
    b.depth_m = mb.depth_m;
    b.yaw_rad = mb.yaw_rad;
    b.feasible = mb.feasible;
    b.left_car_id = mb.left_car_id;
    b.right_car_id = mb.right_car_id;
    t.bays.push_back(b);
  }
  return t;
}

std::vector<std::uint8_t> Encode(const GtDepth& d) {
  const std::size_t n = static_cast<std::size_t>(d.width) * d.height;
  ROMO_THROW_UNLESS(d.left_depth_m.size() == n && d.right_depth_m.size() == n &&
                    d.left_object_id.size() == n && d.right_object_id.size() == n);
  romo_lcm::gt_depth_t m;
  m.stamp_ns = d.stamp_ns;
  m.frame_sequence = static_cast<std::int64_t>(d.sequence);
  m.rig_id = d.rig_id;
  m.width = d.width;
  m.height = d.height;
  m.size = static_cast<std::int32_t>(n);
  m.left_depth_m = d.left_depth_m;
  m.right_depth_m = d.right_depth_m;
  m.left_object_id = d.left_object_id;
  m.right_object_id = d.right_object_id;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  ROMO_DEMAND(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())) ==
              static_cast<int>(bytes.size()));
  return bytes;
}

GtDepth DecodeGtDepth(const void* data, std::size_t size, const std::string& origin) {
  CheckCounts(data, size, romo_lcm::gt_depth_t::getHash(), WalkGtDepth, "gt_depth_t", origin);
  romo_lcm::gt_depth_t m;
  if (!DecodeInto(data, size, &m)) {
    Fail(origin + ": not a valid romo_lcm.gt_depth_t message (" + std::to_string(size) +
         " bytes)");
  }
  if (m.width < 0 || m.height < 0 ||
      static_cast<std::int64_t>(m.width) * m.height != m.size) {
    Fail(origin + ": gt_depth_t size " + std::to_string(m.size) + " does not match " +
         std::to_string(m.width) + "x" + std::to_string(m.height));
  }
  GtDepth d;
  d.stamp_ns = m.stamp_ns;
  d.sequence = static_cast<std::uint64_t>(m.frame_sequence);
  d.rig_id = m.rig_id;
  d.width = m.width;
  d.height = m.height;
  d.left_depth_m = std::move(m.left_depth_m);
  d.right_depth_m = std::move(m.right_depth_m);
  d.left_object_id = std::move(m.left_object_id);
  d.right_object_id = std::move(m.right_object_id);
  return d;
}

}  // namespace romo::sim
