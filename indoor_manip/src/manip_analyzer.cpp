#include "romo/indoor_manip/manip_analyzer.hpp"

#include <string>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

void ManipParams::Validate() const {
  hand.Validate();
  kalman.Validate();
  rotation.Validate();
  thresholds.Validate();
  location.Validate();
  scene.Validate();
  odometry.Validate();
  icp.Validate();
  map.Validate();
  if (max_lost_frames < 0) Fail("max_lost_frames must be >= 0, got " + std::to_string(max_lost_frames));
}

class ManipAnalyzer::Impl {
 public:
  Impl(const InteractionPlane& plane, const DepthIntrinsics& k, const ManipParams& params)
      : plane_(plane), k_(k), params_(params), kf_(params.kalman) {
    if (params.object_map) map_ = std::make_unique<ObjectMap>(k, plane, params.map, params.odometry);
  }

  std::optional<HandBlob> Add(const RgbdImage& image, cv::Point seed) {
    const double t = image.stamp_ns * 1e-9;
    ++frames_;
    std::optional<HandBlob> blob;
    PathSample s;
    s.t_s = t;
    if (!kf_.initialized()) {
      blob = GrowHandRegion(image, k_, seed, &plane_, params_.hand);
      if (blob->pixel_count < params_.hand.min_pixels) {
        Fail("hand seed (" + std::to_string(seed.x) + "," + std::to_string(seed.y) + ") grew only " +
             std::to_string(blob->pixel_count) + " pixels (min_pixels " +
             std::to_string(params_.hand.min_pixels) + "): not a hand-sized blob");
      }
      kf_.Initialize(blob->centroid_m);
      scene_ = SegmentSceneObjects(image, k_, plane_, blob->seed, params_.scene);
      first_image_ = image;
      s.predicted_m = blob->centroid_m;
      if (map_) map_->Add(image, scene_);
    } else {
      if (lost_ > params_.max_lost_frames) {
        ++without_hand_;
        return std::nullopt;
      }
      s.predicted_m = kf_.Predict(t - last_t_);
      blob = FindHandNear(image, k_, s.predicted_m, &plane_, params_.hand);
      if (map_) {
        // Without the hand found its blob cannot be told from the objects': not fused.
        if (blob && map_->NextFrameIsDue()) {
          map_->Add(image, SegmentSceneObjects(image, k_, plane_, blob->seed, params_.scene));
        } else {
          map_->Skip();
        }
      }
    }
    if (blob) {
      s.measured = true;
      s.measured_m = blob->centroid_m;
      s.hand_pixels = blob->pixel_count;
      s.corrected_m = path_.empty() ? blob->centroid_m : kf_.Correct(blob->centroid_m);
      lost_ = 0;
      if (prev_blob_) {
        // Hand frame {H}: z along the plane normal, x the plane's x axis (Sec. 4.2.4).
        const PlaneFrame f = PlaneAlignedFrame(plane_, blob->centroid_m);
        const RotationStep r = EstimateHandRotation(prev_image_, image, prev_blob_->mask,
                                                    prev_blob_->bbox, k_, f.R_camera_frame(),
                                                    params_.rotation);
        rotation_.push_back(r.valid ? r.angle_rad : Eigen::Vector3d::Zero());
      }
      prev_blob_ = blob;
      prev_image_ = image;
    } else {
      s.corrected_m = s.predicted_m;
      ++lost_;
      ++without_hand_;
      prev_blob_.reset();
    }
    last_t_ = t;
    last_image_ = image;
    path_.push_back(s);
    return blob;
  }

  ManipResult Finish() const {
    int measured = 0;
    for (const auto& s : path_) measured += s.measured;
    if (measured < 2) {
      Fail("manipulation: the hand was found in " + std::to_string(measured) + " of " +
           std::to_string(frames_) + " frames; need at least 2");
    }
    ManipResult r;
    r.plane = plane_;
    r.path = path_;
    r.frames = frames_;
    r.frames_without_hand = without_hand_;
    r.rotation_steps_rad = rotation_;
    // Trailing predictions after the hand was lost for good carry no information.
    std::size_t last = path_.size();
    while (last > 0 && !path_[last - 1].measured) --last;
    std::vector<double> t;
    std::vector<Eigen::Vector3d> c;
    for (std::size_t i = 0; i < last; ++i) {
      t.push_back(path_[i].t_s - path_.front().t_s);
      c.push_back(path_[i].corrected_m);
    }
    r.fingerprint = BuildFingerprint(t, c, plane_, params_.encapsulation);
    r.features = ComputeActionFeatures(r.fingerprint.profiles, rotation_);
    r.decision = ClassifyAction(r.features, params_.thresholds);
    r.locations = FindLocationAreas(r.fingerprint, params_.location);
    r.scene = scene_;
    if (map_) {
      r.completed_objects = map_->Completed();
      r.object_map = map_->stats();
    }
    if (params_.object_motions && frames_ > 1) {
      const SceneGeometry last = SegmentSceneObjects(last_image_, k_, plane_, cv::Point(-1, -1), params_.scene);
      r.object_motions = EstimateObjectMotions(first_image_, scene_, last_image_, last, k_, params_.odometry, params_.icp);
    }
    return r;
  }

 private:
  InteractionPlane plane_;
  DepthIntrinsics k_;
  ManipParams params_;
  HandKalmanFilter kf_;
  std::vector<PathSample> path_;
  SceneGeometry scene_;
  std::unique_ptr<ObjectMap> map_;
  RgbdImage first_image_, last_image_;
  std::vector<Eigen::Vector3d> rotation_;
  std::optional<HandBlob> prev_blob_;
  RgbdImage prev_image_;
  double last_t_ = 0.0;
  int frames_ = 0;
  int lost_ = 0;
  int without_hand_ = 0;
};

ManipAnalyzer::ManipAnalyzer(const InteractionPlane& plane, const DepthIntrinsics& intrinsics,
                             const ManipParams& params) {
  params.Validate();
  intrinsics.Validate();
  impl_ = std::make_unique<Impl>(plane, intrinsics, params);
}

ManipAnalyzer::~ManipAnalyzer() = default;

std::optional<HandBlob> ManipAnalyzer::AddFrame(const RgbdImage& image, cv::Point seed) {
  return impl_->Add(image, seed);
}

ManipResult ManipAnalyzer::Finish() const { return impl_->Finish(); }

}  // namespace romo::indoor_manip
