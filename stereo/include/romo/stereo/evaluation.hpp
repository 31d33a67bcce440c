#pragma once
/// Disparity quality figures as OpenCV's stereo-matching regression test computes them
/// (modules/calib3d/test/test_stereomatching.cpp), so romo's numbers compare with the
/// reference figures OpenCV ships for StereoSGBM on the Middlebury scenes.
#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

namespace romo::stereo {

struct DisparityMetrics {
  double bad1_all = 0.0;  ///< fraction of evaluated pixels with |d - gt| > 1 px
  double bad2_all = 0.0;  ///< same with > 2 px
  std::optional<double> bad1_nonocc;  ///< over non-occluded pixels; empty without right GT
  std::optional<double> bad2_nonocc;
  double rms_all = 0.0;  ///< RMS of d - gt over evaluated pixels, px
  double density = 0.0;  ///< fraction of evaluated pixels with a valid disparity
  double ms = 0.0;       ///< matching time, filled by the caller
};

/// A Middlebury-style ground truth: disparity_px = stored value / scale, 0 = unknown.
struct DisparityGroundTruth {
  cv::Mat left_px;   ///< CV_32FC1, 0 = unknown
  cv::Mat right_px;  ///< CV_32FC1 or empty (then no occlusion mask)

  /// Reads 8- or 16-bit PNG ground truth (colour files read as grey).
  /// @param right_path "" for none.
  /// @throws romo::Error naming the file when it is missing/unreadable or sizes disagree.
  static DisparityGroundTruth Load(const std::string& left_path, const std::string& right_path,
                                   double scale);
};

/// Ignored image border of OpenCV's test, px.
inline constexpr int kEvalBorderPx = 10;

/// Evaluates @p disparity_px (CV_32FC1, px). Pixels in @p valid_mask (CV_8UC1, optional)
/// that are 0 count as invalid for the density; their value in @p disparity_px is still compared
/// with the ground truth, as OpenCV's test does (an invalid -1 is simply a wrong disparity).
/// Evaluated pixels: known ground truth, more than @p border_px from the image edge.
/// Non-occluded: ground-truth left/right consistency within 1 px (OpenCV's occlusion mask).
/// @throws romo::Error when sizes disagree.
DisparityMetrics EvaluateDisparity(const cv::Mat& disparity_px, const cv::Mat& valid_mask,
                                   const DisparityGroundTruth& gt, int border_px = kEvalBorderPx);

/// OpenCV's own test settings for StereoSGBM on a scene (stereosgbm_params.xml).
struct OpenCvSgbmCase {
  int ndisp = 16;
  int window = 3;
  bool full_dp = false;
};

/// Runs plain cv::StereoSGBM exactly as OpenCV's regression test: P1 = 10 w^2, P2 = 40 w^2,
/// disp12MaxDiff 1, preFilterCap 63, uniqueness 10, speckle 100 / 32, integer result (/16).
/// @param left,right as the test reads them (3-channel BGR) or grey.
/// @param ms filled with the matching time when non-null.
/// @returns CV_32FC1 disparity in whole px, invalid = -1 (as the test leaves it).
cv::Mat RunOpenCvReferenceSgbm(const cv::Mat& left, const cv::Mat& right,
                               const OpenCvSgbmCase& params, double* ms = nullptr);

}  // namespace romo::stereo
