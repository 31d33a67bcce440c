#include "romo/sim_manip/sim_manip.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <random>

#include <Eigen/Geometry>

#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/indoor_manip/action_label.hpp"
#include "trajectories.hpp"

namespace romo::sim_manip {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Hand-sized ellipsoid: semi-axes along the hand's x (fingers), y, z (plane normal), metres.
const Eigen::Vector3d kHandSemiAxes(0.045, 0.035, 0.025);

// Deterministic lattice noise in [0, 1): textures that optical flow can follow.
double Hash(std::int64_t x, std::int64_t y, std::uint64_t salt) {
  std::uint64_t h = static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(y) * 0xC2B2AE3D27D4EB4Full ^ salt;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  return (h >> 11) * (1.0 / 9007199254740992.0);
}
double ValueNoise(double x, double y, double cell, std::uint64_t salt) {
  const double fx = x / cell, fy = y / cell;
  const auto ix = static_cast<std::int64_t>(std::floor(fx));
  const auto iy = static_cast<std::int64_t>(std::floor(fy));
  const double tx = fx - ix, ty = fy - iy;
  const double sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  const double a = Hash(ix, iy, salt), b = Hash(ix + 1, iy, salt);
  const double c = Hash(ix, iy + 1, salt), d = Hash(ix + 1, iy + 1, salt);
  return (a + (b - a) * sx) * (1 - sy) + (c + (d - c) * sx) * sy;
}

// The sliding book of slide=1 (plane frame): 20 x 14 x 4 cm, front left of the hand's start, at
// rest for the first third, pushed 10 cm right, 4 cm back and turned 15 deg about the plane
// normal (eased) in the middle third, at rest again for the last.
const Eigen::Vector3d kBookHalf(0.10, 0.07, 0.02);  // half extents; it stands on z = 0
const Eigen::Vector2d kBookStart(-0.25, -0.18);
const Eigen::Vector2d kBookShift(0.10, 0.04);
constexpr double kBookTurnRad = 15.0 * M_PI / 180.0;

// Centre (plane frame, on the plane) and yaw of the book at frame @p k of @p frames.
std::pair<Eigen::Vector3d, double> BookPose(int k, int frames) {
  const double s = std::clamp((3.0 * k / std::max(1, frames - 1)) - 1.0, 0.0, 1.0);
  const double e = s * s * (3 - 2 * s);
  const Eigen::Vector2d c = kBookStart + e * kBookShift;
  return {Eigen::Vector3d(c.x(), c.y(), kBookHalf.z()), e * kBookTurnRad};
}

// Axial noise of a Kinect v1 (Nguyen, Izadi, Lovell 2012): 1.2 mm + 1.9 mm * (z - 0.4 m)^2.
double KinectSigmaM(double z_m) { return 0.0012 + 0.0019 * (z_m - 0.4) * (z_m - 0.4); }

struct Box {
  Eigen::Vector3d lo, hi;  // plane frame
  Eigen::Vector3d rgb;
  std::string name;
};

// Where the ray origin + t d (t > 0) enters the axis-aligned box [lo, hi], and the axis of the
// face it enters through (slab method); nullopt when it misses or starts inside.
struct BoxEntry {
  double t;
  int axis;
};
std::optional<BoxEntry> RayEntersBox(const Eigen::Vector3d& origin, const Eigen::Vector3d& d,
                                     const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t0 = 0.0, t1 = kInf;
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (origin[a] < lo[a] || origin[a] > hi[a]) return std::nullopt;
      continue;
    }
    double ta = (lo[a] - origin[a]) / d[a], tb = (hi[a] - origin[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) {
      t0 = ta;
      axis = a;
    }
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::nullopt;
  }
  if (axis < 0) return std::nullopt;
  return BoxEntry{t0, axis};
}

}  // namespace

SimManipOptions SimManipOptions::FromUri(const drivers::Uri& uri) {
  SimManipOptions o;
  o.action = uri.path;
  for (const auto& [key, value] : uri.query) {
    if (key != "seed" && key != "frames" && key != "width" && key != "height" && key != "fps" &&
        key != "noise" && key != "transports" && key != "prop" && key != "slide") {
      Fail("sim-manip URI '" + uri.ToString() + "': unknown query key '" + key +
           "' (known: seed, frames, width, height, fps, noise, transports, prop, slide)");
    }
  }
  if (auto v = uri.GetInt("seed")) {
    if (*v < 0) Fail("sim-manip URI: seed must be >= 0, got " + std::to_string(*v));
    o.seed = static_cast<std::uint64_t>(*v);
  }
  if (auto v = uri.GetInt32("frames")) o.frames = *v;
  if (auto v = uri.GetInt32("width")) o.width_px = *v;
  if (auto v = uri.GetInt32("height")) o.height_px = *v;
  if (auto v = uri.GetDouble("fps")) o.fps = *v;
  if (auto v = uri.GetInt("noise")) o.noise = *v != 0;
  if (auto v = uri.GetInt32("transports")) o.transports = *v;
  if (auto v = uri.GetInt("prop")) o.prop = *v != 0;
  if (auto v = uri.GetInt("slide")) o.slide = *v != 0;
  o.Validate();
  return o;
}

void SimManipOptions::Validate() const {
  const auto& names = indoor_manip::ActionNames();
  if (std::find(names.begin(), names.end(), action) == names.end()) {
    indoor_manip::ActionPartner(action);  // throws, listing the known actions
  }
  if (frames < 2 || frames > 100000) Fail("sim-manip: frames must be in [2, 100000], got " + std::to_string(frames));
  if (width_px < 64 || height_px < 48 || width_px > 4096 || height_px > 4096) {
    Fail("sim-manip: image size must be within 64x48 .. 4096x4096, got " + std::to_string(width_px) +
         "x" + std::to_string(height_px));
  }
  if (!(fps >= 1.0 && fps <= 240.0)) Fail("sim-manip: fps must be in [1, 240], got " + std::to_string(fps));
  if (prop && internal::IsBoardAction(action)) {
    Fail("sim-manip: prop=1 needs a table action, got '" + action + "' (a whiteboard action)");
  }
  if (slide && internal::IsBoardAction(action)) {
    Fail("sim-manip: slide=1 needs a table action, got '" + action + "' (a whiteboard action)");
  }
  if (transports < 0 || transports > 20) {
    Fail("sim-manip: transports must be in [0, 20], got " + std::to_string(transports));
  }
  // Each work segment must last a second at least, besides the 1 s transports.
  if (transports > 0 && frames < static_cast<int>(std::ceil((2 * transports + 1) * fps))) {
    Fail("sim-manip: " + std::to_string(transports) + " transports need at least " +
         std::to_string(static_cast<int>(std::ceil((2 * transports + 1) * fps))) + " frames, got " +
         std::to_string(frames));
  }
}

namespace {

// The action's own path re-timed around transports: work at spot A, carry the hand (lifted,
// pose frozen) to spot B, work there, back to A, ... Spots are plane offsets (u, v).
std::vector<internal::HandPose> WithTransports(const std::vector<internal::HandPose>& action, int transports,
                                               double fps, std::vector<int>* spot_of_frame,
                                               std::vector<std::pair<int, int>>* transport_frames) {
  const int n = static_cast<int>(action.size());
  const Eigen::Vector2d spots[2] = {{0.0, 0.0}, {0.30, -0.05}};  // 30 cm apart, both in view
  constexpr double kLiftM = 0.12;  // a carried hand clears the table
  const int tf = static_cast<int>(std::lround(fps));  // 1 s per transport
  const int work = (n - transports * tf) / (transports + 1);
  std::vector<internal::HandPose> out(n);
  spot_of_frame->assign(n, -1);
  int action_k = 0;  // the action's own clock only runs while working
  int k = 0;
  for (int seg = 0; seg <= transports; ++seg) {
    const int spot = seg % 2;
    const int len = seg == transports ? n - k : work;
    for (int i = 0; i < len; ++i, ++k) {
      out[k] = action[std::min(action_k++, n - 1)];
      out[k].u_m += spots[spot].x();
      out[k].v_m += spots[spot].y();
      (*spot_of_frame)[k] = spot;
    }
    if (seg == transports) break;
    const internal::HandPose held = action[std::min(action_k, n - 1)];
    const Eigen::Vector2d from = spots[spot], to = spots[1 - spot];
    transport_frames->push_back({k, k + tf - 1});
    for (int i = 0; i < tf; ++i, ++k) {
      const double s = (i + 1.0) / (tf + 1.0);
      const double e = s * s * (3 - 2 * s);  // eased: hands accelerate and brake
      out[k] = held;
      out[k].u_m += from.x() + e * (to.x() - from.x());
      out[k].v_m += from.y() + e * (to.y() - from.y());
      out[k].h_m += kLiftM * std::sin(M_PI * s);
    }
  }
  return out;
}

}  // namespace

class SimManipScene::Impl {
 public:
  explicit Impl(const SimManipOptions& o) : opt_(o) {
    o.Validate();
    const std::uint64_t action_salt = std::hash<std::string>{}(o.action);
    salt_ = o.seed * 0x100000001B3ull ^ action_salt;
    std::mt19937_64 rng(salt_);
    path_ = internal::GenerateHandPath(o.action, rng, o.frames, o.fps);
    std::vector<int> spot_of_frame(path_.size(), 0);
    if (o.transports > 0) {
      path_ = WithTransports(path_, o.transports, o.fps, &spot_of_frame, &truth_.transport_frames);
    }
    board_ = internal::IsBoardAction(o.action);

    // Kinect v1 intrinsics scaled to the image size.
    const double s = o.width_px / 640.0;
    K_ << 525.0 * s, 0, (o.width_px - 1) / 2.0, 0, 525.0 * s, (o.height_px - 1) / 2.0, 0, 0, 1;

    // Camera looking at the hand's start: from the front for a board, from above-front
    // (50 deg elevation) for a table. Plane frame P: x along the plane, z its normal.
    const Eigen::Vector3d target(0.0, 0.0, path_.front().h_m);
    Eigen::Vector3d eye;
    Eigen::Vector3d up_hint;
    if (board_) {
      eye = target + Eigen::Vector3d(0.05, -0.1, 1.3);
      up_hint = Eigen::Vector3d::UnitY();
    } else {
      const double el = 50.0 * M_PI / 180.0, dist = 1.0;
      eye = target + dist * Eigen::Vector3d(0.0, -std::cos(el), std::sin(el));
      up_hint = Eigen::Vector3d::UnitZ();
    }
    const Eigen::Vector3d zc = (target - eye).normalized();  // optical axis
    const Eigen::Vector3d xc = zc.cross(up_hint).normalized();  // image right
    const Eigen::Vector3d yc = zc.cross(xc);  // image down
    R_P_C_.col(0) = xc;
    R_P_C_.col(1) = yc;
    R_P_C_.col(2) = zc;
    eye_ = eye;

    // Objects on the plane, away from the hand's working area.
    if (board_) {
      boxes_.push_back({{-0.35, -0.85, 0.0}, {0.6, -0.8, 0.06}, {0.55, 0.55, 0.6}, "marker_tray"});
      boxes_.push_back({{-0.35, 0.15, 0.0}, {-0.27, 0.23, 0.02}, {0.8, 0.2, 0.2}, "magnet"});
    } else {
      boxes_.push_back({{-0.42, 0.15, 0.0}, {-0.34, 0.23, 0.12}, {0.2, 0.35, 0.8}, "cup"});
      boxes_.push_back({{0.3, 0.25, 0.0}, {0.45, 0.35, 0.04}, {0.3, 0.7, 0.3}, "box"});
      // Behind the mouth position of eating/drinking (v 0.20-0.26 m, h 0.20-0.36 m) as seen from
      // the camera (50 deg elevation): the raised hand covers part of its front and top (10-30 %
      // of its pixels in 15-30 of drinking's 210 frames).
      if (o.prop) boxes_.push_back({{0.01, 0.32, 0.0}, {0.11, 0.40, 0.12}, {0.75, 0.7, 0.2}, "prop"});
    }

    // Truth in the camera frame.
    const Eigen::Matrix3d R_C_P = R_P_C_.transpose();
    const Eigen::Vector3d n_C = R_C_P * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d origin_C = R_C_P * (Eigen::Vector3d::Zero() - eye_);
    truth_.plane_camera << n_C, -n_C.dot(origin_C);
    if (truth_.plane_camera[3] < 0) truth_.plane_camera = -truth_.plane_camera;
    truth_.K = K_;
    for (const Box& b : boxes_) {
      SimObjectTruth t;
      t.name = b.name;
      t.size_m = b.hi - b.lo;
      t.centre_camera_m = R_C_P * (0.5 * (b.lo + b.hi) - eye_);
      t.axes_camera = R_C_P;
      truth_.objects.push_back(t);
    }
    if (o.slide) {
      // The book's local frame (centre, axes) into the camera at frame k: A_k; its motion since
      // frame 0 is A_k A_0^-1.
      auto local_to_camera = [&](int k) {
        const auto [c, yaw] = BookPose(k, o.frames);
        Eigen::Isometry3d A = Eigen::Isometry3d::Identity();
        A.linear() = R_C_P * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        A.translation() = R_C_P * (c - eye_);
        return A;
      };
      SimObjectTruth t;
      t.name = "book";
      t.size_m = 2 * kBookHalf;
      const Eigen::Isometry3d A0 = local_to_camera(0);
      t.centre_camera_m = A0.translation();
      t.axes_camera = A0.linear();
      for (int k = 0; k < o.frames; ++k) t.T_k_0_camera.push_back(local_to_camera(k) * A0.inverse());
      truth_.objects.push_back(t);
    }
    for (const auto& p : path_) {
      truth_.hand_centre_camera_m.push_back(R_C_P * (Eigen::Vector3d(p.u_m, p.v_m, p.h_m) - eye_));
      truth_.hand_yaw_rad.push_back(p.yaw_rad);
    }
    for (int spot = 0; spot < (o.transports > 0 ? 2 : 1); ++spot) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      int count = 0;
      for (std::size_t k = 0; k < path_.size(); ++k) {
        if (spot_of_frame[k] != spot) continue;
        mean += Eigen::Vector3d(path_[k].u_m, path_[k].v_m, 0.0);
        ++count;
      }
      truth_.work_area_centres_camera_m.push_back(R_C_P * (mean / count - eye_));
    }
    const Eigen::Vector3d c0 = truth_.hand_centre_camera_m.front();
    truth_.seed_u_px = static_cast<int>(std::lround(K_(0, 0) * c0.x() / c0.z() + K_(0, 2)));
    truth_.seed_v_px = static_cast<int>(std::lround(K_(1, 1) * c0.y() / c0.z() + K_(1, 2)));
    // Three free plane pixels spread over the image's lower half / corners.
    const int w = o.width_px, h = o.height_px;
    truth_.plane_pixels = board_ ? std::vector<std::pair<int, int>>{{w / 10, h / 10}, {w - w / 10, h / 8}, {w / 8, h - h / 5}}
                                 : std::vector<std::pair<int, int>>{{w / 10, h - h / 10}, {w - w / 10, h - h / 12}, {w / 2, h / 12}};

    drivers::RigCalibration rig;
    rig.rig_id = 0;
    rig.name = "sim_manip";
    rig.width_px = w;
    rig.height_px = h;
    rig.left.K = K_;
    rig.right.K = K_;
    calibration_.rigs.push_back(rig);
    RenderBackground();
  }

  // Ray parameter of pixel (u, v): its direction with camera-frame z = 1, so t is the depth.
  Eigen::Vector3d Ray(int u, int v) const {
    return R_P_C_ * Eigen::Vector3d((u - K_(0, 2)) / K_(0, 0), (v - K_(1, 2)) / K_(1, 1), 1.0);
  }

  // The static part (plane and objects) is rendered once; frames only re-cast the hand.
  void RenderBackground() {
    const int w = opt_.width_px, h = opt_.height_px;
    bg_depth_.assign(static_cast<std::size_t>(w) * h, 0.0);
    bg_colour_.assign(bg_depth_.size(), Eigen::Vector3f::Zero());
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        const Eigen::Vector3d d = Ray(u, v);
        double best = kInf;
        Eigen::Vector3d rgb(0, 0, 0);
        if (d.z() < -1e-9) {  // plane z = 0
          const double t = -eye_.z() / d.z();
          const Eigen::Vector3d p = eye_ + t * d;
          best = t;
          double tex = ValueNoise(p.x(), p.y(), 0.02, 11) * 0.6 + ValueNoise(p.x(), p.y(), 0.005, 12) * 0.4;
          if (opt_.slide) {
            // A patterned tablecloth (1 cm blocks): the still scene then holds most of the
            // features, as a room does, and the ego-motion is the camera's, not the book's.
            tex = 0.5 * tex + 0.5 * Hash(static_cast<std::int64_t>(std::floor(p.x() / 0.01)),
                                         static_cast<std::int64_t>(std::floor(p.y() / 0.01)), 14);
          }
          rgb = board_ ? Eigen::Vector3d(0.86, 0.87, 0.88) * (0.9 + 0.1 * tex)
                       : Eigen::Vector3d(0.62, 0.45, 0.3) * (opt_.slide ? 0.35 + 0.65 * tex : 0.7 + 0.3 * tex);
        }
        for (const Box& b : boxes_) {
          const auto entry = RayEntersBox(eye_, d, b.lo, b.hi);
          if (entry && entry->t < best) {
            best = entry->t;
            const double shade = entry->axis == 2 ? 1.0 : 0.75;
            const Eigen::Vector3d p = eye_ + entry->t * d;
            rgb = b.rgb * shade * (0.85 + 0.15 * ValueNoise(p.x() + p.z(), p.y() - p.z(), 0.01, 13));
          }
        }
        if (best < 6.0) {
          const std::size_t i = static_cast<std::size_t>(v) * w + u;
          bg_depth_[i] = best;
          bg_colour_[i] = rgb.cast<float>();
        }
      }
    }
    // A fixed table of standard normal samples: per-frame noise is a seeded walk through it.
    std::mt19937_64 rng(salt_ ^ 0x6A09E667F3BCC909ull);
    std::normal_distribution<float> gauss(0.f, 1.f);
    noise_.resize(1 << 18);
    for (auto& n : noise_) n = gauss(rng);
  }

  // The sliding book at frame @p k, ray-cast over the static background (its texture is fixed to
  // the book, so features follow it).
  void CastBook(int k, std::vector<double>* depth, std::vector<Eigen::Vector3f>* colour) const {
    const int w = opt_.width_px, h = opt_.height_px;
    const auto [c, yaw] = BookPose(k, opt_.frames);
    const Eigen::Matrix3d R_local_P = Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d o = R_local_P * (eye_ - c);
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        const Eigen::Vector3d d = R_local_P * Ray(u, v);
        const auto entry = RayEntersBox(o, d, -kBookHalf, kBookHalf);
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        if (!entry || ((*depth)[i] > 0 && entry->t >= (*depth)[i])) continue;
        const double t0 = entry->t;
        const int axis = entry->axis;
        const Eigen::Vector3d p = o + t0 * d;  // book frame
        // A printed cover: random 8 mm blocks (corners for feature detectors) over fine noise.
        const double qx = p.x() + p.z(), qy = p.y() - p.z();
        const double block = Hash(static_cast<std::int64_t>(std::floor(qx / 0.008)),
                                  static_cast<std::int64_t>(std::floor(qy / 0.008)), 31);
        const double tex = 0.7 * block + 0.3 * ValueNoise(qx, qy, 0.004, 32);
        const double shade = axis == 2 ? 1.0 : 0.75;
        (*depth)[i] = t0;
        (*colour)[i] = (Eigen::Vector3d(0.85, 0.35, 0.3) * shade * (0.15 + 0.85 * tex)).cast<float>();
      }
    }
  }

  drivers::RgbdFrame Render(int k) const {
    ROMO_THROW_UNLESS(k >= 0 && k < opt_.frames);
    const int w = opt_.width_px, h = opt_.height_px;
    const internal::HandPose& hp = path_[k];
    const Eigen::Vector3d hand_c(hp.u_m, hp.v_m, hp.h_m);
    const Eigen::Matrix3d R_P_H =
        (Eigen::AngleAxisd(hp.yaw_rad, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(hp.pitch_rad, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(hp.roll_rad, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
    const Eigen::Vector3d light = Eigen::Vector3d(0.3, -0.4, 1.0).normalized();
    std::vector<double> depth = bg_depth_;
    std::vector<Eigen::Vector3f> colour = bg_colour_;
    if (opt_.slide) CastBook(k, &depth, &colour);
    // Only pixels inside the projection of the hand's bounding sphere can see the hand.
    const Eigen::Vector3d c_C = R_P_C_.transpose() * (hand_c - eye_);
    const double radius = kHandSemiAxes.maxCoeff();
    int u0 = 0, u1 = w - 1, v0 = 0, v1 = h - 1;
    if (c_C.z() > radius) {
      const double uc = K_(0, 0) * c_C.x() / c_C.z() + K_(0, 2);
      const double vc = K_(1, 1) * c_C.y() / c_C.z() + K_(1, 2);
      const double rp = K_(0, 0) * radius / (c_C.z() - radius) + 2.0;
      u0 = std::max(0, static_cast<int>(uc - rp));
      u1 = std::min(w - 1, static_cast<int>(uc + rp));
      v0 = std::max(0, static_cast<int>(vc - rp));
      v1 = std::min(h - 1, static_cast<int>(vc + rp));
    }
    const Eigen::Vector3d o = (R_P_H.transpose() * (eye_ - hand_c)).cwiseQuotient(kHandSemiAxes);
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        // Hand ellipsoid: unit sphere in scaled hand coordinates.
        const Eigen::Vector3d dd = (R_P_H.transpose() * Ray(u, v)).cwiseQuotient(kHandSemiAxes);
        const double A = dd.squaredNorm(), B = 2 * o.dot(dd), C = o.squaredNorm() - 1.0;
        const double disc = B * B - 4 * A * C;
        if (disc <= 0) continue;
        const double t = (-B - std::sqrt(disc)) / (2 * A);
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        if (!(t > 0) || (depth[i] > 0 && t >= depth[i])) continue;
        const Eigen::Vector3d ls = o + t * dd;  // unit sphere point
        const Eigen::Vector3d lp = ls.cwiseProduct(kHandSemiAxes);
        const Eigen::Vector3d n_P = R_P_H * ls.cwiseQuotient(kHandSemiAxes).normalized();
        const double lambert = 0.55 + 0.45 * std::max(0.0, n_P.dot(light));
        // Texture fixed to the hand (skin folds, nails, the tool): flow follows rotations.
        const double tex = 0.55 * ValueNoise(lp.x() + lp.z(), lp.y() - lp.z(), 0.012, 21) +
                           0.45 * ValueNoise(lp.x() - lp.z(), lp.y() + 0.5 * lp.z(), 0.006, 22);
        depth[i] = t;
        colour[i] = (Eigen::Vector3d(0.85, 0.62, 0.5) * lambert * (0.55 + 0.45 * tex)).cast<float>();
      }
    }

    drivers::RgbdFrame frame;
    frame.rgb = drivers::Image::Allocate(drivers::PixelFormat::kRgb8, w, h);
    frame.depth = drivers::Image::Allocate(drivers::PixelFormat::kMono16, w, h);
    frame.depth_scale_m = 0.001;
    frame.stamp_ns = static_cast<std::int64_t>(std::llround(k * 1e9 / opt_.fps));
    frame.sequence = static_cast<std::uint64_t>(k);
    std::mt19937_64 rng(salt_ ^ (0xD1B54A32D192ED03ull * (k + 1)));
    const std::size_t table = noise_.size();
    std::size_t at = rng() % table;
    const std::size_t step = 1 + 2 * (rng() % 1000);  // odd: walks the whole table
    auto next_noise = [&] {
      at = (at + step) % table;
      return noise_[at];
    };
    // Holes: ~1% random dropouts (a cheap hash per pixel and frame).
    const std::uint64_t hole_salt = rng();
    for (int v = 0; v < h; ++v) {
      auto* drow = reinterpret_cast<std::uint16_t*>(frame.depth.row(v));
      std::uint8_t* crow = frame.rgb.row(v);
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        double z = depth[i];
        float cn = 0.f;
        if (opt_.noise) {
          cn = 2.0f * next_noise();
          if (z > 0) {
            // The IR shadow right of a near-to-far depth edge, and random dropouts.
            const bool shadow = u >= 1 && depth[i - 1] > 0 && depth[i - 1] < z - 0.05;
            const bool shadow2 = u >= 2 && depth[i - 2] > 0 && depth[i - 2] < z - 0.05;
            const double r = Hash(u, v, hole_salt);
            if (r < 0.01 || (shadow && r < 0.8) || (shadow2 && r < 0.4)) z = 0;
            else z += KinectSigmaM(z) * next_noise();
          }
        }
        drow[u] = z > 0 ? static_cast<std::uint16_t>(std::clamp(std::lround(z * 1000.0), 0L, 65535L)) : 0;
        for (int c = 0; c < 3; ++c) {
          const double val = colour[i][c] * 255.0 + cn;
          crow[3 * u + c] = static_cast<std::uint8_t>(std::clamp(std::lround(val), 0L, 255L));
        }
      }
    }
    return frame;
  }

  SimManipOptions opt_;
  std::uint64_t salt_ = 0;
  bool board_ = false;
  std::vector<internal::HandPose> path_;
  Eigen::Matrix3d K_;
  Eigen::Matrix3d R_P_C_;
  Eigen::Vector3d eye_;
  std::vector<Box> boxes_;
  SimManipTruth truth_;
  drivers::Calibration calibration_;
  std::vector<double> bg_depth_;
  std::vector<Eigen::Vector3f> bg_colour_;
  std::vector<float> noise_;
};

SimManipScene::SimManipScene(const SimManipOptions& options) : impl_(std::make_unique<Impl>(options)) {}
SimManipScene::~SimManipScene() = default;
int SimManipScene::frame_count() const { return impl_->opt_.frames; }
drivers::RgbdFrame SimManipScene::Render(int k) const { return impl_->Render(k); }
const SimManipTruth& SimManipScene::truth() const { return impl_->truth_; }
const drivers::Calibration& SimManipScene::calibration() const { return impl_->calibration_; }

namespace {

class SimManipSource : public drivers::FrameSource {
 public:
  explicit SimManipSource(const SimManipOptions& o) : scene_(o) {}
  std::optional<drivers::FrameSet> Next() override {
    if (next_ >= scene_.frame_count()) return std::nullopt;
    drivers::FrameSet set;
    set.rgbd = scene_.Render(next_);
    set.stamp_ns = set.rgbd->stamp_ns;
    set.sequence = set.rgbd->sequence;
    ++next_;
    return set;
  }
  const drivers::Calibration* calibration() const override { return &scene_.calibration(); }

 private:
  SimManipScene scene_;
  int next_ = 0;
};

}  // namespace

void RegisterSimManipScheme() {
  static std::once_flag once;
  std::call_once(once, [] {
    drivers::RegisterSourceScheme("sim-manip", [](const drivers::Uri& uri) {
      return std::make_unique<SimManipSource>(SimManipOptions::FromUri(uri));
    });
  });
}

}  // namespace romo::sim_manip
