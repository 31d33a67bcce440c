#include "romo/indoor_manip/object_map.hpp"

#include <algorithm>
#include <map>
#include <string>

#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"
#include "romo/indoor_manip/manip_session.hpp"
#include "romo/mapping/confidence.hpp"

namespace romo::indoor_manip {

void ObjectMapParams::Validate() const {
  blobs.Validate();
  if (every_frames < 1) Fail("object_map.every_frames must be >= 1, got " + std::to_string(every_frames));
  if (!(completed_min_cv > 0 && completed_min_cv < 1)) {
    Fail("object_map.completed_min_cv must be in (0, 1), got " + std::to_string(completed_min_cv));
  }
  if (min_completed_points < 4) {
    Fail("object_map.min_completed_points must be >= 4, got " + std::to_string(min_completed_points));
  }
  if (!(pixel_sigma_px > 0)) Fail("object_map.pixel_sigma_px must be > 0, got " + std::to_string(pixel_sigma_px));
  if (hand_margin_px < 0) Fail("object_map.hand_margin_px must be >= 0, got " + std::to_string(hand_margin_px));
  if (min_keyframe_inliers < 3) {
    Fail("object_map.min_keyframe_inliers must be >= 3, got " + std::to_string(min_keyframe_inliers));
  }
}

class ObjectMap::Impl {
 public:
  Impl(const DepthIntrinsics& k, const InteractionPlane& plane, const ObjectMapParams& p, const OdometryParams& o)
      : k_(k), plane_(plane), params_(p), odometry_(o), map_(p.blobs) {}

  bool Add(const RgbdImage& full_image, const SceneGeometry& scene) {
    const int index = frames_seen_++;
    if (index % params_.every_frames != 0) return false;
    // The ego-motion only sees the static scene: the hand's features move with it and would pull
    // the estimate along (it carries most of the texture near the camera).
    const RgbdImage image = WithoutHand(full_image, scene);
    if (index == 0) {
      keyframe_ = image;
      T_world_key_ = Eigen::Isometry3d::Identity();
      T_world_camera_ = T_world_key_;
    } else {
      std::optional<Eigen::Isometry3d> T = PoseAgainstKeyframe(image);
      if (!T && has_previous_) {
        // Re-key on the previous fused frame (its pose is known) and try again.
        keyframe_ = previous_;
        T_world_key_ = T_world_previous_;
        ++stats_.rekeys;
        T = PoseAgainstKeyframe(image);
      }
      if (!T) {
        ++stats_.ego_failures;
        return false;
      }
      T_world_camera_ = *T;
    }
    Fuse(full_image, scene, index == 0);
    previous_ = image;
    T_world_previous_ = T_world_camera_;
    has_previous_ = true;
    ++stats_.frames_fused;
    return true;
  }

  bool NextFrameIsDue() const { return frames_seen_ % params_.every_frames == 0; }
  void Skip() { ++frames_seen_; }

  std::vector<CompletedObject> Completed() const {
    std::vector<CompletedObject> out;
    const auto& cp = params_.blobs.confidence;
    for (const mapping::Blob& b : map_.blobs()) {
      CompletedObject c;
      c.blob_id = b.id;
      const auto it = first_frame_object_.find(b.id);
      c.first_frame_object = it == first_frame_object_.end() ? -1 : it->second;
      c.points = static_cast<int>(b.size());
      std::vector<int> confident;
      double sum = 0;
      for (std::size_t i = 0; i < b.size(); ++i) {
        const double cv = mapping::ConfidenceValue(b.evidence[i], cp);
        sum += cv;
        int band = 0;
        while (band + 1 < static_cast<int>(kConfidenceBandLow.size()) && cv >= kConfidenceBandLow[band + 1]) ++band;
        ++c.points_per_band[band];
        if (cv >= params_.completed_min_cv) confident.push_back(static_cast<int>(i));
      }
      c.mean_confidence = b.size() > 0 ? sum / static_cast<double>(b.size()) : 0.0;
      c.completed_points = static_cast<int>(confident.size());
      if (c.completed_points >= params_.min_completed_points) {
        const Eigen::Matrix3Xf xyz = b.xyz_world.cast<float>();
        c.completed_box = objects::FitVerticalBox(xyz, confident, plane_.normal.cast<float>().normalized());
        c.completed_pca_box = objects::FitPcaBox(xyz, confident);
      }
      out.push_back(c);
    }
    return out;
  }

  const ObjectMapStats& stats() const { return stats_; }
  const Eigen::Isometry3d& T_world_camera() const { return T_world_camera_; }
  const mapping::BlobMap& blob_map() const { return map_; }

 private:
  // T_world_camera of @p image from the ego-motion against the keyframe, when it is supported by
  // enough inliers.
  std::optional<Eigen::Isometry3d> PoseAgainstKeyframe(const RgbdImage& image) const {
    const auto motion = EstimateEgoMotion(keyframe_, image, k_, odometry_);
    if (!motion || static_cast<int>(motion->inliers.size()) < params_.min_keyframe_inliers) return std::nullopt;
    // motion->T_2_1 maps keyframe-camera points into the current camera.
    return T_world_key_ * motion->T_2_1.inverse();
  }

  // @p image with the depth of the hand's blob (dilated by a few pixels for its rim, which lies
  // under the foreground height) removed, so no feature is taken there.
  RgbdImage WithoutHand(const RgbdImage& image, const SceneGeometry& scene) const {
    cv::Mat hand = cv::Mat::zeros(image.height(), image.width(), CV_8UC1);
    bool any = false;
    for (const SceneObject& o : scene.objects) {
      if (!o.is_hand) continue;
      for (int p : o.pixels) hand.data[p] = 255;
      any = true;
    }
    if (!any) return image;
    const int r = params_.hand_margin_px;
    cv::dilate(hand, hand, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
    RgbdImage out = image;
    out.depth_m = image.depth_m.clone();
    out.depth_m.setTo(0.f, hand);
    return out;
  }

  void Fuse(const RgbdImage& image, const SceneGeometry& scene, bool first) {
    const Eigen::Matrix3Xf cloud = OrganizedCloud(image, k_);
    const Eigen::Matrix3d R = T_world_camera_.linear();
    std::vector<mapping::ObservedBlob> blobs;
    std::vector<int> scene_ids;
    for (const SceneObject& o : scene.objects) {
      if (o.is_hand || o.pixels.empty()) continue;
      mapping::ObservedBlob b;
      b.xyz_world.resize(3, static_cast<Eigen::Index>(o.pixels.size()));
      b.cov_world.reserve(o.pixels.size());
      for (std::size_t i = 0; i < o.pixels.size(); ++i) {
        const Eigen::Vector3d p = cloud.col(o.pixels[i]).cast<double>();
        b.xyz_world.col(static_cast<Eigen::Index>(i)) = T_world_camera_ * p;
        const Eigen::Matrix3d c = mapping::RayCovariance(p, KinectDepthSigmaM(p.z()), params_.pixel_sigma_px * p.z() / k_.fx_px);
        b.cov_world.push_back(R * c * R.transpose());
      }
      blobs.push_back(std::move(b));
      scene_ids.push_back(o.id);
    }
    mapping::PinholeCamera cam;
    cam.fx_px = k_.fx_px;
    cam.fy_px = k_.fy_px;
    cam.cx_px = k_.cx_px;
    cam.cy_px = k_.cy_px;
    cam.width_px = image.width();
    cam.height_px = image.height();
    cam.T_world_camera = T_world_camera_;
    std::vector<float> depth(static_cast<std::size_t>(image.width()) * image.height());
    for (int v = 0; v < image.height(); ++v) {
      const float* row = image.depth_m.ptr<float>(v);
      std::copy(row, row + image.width(), depth.begin() + static_cast<std::ptrdiff_t>(v) * image.width());
    }
    const std::size_t before = map_.blobs().size();
    const mapping::BlobMapUpdate u = map_.Update(blobs, cam, depth);
    stats_.matched += u.matched;
    stats_.unpredicted += u.unpredicted;
    stats_.unobserved += u.unobserved;
    if (first) {
      // An empty map turns every observed blob into a stored one, in order.
      for (std::size_t i = before; i < map_.blobs().size(); ++i) {
        first_frame_object_[map_.blobs()[i].id] = scene_ids[i - before];
      }
    }
  }

  DepthIntrinsics k_;
  InteractionPlane plane_;
  ObjectMapParams params_;
  OdometryParams odometry_;
  mapping::BlobMap map_;
  ObjectMapStats stats_;
  int frames_seen_ = 0;
  RgbdImage keyframe_, previous_;
  bool has_previous_ = false;
  Eigen::Isometry3d T_world_key_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_previous_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_camera_ = Eigen::Isometry3d::Identity();
  std::map<int, int> first_frame_object_;
};

ObjectMap::ObjectMap(const DepthIntrinsics& intrinsics, const InteractionPlane& plane, const ObjectMapParams& params,
                     const OdometryParams& odometry) {
  params.Validate();
  odometry.Validate();
  intrinsics.Validate();
  impl_ = std::make_unique<Impl>(intrinsics, plane, params, odometry);
}
ObjectMap::~ObjectMap() = default;
bool ObjectMap::Add(const RgbdImage& image, const SceneGeometry& scene) { return impl_->Add(image, scene); }
bool ObjectMap::NextFrameIsDue() const { return impl_->NextFrameIsDue(); }
void ObjectMap::Skip() { impl_->Skip(); }
std::vector<CompletedObject> ObjectMap::Completed() const { return impl_->Completed(); }
const ObjectMapStats& ObjectMap::stats() const { return impl_->stats(); }
const Eigen::Isometry3d& ObjectMap::T_world_camera() const { return impl_->T_world_camera(); }
const mapping::BlobMap& ObjectMap::blob_map() const { return impl_->blob_map(); }

}  // namespace romo::indoor_manip
