#include "romo/stereo/multi_rig.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include <opencv2/imgproc.hpp>

#include "internal/thread_pool.hpp"
#include "romo/core/check.hpp"
#include "romo/stereo/rectification.hpp"

namespace romo::stereo {
namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void StereoParams::Validate() const {
  if (disparity_size < 16 || disparity_size > 256 || disparity_size % 16 != 0) {
    Fail("StereoParams.disparity_size = " + std::to_string(disparity_size) +
         ": must be a multiple of 16 in [16, 256]");
  }
  if (mono16_significant_bits < 8 || mono16_significant_bits > 16) {
    Fail("StereoParams.mono16_significant_bits = " + std::to_string(mono16_significant_bits) +
         ": must be 8..16");
  }
  sgm.Validate();
  reprojection.Validate();
}

cv::Mat ToGreyMat(const drivers::Image& image) {
  image.Validate();
  auto* data = const_cast<std::uint8_t*>(image.data.data());  // wrapped read-only
  switch (image.format) {
    case drivers::PixelFormat::kMono8:
      return cv::Mat(image.height, image.width, CV_8UC1, data, static_cast<std::size_t>(image.stride_bytes));
    case drivers::PixelFormat::kMono16:
      return cv::Mat(image.height, image.width, CV_16UC1, data, static_cast<std::size_t>(image.stride_bytes));
    case drivers::PixelFormat::kRgb8: {
      const cv::Mat rgb(image.height, image.width, CV_8UC3, data, static_cast<std::size_t>(image.stride_bytes));
      cv::Mat grey;
      cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
      return grey;
    }
  }
  Fail("unknown pixel format " + std::to_string(static_cast<int>(image.format)));
}

namespace {

// Everything one rig needs, built once.
struct RigPipeline {
  const drivers::RigCalibration* calibration;
  Rectifier rectifier;
  StereoSgm sgm;
  cv::Mat left_rect, right_rect;  // scratch, one task per rig at a time
};

}  // namespace

class MultiRigStereo::Impl {
 public:
  Impl(const drivers::Calibration& calibration, const StereoParams& params, int threads)
      : calibration_(calibration), params_(params),
        pool_(threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()))) {
    params.Validate();
    if (calibration_.rigs.empty()) Fail("MultiRigStereo: the calibration has no rigs");
    for (const drivers::RigCalibration& rig : calibration_.rigs) {
      rigs_.push_back(std::make_unique<RigPipeline>(RigPipeline{
          &rig, Rectifier(rig),
          StereoSgm(rig.width_px, rig.height_px, params.disparity_size, 8, 16, params.sgm), {}, {}}));
    }
  }

  RigResult ProcessRig(const drivers::StereoFrame& frame) {
    const auto t0 = std::chrono::steady_clock::now();
    RigResult result;
    result.rig_id = frame.rig_id;
    try {
      RigPipeline& rig = Find(frame.rig_id);
      const cv::Mat left = To8Bit(ToGreyMat(frame.left.image));
      const cv::Mat right = To8Bit(ToGreyMat(frame.right.image));
      auto t = std::chrono::steady_clock::now();
      rig.rectifier.Rectify(left, right, &rig.left_rect, &rig.right_rect);
      result.rectify_ms = MsSince(t);
      t = std::chrono::steady_clock::now();
      rig.sgm.execute(rig.left_rect, rig.right_rect, &result.disparity);
      result.match_ms = MsSince(t);
      result.subpixel_scale = rig.sgm.subpixel_scale();
      result.invalid_disparity = rig.sgm.get_invalid_disparity();
      t = std::chrono::steady_clock::now();
      result.cloud_vehicle = ReprojectDisparity(result.disparity, result.subpixel_scale, result.invalid_disparity,
                                                rig.left_rect, rig.rectifier.geometry(), params_.reprojection,
                                                rig.calibration->T_vehicle_rig);
      result.reproject_ms = MsSince(t);
      result.ok = true;
    } catch (const std::exception& e) {
      // romo::Error for bad input; cv::Exception must not escape a worker thread either.
      result.ok = false;
      result.error = e.what();
    }
    result.total_ms = MsSince(t0);
    return result;
  }

  std::vector<RigResult> Process(const drivers::FrameSet& frames) {
    std::vector<RigResult> results(frames.stereo.size());
    // Two frames of one rig in a set would share its scratch buffers: run those one by one.
    std::vector<int> ids;
    for (const auto& f : frames.stereo) ids.push_back(f.rig_id);
    std::sort(ids.begin(), ids.end());
    if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) {
      for (std::size_t i = 0; i < frames.stereo.size(); ++i) results[i] = ProcessRig(frames.stereo[i]);
      return results;
    }
    pool_.Run(frames.stereo.size(), [&](std::size_t i) { results[i] = ProcessRig(frames.stereo[i]); });
    return results;
  }

  int threads() const { return pool_.size(); }

 private:
  RigPipeline& Find(int rig_id) {
    for (auto& rig : rigs_) {
      if (rig->calibration->rig_id == rig_id) return *rig;
    }
    Fail("MultiRigStereo: frame of rig " + std::to_string(rig_id) + " but the calibration has no such rig");
  }

  cv::Mat To8Bit(const cv::Mat& grey) const {
    if (grey.depth() == CV_8U) return grey;
    cv::Mat out;
    grey.convertTo(out, CV_8U, 1.0 / (1 << (params_.mono16_significant_bits - 8)));
    return out;
  }

  drivers::Calibration calibration_;  // owned copy: rig pipelines point into it
  StereoParams params_;
  std::vector<std::unique_ptr<RigPipeline>> rigs_;
  internal::ThreadPool pool_;
};

MultiRigStereo::MultiRigStereo(const drivers::Calibration& calibration, const StereoParams& params, int threads)
    : impl_(std::make_unique<Impl>(calibration, params, threads)) {}
MultiRigStereo::~MultiRigStereo() = default;
std::vector<RigResult> MultiRigStereo::Process(const drivers::FrameSet& frames) { return impl_->Process(frames); }
RigResult MultiRigStereo::ProcessRig(const drivers::StereoFrame& frame) { return impl_->ProcessRig(frame); }
int MultiRigStereo::threads() const { return impl_->threads(); }

}  // namespace romo::stereo
