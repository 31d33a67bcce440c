#include "romo/stereo/evaluation.hpp"

#include <chrono>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "romo/core/check.hpp"

namespace romo::stereo {
namespace {

cv::Mat ReadGroundTruth(const std::string& path, double scale) {
  const cv::Mat raw = cv::imread(path, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH);
  if (raw.empty()) Fail("ground-truth disparity '" + path + "' is missing or not an image");
  cv::Mat px;
  raw.convertTo(px, CV_32F, 1.0 / scale);
  return px;
}

}  // namespace

DisparityGroundTruth DisparityGroundTruth::Load(const std::string& left_path,
                                                const std::string& right_path, double scale) {
  if (!(scale > 0.0)) Fail("ground-truth scale " + std::to_string(scale) + " must be > 0");
  DisparityGroundTruth gt;
  gt.left_px = ReadGroundTruth(left_path, scale);
  if (!right_path.empty()) {
    gt.right_px = ReadGroundTruth(right_path, scale);
    if (gt.right_px.size() != gt.left_px.size()) {
      Fail("ground truth '" + right_path + "' is " + std::to_string(gt.right_px.cols) + "x" +
           std::to_string(gt.right_px.rows) + ", '" + left_path + "' is " +
           std::to_string(gt.left_px.cols) + "x" + std::to_string(gt.left_px.rows));
    }
  }
  return gt;
}

DisparityMetrics EvaluateDisparity(const cv::Mat& disparity_px, const cv::Mat& valid_mask,
                                   const DisparityGroundTruth& gt, int border_px) {
  const cv::Mat& gl = gt.left_px;
  ROMO_THROW_UNLESS(gl.type() == CV_32FC1 && disparity_px.type() == CV_32FC1);
  if (disparity_px.size() != gl.size()) {
    Fail("disparity is " + std::to_string(disparity_px.cols) + "x" + std::to_string(disparity_px.rows) +
         " but the ground truth is " + std::to_string(gl.cols) + "x" + std::to_string(gl.rows));
  }
  ROMO_THROW_UNLESS(valid_mask.empty() || (valid_mask.type() == CV_8UC1 && valid_mask.size() == gl.size()));
  const bool have_right = !gt.right_px.empty();
  const cv::Mat& gr = gt.right_px;

  std::size_t n_all = 0, bad1 = 0, bad2 = 0, valid = 0, n_nonocc = 0, bad1_no = 0, bad2_no = 0;
  double sq = 0.0;
  for (int y = border_px; y < gl.rows - border_px; ++y) {
    for (int x = border_px; x < gl.cols - border_px; ++x) {
      const float g = gl.at<float>(y, x);
      if (g == 0.f) continue;  // unknown ground truth
      const float d = disparity_px.at<float>(y, x);
      const float err = std::fabs(d - g);
      ++n_all;
      // OpenCV's test compares |d - gt| > cvRound(threshold).
      const bool b1 = err > 1.f, b2 = err > 2.f;
      bad1 += b1;
      bad2 += b2;
      sq += static_cast<double>(err) * err;
      if (valid_mask.empty() || valid_mask.at<std::uint8_t>(y, x) != 0) ++valid;
      if (have_right) {
        // Non-occluded: the pixel's partner in the right view exists, has known ground truth
        // and is not nearer by more than 1 px (computeOcclusionBasedMasks).
        const int xr = x - static_cast<int>(std::lround(g));
        if (xr < 0) continue;
        const float gright = gr.at<float>(y, xr);
        if (gright == 0.f || gright > g + 1.f) continue;
        ++n_nonocc;
        bad1_no += b1;
        bad2_no += b2;
      }
    }
  }
  DisparityMetrics m;
  if (n_all == 0) Fail("no pixel with known ground truth inside the evaluation border");
  m.bad1_all = static_cast<double>(bad1) / n_all;
  m.bad2_all = static_cast<double>(bad2) / n_all;
  m.rms_all = std::sqrt(sq / n_all);
  m.density = static_cast<double>(valid) / n_all;
  if (have_right && n_nonocc > 0) {
    m.bad1_nonocc = static_cast<double>(bad1_no) / n_nonocc;
    m.bad2_nonocc = static_cast<double>(bad2_no) / n_nonocc;
  }
  return m;
}

cv::Mat RunOpenCvReferenceSgbm(const cv::Mat& left, const cv::Mat& right,
                               const OpenCvSgbmCase& params, double* ms) {
  const int w = params.window;
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      0, params.ndisp, w, 10 * w * w, 40 * w * w, 1, 63, 10, 100, 32,
      params.full_dp ? cv::StereoSGBM::MODE_HH : cv::StereoSGBM::MODE_SGBM);
  cv::Mat disp16;
  const auto t0 = std::chrono::steady_clock::now();
  sgbm->compute(left, right, disp16);
  const auto t1 = std::chrono::steady_clock::now();
  if (ms != nullptr) *ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  disp16 /= 16;  // integer division with rounding, as the test does
  cv::Mat out;
  disp16.convertTo(out, CV_32F);
  return out;
}

}  // namespace romo::stereo
