#pragma once
/// Semi-global matching with a libSGM-style interface: construct once for an image size and
/// disparity range, then call execute() per rectified pair. The back end (OpenCV StereoSGBM today)
/// sits behind a pimpl so vectorised or CUDA back ends can replace it without touching callers.
#include <memory>

#include <opencv2/core/mat.hpp>

namespace romo::stereo {

/// Aggregation paths; each maps onto an OpenCV StereoSGBM mode.
enum class PathCount {
  k3 = 3,  ///< MODE_SGBM_3WAY: 3 directions, parallel over rows (fastest)
  k5 = 5,  ///< MODE_SGBM: 5 directions, single pass
  k8 = 8,  ///< MODE_HH: all 8 directions, two passes (slowest, most memory)
};

/// Filtering applied after matching (measured on Middlebury with `romo eval stereo`).
enum class PostFilter {
  kNone,
  kMedian3,  ///< 3x3 median over valid disparities only (invalid pixels stay invalid)
  kWls,      ///< ximgproc weighted-least-squares with a right-view matcher (about 2x the cost)
};

/// Matching parameters. Costs are sums over a block_size^2 window of pre-filtered intensities,
/// so p1/p2 scale with block_size^2 (OpenCV's test uses 10 w^2 and 40 w^2).
/// The defaults were tuned on the Middlebury scenes with `romo eval stereo` (3 paths, 1 px block):
/// they beat OpenCV's own reference figures on every scene (tests/stereo/middlebury_test.cpp).
/// Post-filters measured there: the valid-only 3x3 median lowers bad-1 by at most 0.0015 (tsukuba
/// 0.0620 -> 0.0605) for ~25% more time, so it is off by default; WLS does not pay off (RMS
/// doubles on poster and sawtooth). 8 paths were no better than 3 at 3-6x the cost.
struct SgmParameters {
  int p1 = 14;  ///< penalty for a +-1 px disparity change between neighbours
  int p2 = 30;  ///< penalty for larger disparity jumps; must exceed p1
  /// libSGM-style: the best cost must be below uniqueness x the second-best cost; 1 = off.
  float uniqueness = 0.95f;
  bool subpixel = true;  ///< output in 1/16 px (kSubpixelScale) instead of whole pixels
  bool lr_check = true;  ///< drop pixels whose left-right disparities differ by > lr_max_diff_px
  int lr_max_diff_px = 1;
  PathCount path_count = PathCount::k3;
  int min_disparity = 0;  ///< smallest disparity searched, px
  int block_size = 1;  ///< matching window side, odd, 1..11 px
  int pre_filter_cap = 63;  ///< clamp of the x-derivative pre-filter, 1..63
  int speckle_window_px = 100;  ///< largest blob (px) removed as speckle; 0 = no speckle filter
  int speckle_range_px = 2;  ///< max disparity step (px) inside one speckle blob
  PostFilter post_filter = PostFilter::kNone;
  /// With subpixel output: each disparity is refined by 1-D Lucas-Kanade on the rectified pair
  /// over a (2r+1)^2 window (RefineDisparityByGradient); 0 = OpenCV's parabola fit alone, which
  /// pulls disparities toward whole pixels ("pixel locking").
  int gradient_refine_radius_px = 0;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

class StereoSgm {
 public:
  using Parameters = SgmParameters;

  /// Fixed-point scale of subpixel output (4 fractional bits, as libSGM and OpenCV).
  static constexpr int kSubpixelScale = 16;

  /// @param disparity_size number of disparities searched: a multiple of 16 in [16, 256]
  ///        (libSGM allows 64/128/256; smaller ranges serve small images such as Middlebury).
  /// @param input_depth_bits 8 (CV_8UC1 input) or 9..16 (CV_16UC1 holding that many significant
  ///        bits, e.g. 12 for 12-bit cameras; reduced to 8 bits by shifting).
  /// @param output_depth_bits 16 (CV_16SC1) or 8 (CV_8UC1; needs subpixel off and
  ///        min_disparity + disparity_size <= 255).
  /// @throws romo::Error for any argument or parameter out of range.
  StereoSgm(int width, int height, int disparity_size, int input_depth_bits,
            int output_depth_bits, const Parameters& params = Parameters{});
  ~StereoSgm();
  StereoSgm(StereoSgm&&) noexcept;
  StereoSgm& operator=(StereoSgm&&) noexcept;

  /// Disparity of the left image of a rectified pair, in left-image pixels.
  /// Valid output = disparity x subpixel_scale(); invalid pixels hold get_invalid_disparity().
  /// @param disparity reallocated when its size or type differ.
  /// @throws romo::Error for empty images, a size or type different from the construction, or
  ///         an image without texture (constant value).
  void execute(const cv::Mat& left, const cv::Mat& right, cv::Mat* disparity);

  /// The value of pixels without a disparity: (min_disparity - 1) x subpixel_scale() for 16-bit
  /// output (-16 with the defaults, as OpenCV), 255 for 8-bit output.
  int get_invalid_disparity() const;
  /// 16 with subpixel output, else 1.
  int subpixel_scale() const;
  int width() const;
  int height() const;
  int disparity_size() const;
  const Parameters& parameters() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// Converts execute()'s output to float pixels; invalid pixels become @p invalid_value_px.
cv::Mat DisparityToFloat(const cv::Mat& disparity, int subpixel_scale, int invalid_disparity,
                         float invalid_value_px);

/// 3x3 median over valid pixels only, in place (the stage behind PostFilter::kMedian3).
/// Pixels that are invalid stay invalid; a valid pixel takes the median of its valid neighbours.
void MedianFilterValid(cv::Mat* disparity, int invalid_disparity);

/// Refines a subpixel disparity map (value = disparity x @p subpixel_scale) of the rectified
/// 8-bit pair in place: two Gauss-Newton steps of the window's zero-mean intensity difference
/// between left and shifted right (x-gradients averaged over both images), window (2 @p radius
/// + 1)^2. A pixel keeps its disparity where the window lacks x-texture, leaves either image,
/// or the refinement moves it by a pixel or more (a depth edge).
void RefineDisparityByGradient(const cv::Mat& left8, const cv::Mat& right8, int radius, int subpixel_scale,
                               int invalid_disparity, cv::Mat* disparity);

}  // namespace romo::stereo
