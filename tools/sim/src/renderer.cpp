#include "romo/sim/renderer.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

#include "hash.hpp"
#include "romo/core/check.hpp"
#include "texture.hpp"

namespace romo::sim {
namespace {

constexpr int kTile = 16;  // pixels; objects are culled per tile
constexpr float kInf = std::numeric_limits<float>::infinity();

// Normalised, undistorted image coordinates of pixel position (u, v): inverts the OpenCV model
// (radial k1 k2 k3 / k4 k5 k6 rational, tangential p1 p2) by fixed-point iteration.
Eigen::Vector2d Undistort(double u, double v, const drivers::CameraIntrinsics& cam) {
  const Eigen::Matrix3d& K = cam.K;
  const double xd = (u - K(0, 2) - K(0, 1) * (v - K(1, 2)) / K(1, 1)) / K(0, 0);
  const double yd = (v - K(1, 2)) / K(1, 1);
  double k[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < cam.distortion.size() && i < 8; ++i) k[i] = cam.distortion[i];
  double x = xd, y = yd;
  for (int it = 0; it < 100; ++it) {
    const double r2 = x * x + y * y;
    const double radial = (1 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]))) /
                          (1 + r2 * (k[5] + r2 * (k[6] + r2 * k[7])));
    const double dx = 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x);
    const double dy = k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y;
    const double nx = (xd - dx) / radial, ny = (yd - dy) / radial;
    const double change = std::abs(nx - x) + std::abs(ny - y);
    x = nx;
    y = ny;
    if (change < 1e-14) break;
  }
  return {x, y};
}

// Ray directions (z = 1 in the camera frame) of every sample of one camera model.
struct RayTable {
  int width = 0, height = 0, spp = 1;
  const drivers::CameraIntrinsics* intrinsics = nullptr;
  std::vector<float> sx, sy;  // [(y * width + x) * spp + s]
  std::vector<float> cx, cy;  // pixel centres, [y * width + x]
  int tiles_x = 0, tiles_y = 0;
  std::vector<Eigen::Vector4f> tile_bounds;  // min x, max x, min y, max y over the tile's rays
};

bool SameModel(const RayTable& t, const drivers::CameraIntrinsics& cam, int w, int h) {
  return t.width == w && t.height == h && t.intrinsics->K == cam.K &&
         t.intrinsics->distortion == cam.distortion;
}

RayTable BuildTable(const drivers::CameraIntrinsics& cam, int w, int h, int n, int threads) {
  RayTable t;
  t.width = w;
  t.height = h;
  t.spp = n * n;
  t.intrinsics = &cam;
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  t.sx.resize(pixels * t.spp);
  t.sy.resize(pixels * t.spp);
  t.cx.resize(pixels);
  t.cy.resize(pixels);
  ParallelFor(h, threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          // Regular grid centred on the pixel (pixel centres at integer coordinates).
          const double u = x + (i + 0.5) / n - 0.5, v = y + (j + 0.5) / n - 0.5;
          const Eigen::Vector2d r = Undistort(u, v, cam);
          t.sx[p * t.spp + j * n + i] = static_cast<float>(r.x());
          t.sy[p * t.spp + j * n + i] = static_cast<float>(r.y());
        }
      }
      const Eigen::Vector2d c = Undistort(x, y, cam);
      t.cx[p] = static_cast<float>(c.x());
      t.cy[p] = static_cast<float>(c.y());
    }
  });
  t.tiles_x = (w + kTile - 1) / kTile;
  t.tiles_y = (h + kTile - 1) / kTile;
  t.tile_bounds.assign(static_cast<std::size_t>(t.tiles_x) * t.tiles_y,
                       Eigen::Vector4f(kInf, -kInf, kInf, -kInf));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      Eigen::Vector4f& b = t.tile_bounds[(y / kTile) * t.tiles_x + x / kTile];
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      auto grow = [&](float rx, float ry) {
        b[0] = std::min(b[0], rx);
        b[1] = std::max(b[1], rx);
        b[2] = std::min(b[2], ry);
        b[3] = std::max(b[3], ry);
      };
      for (int s = 0; s < t.spp; ++s) grow(t.sx[p * t.spp + s], t.sy[p * t.spp + s]);
      grow(t.cx[p], t.cy[p]);
    }
  }
  return t;
}

struct Camera {
  int rig_index = 0;
  bool right = false;
  int table = 0;
  Eigen::Isometry3d T_rig_camera = Eigen::Isometry3d::Identity();
  std::string camera_id;
};

// An object prepared for one camera: rays (camera frame, z = 1) map into its box frame by M
// with origin o; bounds in normalised image coordinates for culling.
struct CamObject {
  Eigen::Matrix3f M;
  Eigen::Vector3f o;
  float hl, hw, h;
  float cos_yaw, sin_yaw;
  int index;     // into the snapshot's objects
  bool always;   // a corner is near or behind the camera: test every ray
  Eigen::Vector4f bounds;
};

struct Hit {
  float t = kInf;   // = depth along the camera z axis (rays have z = 1)
  int object = -2;  // -2 nothing, -1 ground, >= 0 index into CamObjects
  internal::Face face = internal::Face::kTop;
};

struct Line {
  Eigen::Vector2f centre, dir;
  float half_length, half_width;
};

// Everything one camera's rays need at one frame.
struct CameraFrameSetup {
  Eigen::Matrix3f R_world_camera;
  Eigen::Vector3f origin_world;
  std::vector<CamObject> objects;
  const SceneSnapshot* snapshot;
  const std::vector<Line>* lines;
  Eigen::Vector4f lines_box;  // min x, max x, min y, max y of all paint
  float pixel_angle;          // 1 / fx: a pixel's size in normalised coordinates
};

// Size of a ray's pixel on a surface at depth t seen at incidence cosine cos_inc: the geometric
// mean of the footprint's two axes (the texture level of detail).
inline float Footprint(const CameraFrameSetup& c, float t, float ray_norm, float cos_inc) {
  return t * ray_norm * c.pixel_angle / std::sqrt(std::max(cos_inc, 0.05f));
}

const Eigen::Vector3f kSun = Eigen::Vector3f(0.35f, -0.45f, 0.82f).normalized();

inline Hit Trace(const CameraFrameSetup& c, const int* candidates, int n_candidates, float dx,
                 float dy) {
  Hit hit;
  const Eigen::Vector3f d(dx, dy, 1.0f);
  const float dwz = c.R_world_camera.row(2).dot(d);
  if (dwz < -1e-9f) {
    const float t = -c.origin_world.z() / dwz;
    if (t > 0.0f) {
      hit.t = t;
      hit.object = -1;
    }
  }
  for (int k = 0; k < n_candidates; ++k) {
    const CamObject& ob = c.objects[candidates[k]];
    const Eigen::Vector3f dl = ob.M * d;
    float tnear = -kInf, tfar = kInf;
    int axis = 0;
    bool negative = false;
    const float lo[3] = {-ob.hl, -ob.hw, 0.0f};
    const float hi[3] = {ob.hl, ob.hw, ob.h};
    bool miss = false;
    for (int i = 0; i < 3; ++i) {
      if (std::abs(dl[i]) < 1e-12f) {
        if (ob.o[i] < lo[i] || ob.o[i] > hi[i]) {
          miss = true;
          break;
        }
        continue;
      }
      const float inv = 1.0f / dl[i];
      float t1 = (lo[i] - ob.o[i]) * inv, t2 = (hi[i] - ob.o[i]) * inv;
      if (t1 > t2) std::swap(t1, t2);
      if (t1 > tnear) {
        tnear = t1;
        axis = i;
        negative = dl[i] > 0.0f;  // entering through the face on the negative side
      }
      tfar = std::min(tfar, t2);
      if (tnear > tfar) {
        miss = true;
        break;
      }
    }
    if (miss || tfar <= 0.0f || tnear <= 0.0f || tnear >= hit.t) continue;
    hit.t = tnear;
    hit.object = candidates[k];
    hit.face = axis == 0   ? (negative ? internal::Face::kMinusX : internal::Face::kPlusX)
               : axis == 1 ? (negative ? internal::Face::kMinusY : internal::Face::kPlusY)
                           : internal::Face::kTop;
  }
  return hit;
}

// Grey value (0-255, unclipped) of a ray's hit.
inline float Shade(const CameraFrameSetup& c, const Hit& hit, float dx, float dy) {
  const Eigen::Vector3f d(dx, dy, 1.0f);
  if (hit.object == -2) {
    const Eigen::Vector3f dw = c.R_world_camera * d;
    const float elevation = std::max(0.0f, dw.z() / dw.norm());
    return 255.0f * (0.74f + 0.16f * elevation);
  }
  if (hit.object == -1) {
    const Eigen::Vector3f dw = c.R_world_camera * d;
    const Eigen::Vector3f p = c.origin_world + hit.t * dw;
    const float norm = dw.norm();
    const float fp = Footprint(c, hit.t, norm, -dw.z() / norm);
    float albedo = -1.0f;
    const Eigen::Vector4f& lb = c.lines_box;
    if (p.x() >= lb[0] && p.x() <= lb[1] && p.y() >= lb[2] && p.y() <= lb[3]) {
      for (const Line& line : *c.lines) {
        const Eigen::Vector2f r = p.head<2>() - line.centre;
        const float along = r.dot(line.dir);
        const float across = r.x() * line.dir.y() - r.y() * line.dir.x();
        if (std::abs(along) <= line.half_length && std::abs(across) <= line.half_width) {
          albedo = internal::PaintAlbedo(p.x(), p.y(), c.snapshot->ground_seed, fp);
          break;
        }
      }
    }
    if (albedo < 0.0f) albedo = internal::AsphaltAlbedo(p.x(), p.y(), c.snapshot->ground_seed, fp);
    return 255.0f * albedo * (0.55f + 0.5f * kSun.z());
  }
  const CamObject& ob = c.objects[hit.object];
  const SceneObject& so = c.snapshot->objects[ob.index];
  const Eigen::Vector3f dl = ob.M * d;
  const Eigen::Vector3f pl = ob.o + hit.t * dl;
  Eigen::Vector3f nl(0, 0, 1);
  switch (hit.face) {
    case internal::Face::kMinusX: nl = Eigen::Vector3f(-1, 0, 0); break;
    case internal::Face::kPlusX: nl = Eigen::Vector3f(1, 0, 0); break;
    case internal::Face::kMinusY: nl = Eigen::Vector3f(0, -1, 0); break;
    case internal::Face::kPlusY: nl = Eigen::Vector3f(0, 1, 0); break;
    case internal::Face::kTop: break;
  }
  const float norm = dl.norm();
  internal::SurfacePoint sp{pl.x(), pl.y(), pl.z(), ob.hl, ob.hw, ob.h, hit.face,
                            Footprint(c, hit.t, norm, std::abs(nl.dot(dl)) / norm)};
  const Eigen::Vector3f nw(ob.cos_yaw * nl.x() - ob.sin_yaw * nl.y(),
                           ob.sin_yaw * nl.x() + ob.cos_yaw * nl.y(), nl.z());
  float albedo = so.albedo;
  switch (so.material) {
    case Material::kCar: albedo = internal::CarAlbedo(sp, so.albedo, so.texture_seed); break;
    case Material::kPedestrian:
      albedo = internal::PedestrianAlbedo(sp, so.albedo, so.texture_seed);
      break;
    case Material::kCurb: albedo = internal::CurbAlbedo(sp, so.albedo, so.texture_seed); break;
    case Material::kHedge: albedo = internal::HedgeAlbedo(sp, so.albedo, so.texture_seed); break;
    case Material::kAsphalt: break;
  }
  return 255.0f * albedo * (0.55f + 0.5f * std::max(0.0f, nw.dot(kSun)));
}

}  // namespace

void RenderParams::Validate() const {
  if (samples_per_axis < 1 || samples_per_axis > 4) {
    Fail("render parameter samples_per_axis = " + std::to_string(samples_per_axis) +
         " is outside 1-4");
  }
  if (!(noise_sigma >= 0.0 && noise_sigma <= 50.0)) {
    Fail("render parameter noise_sigma = " + std::to_string(noise_sigma) +
         " grey levels is outside 0-50");
  }
  if (threads < 1 || threads > 256) {
    Fail("render parameter threads = " + std::to_string(threads) + " is outside 1-256");
  }
}

void ParallelFor(int n, int threads, const std::function<void(int)>& fn) {
  const int workers = std::max(1, std::min(threads, n));
  if (workers == 1) {
    for (int i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<int> next{0};
  auto run = [&]() {
    for (int i = next++; i < n; i = next++) fn(i);
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(run);
  run();
  for (auto& t : pool) t.join();
}

drivers::Calibration ScaleCalibration(const drivers::Calibration& calibration, double scale) {
  if (!(scale > 0.0 && scale <= 4.0)) {
    Fail("simulator scale = " + std::to_string(scale) + " is outside (0, 4]");
  }
  drivers::Calibration out = calibration;
  for (auto& rig : out.rigs) {
    const int w = static_cast<int>(std::lround(rig.width_px * scale));
    const int h = static_cast<int>(std::lround(rig.height_px * scale));
    if (w < 8 || h < 8) {
      Fail("simulator scale = " + std::to_string(scale) + " makes rig '" + rig.name + "' images " +
           std::to_string(w) + "x" + std::to_string(h) + " (below 8x8)");
    }
    // Scale about pixel centres: new width / old width per axis, so the image border maps to
    // the same rays as before.
    const double sx = static_cast<double>(w) / rig.width_px;
    const double sy = static_cast<double>(h) / rig.height_px;
    for (auto* cam : {&rig.left, &rig.right}) {
      Eigen::Matrix3d& K = cam->K;
      K(0, 0) *= sx;
      K(0, 1) *= sx;
      K(0, 2) = (K(0, 2) + 0.5) * sx - 0.5;
      K(1, 1) *= sy;
      K(1, 2) = (K(1, 2) + 0.5) * sy - 0.5;
    }
    rig.width_px = w;
    rig.height_px = h;
  }
  return out;
}

class Renderer::Impl {
 public:
  Impl(const drivers::Calibration& calibration, const RenderParams& params)
      : calibration_(calibration), params_(params) {
    params_.Validate();
    if (calibration_.rigs.empty()) Fail("simulator: the calibration has no rigs");
    tables_.reserve(calibration_.rigs.size() * 2);
    for (std::size_t r = 0; r < calibration_.rigs.size(); ++r) {
      const auto& rig = calibration_.rigs[r];
      for (int side = 0; side < 2; ++side) {
        const drivers::CameraIntrinsics& intr = side == 0 ? rig.left : rig.right;
        Camera cam;
        cam.rig_index = static_cast<int>(r);
        cam.right = side == 1;
        cam.camera_id = "sim-" + rig.name + (side == 0 ? "-left" : "-right");
        if (side == 1) {
          // x_right = R x_left + T, so the right camera's pose in the rig (left) frame is the
          // inverse of [R | T].
          Eigen::Isometry3d T_right_left = Eigen::Isometry3d::Identity();
          T_right_left.linear() = rig.R;
          T_right_left.translation() = rig.T;
          cam.T_rig_camera = T_right_left.inverse();
        }
        cam.table = -1;
        for (std::size_t t = 0; t < tables_.size(); ++t) {
          if (SameModel(tables_[t], intr, rig.width_px, rig.height_px)) cam.table = static_cast<int>(t);
        }
        if (cam.table < 0) {
          tables_.push_back(BuildTable(intr, rig.width_px, rig.height_px, params_.samples_per_axis,
                                       params_.threads));
          cam.table = static_cast<int>(tables_.size()) - 1;
        }
        cameras_.push_back(cam);
      }
    }
  }

  CameraFrameSetup Setup(const Camera& cam, const SceneSnapshot& snap,
                         const std::vector<Line>& lines, const Eigen::Vector4f& lines_box) const {
    const auto& rig = calibration_.rigs[cam.rig_index];
    const Eigen::Isometry3d T_world_camera =
        snap.ego.T_world_vehicle * rig.T_vehicle_rig * cam.T_rig_camera;
    CameraFrameSetup c;
    c.R_world_camera = T_world_camera.linear().cast<float>();
    c.origin_world = T_world_camera.translation().cast<float>();
    c.snapshot = &snap;
    c.lines = &lines;
    c.lines_box = lines_box;
    c.pixel_angle = static_cast<float>(1.0 / tables_[cam.table].intrinsics->K(0, 0));
    const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
    for (std::size_t i = 0; i < snap.objects.size(); ++i) {
      const GtBox& box = snap.objects[i].box;
      const double cy = std::cos(box.yaw_rad), sy = std::sin(box.yaw_rad);
      Eigen::Isometry3d T_world_box = Eigen::Isometry3d::Identity();
      T_world_box.linear() = Eigen::AngleAxisd(box.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T_world_box.translation() =
          Eigen::Vector3d(box.center_m.x(), box.center_m.y(), box.center_m.z() - box.size_m.z() / 2);
      const Eigen::Isometry3d T_box_camera = T_world_box.inverse() * T_world_camera;
      CamObject ob;
      ob.M = T_box_camera.linear().cast<float>();
      ob.o = T_box_camera.translation().cast<float>();
      ob.hl = static_cast<float>(box.size_m.x() / 2);
      ob.hw = static_cast<float>(box.size_m.y() / 2);
      ob.h = static_cast<float>(box.size_m.z());
      ob.cos_yaw = static_cast<float>(cy);
      ob.sin_yaw = static_cast<float>(sy);
      ob.index = static_cast<int>(i);
      ob.always = false;
      ob.bounds = Eigen::Vector4f(kInf, -kInf, kInf, -kInf);
      int behind = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d pb((corner & 1) ? ob.hl : -ob.hl, (corner & 2) ? ob.hw : -ob.hw,
                                 (corner & 4) ? ob.h : 0.0);
        const Eigen::Vector3d pc = T_camera_world * (T_world_box * pb);
        if (pc.z() < 0.05) {
          ++behind;
          ob.always = true;
          continue;
        }
        const float x = static_cast<float>(pc.x() / pc.z()), y = static_cast<float>(pc.y() / pc.z());
        ob.bounds = Eigen::Vector4f(std::min(ob.bounds[0], x), std::max(ob.bounds[1], x),
                                    std::min(ob.bounds[2], y), std::max(ob.bounds[3], y));
      }
      if (behind == 8) continue;  // entirely behind the camera
      c.objects.push_back(ob);
    }
    return c;
  }

  void RenderBand(const Camera& cam, const CameraFrameSetup& c, int tile_row, std::uint64_t seed,
                  std::uint64_t frame, int camera_index, drivers::Image* image,
                  std::vector<float>* depth, std::vector<std::int16_t>* ids) const {
    const RayTable& t = tables_[cam.table];
    const float inv_spp = 1.0f / static_cast<float>(t.spp);
    const float sigma = static_cast<float>(params_.noise_sigma);
    std::vector<int> cand;
    cand.reserve(c.objects.size());
    const int y0 = tile_row * kTile, y1 = std::min(t.height, y0 + kTile);
    for (int tx = 0; tx < t.tiles_x; ++tx) {
      const Eigen::Vector4f& tb = t.tile_bounds[tile_row * t.tiles_x + tx];
      cand.clear();
      for (std::size_t k = 0; k < c.objects.size(); ++k) {
        const CamObject& ob = c.objects[k];
        if (ob.always || (ob.bounds[0] <= tb[1] && ob.bounds[1] >= tb[0] && ob.bounds[2] <= tb[3] &&
                          ob.bounds[3] >= tb[2])) {
          cand.push_back(static_cast<int>(k));
        }
      }
      const int n = static_cast<int>(cand.size());
      const int x0 = tx * kTile, x1 = std::min(t.width, x0 + kTile);
      for (int y = y0; y < y1; ++y) {
        std::uint8_t* row = image->row(y);
        for (int x = x0; x < x1; ++x) {
          const std::size_t p = static_cast<std::size_t>(y) * t.width + x;
          float sum = 0.0f;
          for (int s = 0; s < t.spp; ++s) {
            const float dx = t.sx[p * t.spp + s], dy = t.sy[p * t.spp + s];
            sum += std::min(255.0f, Shade(c, Trace(c, cand.data(), n, dx, dy), dx, dy));
          }
          const float noise = sigma * internal::ToGaussian(internal::Hash(seed, frame, camera_index, p));
          const float v = std::round(sum * inv_spp + noise);
          row[x] = static_cast<std::uint8_t>(std::min(255.0f, std::max(0.0f, v)));
          if (depth != nullptr) {
            const Hit h = Trace(c, cand.data(), n, t.cx[p], t.cy[p]);
            (*depth)[p] = h.object == -2 ? 0.0f : h.t;
            (*ids)[p] = static_cast<std::int16_t>(
                h.object == -2 ? kNoHitId
                : h.object == -1 ? kGroundId
                                 : c.snapshot->objects[c.objects[h.object].index].box.id);
          }
        }
      }
    }
  }

  std::vector<drivers::StereoFrame> Render(const SceneSnapshot& snap, std::uint64_t seed,
                                           std::uint64_t frame, std::vector<GtDepth>* depth) const {
    std::vector<Line> lines;
    Eigen::Vector4f lines_box(kInf, -kInf, kInf, -kInf);
    if (snap.lines != nullptr) {
      for (const PaintLine& pl : *snap.lines) {
        Line l;
        const Eigen::Vector2d d = pl.b_m - pl.a_m;
        l.centre = (0.5 * (pl.a_m + pl.b_m)).cast<float>();
        l.dir = d.normalized().cast<float>();
        l.half_length = static_cast<float>(d.norm() / 2);
        l.half_width = static_cast<float>(pl.width_m / 2);
        lines.push_back(l);
        const double r = pl.width_m;
        lines_box = Eigen::Vector4f(
            std::min<float>(lines_box[0], static_cast<float>(std::min(pl.a_m.x(), pl.b_m.x()) - r)),
            std::max<float>(lines_box[1], static_cast<float>(std::max(pl.a_m.x(), pl.b_m.x()) + r)),
            std::min<float>(lines_box[2], static_cast<float>(std::min(pl.a_m.y(), pl.b_m.y()) - r)),
            std::max<float>(lines_box[3], static_cast<float>(std::max(pl.a_m.y(), pl.b_m.y()) + r)));
      }
    }
    std::vector<CameraFrameSetup> setups;
    std::vector<drivers::Image> images;
    for (const Camera& cam : cameras_) {
      setups.push_back(Setup(cam, snap, lines, lines_box));
      const RayTable& t = tables_[cam.table];
      images.push_back(drivers::Image::Allocate(drivers::PixelFormat::kMono8, t.width, t.height));
    }
    if (depth != nullptr) {
      depth->clear();
      for (const auto& rig : calibration_.rigs) {
        GtDepth d;
        d.rig_id = rig.rig_id;
        d.width = rig.width_px;
        d.height = rig.height_px;
        const std::size_t n = static_cast<std::size_t>(d.width) * d.height;
        d.left_depth_m.assign(n, 0.0f);
        d.right_depth_m.assign(n, 0.0f);
        d.left_object_id.assign(n, kNoHitId);
        d.right_object_id.assign(n, kNoHitId);
        depth->push_back(std::move(d));
      }
    }
    // Work items: one band of tile rows of one camera each.
    std::vector<std::pair<int, int>> items;
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      for (int ty = 0; ty < tables_[cameras_[c].table].tiles_y; ++ty) {
        items.emplace_back(static_cast<int>(c), ty);
      }
    }
    ParallelFor(static_cast<int>(items.size()), params_.threads, [&](int i) {
      const int c = items[i].first;
      const Camera& cam = cameras_[c];
      std::vector<float>* dm = nullptr;
      std::vector<std::int16_t>* ids = nullptr;
      if (depth != nullptr) {
        GtDepth& d = (*depth)[cam.rig_index];
        dm = cam.right ? &d.right_depth_m : &d.left_depth_m;
        ids = cam.right ? &d.right_object_id : &d.left_object_id;
      }
      RenderBand(cam, setups[c], items[i].second, seed, frame, c, &images[c], dm, ids);
    });
    std::vector<drivers::StereoFrame> frames(calibration_.rigs.size());
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      const Camera& cam = cameras_[c];
      drivers::StereoFrame& f = frames[cam.rig_index];
      f.rig_id = calibration_.rigs[cam.rig_index].rig_id;
      drivers::CameraFrame& cf = cam.right ? f.right : f.left;
      cf.image = std::move(images[c]);
      cf.camera_id = cam.camera_id;
      cf.sequence = frame;
    }
    return frames;
  }

  std::uint64_t RaysPerFrame(bool with_depth) const {
    std::uint64_t rays = 0;
    for (const Camera& cam : cameras_) {
      const RayTable& t = tables_[cam.table];
      const std::uint64_t pixels = static_cast<std::uint64_t>(t.width) * t.height;
      rays += pixels * (t.spp + (with_depth ? 1 : 0));
    }
    return rays;
  }

  drivers::Calibration calibration_;
  RenderParams params_;
  std::vector<RayTable> tables_;
  std::vector<Camera> cameras_;
};

Renderer::Renderer(const drivers::Calibration& calibration, const RenderParams& params)
    : impl_(std::make_unique<Impl>(calibration, params)) {}
Renderer::~Renderer() = default;

std::vector<drivers::StereoFrame> Renderer::Render(const SceneSnapshot& snapshot, std::uint64_t seed,
                                                   std::uint64_t frame,
                                                   std::vector<GtDepth>* depth) const {
  return impl_->Render(snapshot, seed, frame, depth);
}

std::uint64_t Renderer::RaysPerFrame(bool with_depth) const { return impl_->RaysPerFrame(with_depth); }
const RenderParams& Renderer::params() const { return impl_->params_; }

}  // namespace romo::sim
