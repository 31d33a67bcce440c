#include "romo/sim/visibility.hpp"

#include <algorithm>
#include <cmath>

namespace romo::sim {
namespace {

constexpr int kSamplesPerSide = 6;  // 6 x 6 per face: 180 samples an object

struct Camera {
  Eigen::Vector3d centre_world;
  Eigen::Isometry3d T_left_world;  // world -> left camera (x right, y down, z forward)
  const drivers::RigCalibration* rig;
};

bool InImage(const Eigen::Matrix3d& K, const Eigen::Vector3d& p_cam, int width, int height) {
  if (p_cam.z() <= 0.05) return false;
  const Eigen::Vector3d uv = K * (p_cam / p_cam.z());
  return uv.x() >= 0.0 && uv.x() < width && uv.y() >= 0.0 && uv.y() < height;
}

// True when the segment from @p a to @p b passes through @p box (slab test in the box's frame),
// ends excluded so that a sample on a face touching another box is not hidden by it.
bool Blocks(const GtBox& box, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = std::cos(box.yaw_rad), s = std::sin(box.yaw_rad);
  auto local = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d d = p - box.center_m;
    return Eigen::Vector3d(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
  };
  const Eigen::Vector3d o = local(a), dir = local(b) - o;
  const Eigen::Vector3d half = box.size_m / 2;
  double t0 = 1e-6, t1 = 1.0 - 1e-6;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(dir[k]) < 1e-12) {
      if (std::abs(o[k]) > half[k]) return false;
      continue;
    }
    double ta = (-half[k] - o[k]) / dir[k], tb = (half[k] - o[k]) / dir[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

double VisibleFraction(const GtBox& target, const std::vector<GtBox>& scene,
                       const drivers::Calibration& calibration, const Eigen::Isometry3d& T_world_vehicle) {
  std::vector<Camera> cameras;
  for (const auto& rig : calibration.rigs) {
    const Eigen::Isometry3d T_world_left = T_world_vehicle * rig.T_vehicle_rig;
    cameras.push_back({T_world_left.translation(), T_world_left.inverse(), &rig});
  }
  const double c = std::cos(target.yaw_rad), s = std::sin(target.yaw_rad);
  const Eigen::Vector3d ax(c, s, 0), ay(-s, c, 0), az(0, 0, 1);
  const Eigen::Vector3d half = target.size_m / 2;
  // Faces: outward normal, and the two in-face directions with their half extents.
  struct Face {
    Eigen::Vector3d normal, u, v;
    double offset, hu, hv;
  };
  const Face faces[5] = {{ax, ay, az, half.x(), half.y(), half.z()},  {-ax, ay, az, half.x(), half.y(), half.z()},
                         {ay, ax, az, half.y(), half.x(), half.z()},  {-ay, ax, az, half.y(), half.x(), half.z()},
                         {az, ax, ay, half.z(), half.x(), half.y()}};
  int facing = 0, seen = 0;
  for (const Face& f : faces) {
    for (int i = 0; i < kSamplesPerSide; ++i) {
      for (int j = 0; j < kSamplesPerSide; ++j) {
        const double a = ((i + 0.5) / kSamplesPerSide * 2.0 - 1.0) * f.hu;
        const double b = ((j + 0.5) / kSamplesPerSide * 2.0 - 1.0) * f.hv;
        const Eigen::Vector3d p = target.center_m + f.normal * f.offset + f.u * a + f.v * b;
        bool turned = false, visible = false;
        for (const Camera& cam : cameras) {
          if (f.normal.dot(cam.centre_world - p) <= 0.0) continue;
          turned = true;
          const drivers::RigCalibration& rig = *cam.rig;
          const Eigen::Vector3d p_left = cam.T_left_world * p;
          if (!InImage(rig.left.K, p_left, rig.width_px, rig.height_px)) continue;
          if (!InImage(rig.right.K, rig.R * p_left + rig.T, rig.width_px, rig.height_px)) continue;
          bool blocked = false;
          for (const GtBox& other : scene) {
            if (other.id != target.id && Blocks(other, cam.centre_world, p)) {
              blocked = true;
              break;
            }
          }
          if (!blocked) {
            visible = true;
            break;
          }
        }
        facing += turned;
        seen += visible;
      }
    }
  }
  return facing > 0 ? static_cast<double>(seen) / facing : 0.0;
}

}  // namespace romo::sim
