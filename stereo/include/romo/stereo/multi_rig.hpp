#pragma once
/// All rigs of a frame set through rectify -> SGM -> reprojection, one task per rig on a thread
/// pool sized to the cores. This is the stereo stage of the vehicle pipeline:
///
///   romo::stereo::MultiRigStereo stereo(calibration, romo::stereo::StereoParams{});
///   for (const auto& rig : stereo.Process(frame_set)) {
///     if (rig.ok) fused.Append(rig.cloud_vehicle);  // vehicle frame, sigma_z per point
///   }
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "romo/core/point_cloud.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/stereo/reprojection.hpp"
#include "romo/stereo/sgm.hpp"

namespace romo::stereo {

struct StereoParams {
  int disparity_size = 128;  ///< multiple of 16 in [16, 256]
  SgmParameters sgm;
  ReprojectionParams reprojection;
  /// Significant bits of mono16 camera images (12-bit cameras: 12); shifted down to 8 bits.
  int mono16_significant_bits = 12;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// One rig's result for one frame set.
struct RigResult {
  int rig_id = 0;
  bool ok = false;
  std::string error;  ///< why the rig produced nothing (constant image, size mismatch, ...)
  cv::Mat disparity;  ///< rectified left view, StereoSgm output (CV_16SC1)
  int subpixel_scale = StereoSgm::kSubpixelScale;
  int invalid_disparity = -StereoSgm::kSubpixelScale;
  PointCloud cloud_vehicle;  ///< vehicle frame, sigma_z and grey intensity per point
  double rectify_ms = 0.0, match_ms = 0.0, reproject_ms = 0.0, total_ms = 0.0;
};

/// Converts a camera image to a grey cv::Mat: mono8 shares the buffer, mono16 and rgb8 are
/// converted (mono16 keeps its 16-bit depth; use StereoSgm's input_depth_bits for it).
/// @throws romo::Error for an inconsistent image.
cv::Mat ToGreyMat(const drivers::Image& image);

class MultiRigStereo {
 public:
  /// Builds rectification maps and a matcher per rig once.
  /// @param threads worker count; 0 = std::thread::hardware_concurrency().
  /// @throws romo::Error for bad parameters or a rig that cannot be rectified.
  MultiRigStereo(const drivers::Calibration& calibration, const StereoParams& params, int threads = 0);
  ~MultiRigStereo();
  MultiRigStereo(const MultiRigStereo&) = delete;
  MultiRigStereo& operator=(const MultiRigStereo&) = delete;

  /// Processes every rig present in @p frames in parallel; results in the order of
  /// frames.stereo. A rig that fails (unknown rig id, image size differing from the calibration,
  /// constant image) yields ok = false with the reason in error; the others are unaffected.
  std::vector<RigResult> Process(const drivers::FrameSet& frames);
  /// One rig, on the calling thread.
  RigResult ProcessRig(const drivers::StereoFrame& frame);

  int threads() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace romo::stereo
