#include "romo/stereo/sgm.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/disparity_filter.hpp>

#include "romo/core/check.hpp"

namespace romo::stereo {
namespace {

std::string SizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

int OpenCvMode(PathCount paths) {
  switch (paths) {
    case PathCount::k3: return cv::StereoSGBM::MODE_SGBM_3WAY;
    case PathCount::k5: return cv::StereoSGBM::MODE_SGBM;
    case PathCount::k8: return cv::StereoSGBM::MODE_HH;
  }
  Fail("StereoSgm::Parameters.path_count = " + std::to_string(static_cast<int>(paths)) +
       ": must be 3, 5 or 8");
}

// libSGM's uniqueness u (best < u * second) expressed as OpenCV's margin in percent
// (best * (100 + r) / 100 < second).
int UniquenessRatioPercent(float uniqueness) {
  return static_cast<int>(std::lround(100.0 / uniqueness - 100.0));
}

// Median of n values (n <= 9) in place.
inline short Median(short* v, int n) {
  std::nth_element(v, v + n / 2, v + n);
  return v[n / 2];
}

}  // namespace

void SgmParameters::Validate() const {
  auto bad = [](const std::string& field, const std::string& value, const std::string& rule) {
    Fail("SgmParameters." + field + " = " + value + ": " + rule);
  };
  if (p1 <= 0) bad("p1", std::to_string(p1), "must be > 0");
  if (p2 <= p1) bad("p2", std::to_string(p2), "must be > p1 (" + std::to_string(p1) + ")");
  if (!(uniqueness > 0.f && uniqueness <= 1.f)) {
    bad("uniqueness", std::to_string(uniqueness), "must be in (0, 1]");
  }
  if (lr_max_diff_px < 0) bad("lr_max_diff_px", std::to_string(lr_max_diff_px), "must be >= 0");
  if (path_count != PathCount::k3 && path_count != PathCount::k5 && path_count != PathCount::k8) {
    bad("path_count", std::to_string(static_cast<int>(path_count)), "must be 3, 5 or 8");
  }
  if (block_size < 1 || block_size > 11 || block_size % 2 == 0) {
    bad("block_size", std::to_string(block_size), "must be odd in [1, 11]");
  }
  if (pre_filter_cap < 1 || pre_filter_cap > 63) {
    bad("pre_filter_cap", std::to_string(pre_filter_cap), "must be in [1, 63]");
  }
  if (gradient_refine_radius_px < 0 || gradient_refine_radius_px > 5) {
    bad("gradient_refine_radius_px", std::to_string(gradient_refine_radius_px), "must be in [0, 5]");
  }
  if (speckle_window_px < 0) bad("speckle_window_px", std::to_string(speckle_window_px), "must be >= 0");
  if (speckle_range_px < 0) bad("speckle_range_px", std::to_string(speckle_range_px), "must be >= 0");
  if (post_filter != PostFilter::kNone && post_filter != PostFilter::kMedian3 &&
      post_filter != PostFilter::kWls) {
    bad("post_filter", std::to_string(static_cast<int>(post_filter)), "unknown filter");
  }
}

class StereoSgm::Impl {
 public:
  Impl(int width, int height, int disparity_size, int input_bits, int output_bits,
       const Parameters& params)
      : width_(width), height_(height), disparity_size_(disparity_size), input_bits_(input_bits),
        output_bits_(output_bits), params_(params) {
    if (width <= 0 || height <= 0) Fail("StereoSgm: image size " + SizeText(width, height) + " must be positive");
    if (disparity_size < 16 || disparity_size > 256 || disparity_size % 16 != 0) {
      Fail("StereoSgm: disparity_size = " + std::to_string(disparity_size) +
           ": must be a multiple of 16 in [16, 256]");
    }
    if (input_bits < 8 || input_bits > 16) {
      Fail("StereoSgm: input_depth_bits = " + std::to_string(input_bits) + ": must be 8..16");
    }
    if (output_bits != 8 && output_bits != 16) {
      Fail("StereoSgm: output_depth_bits = " + std::to_string(output_bits) + ": must be 8 or 16");
    }
    params.Validate();
    if (output_bits == 8 && (params.subpixel || params.min_disparity < 0 ||
                             params.min_disparity + disparity_size > 255)) {
      Fail("StereoSgm: 8-bit output needs subpixel off and 0 <= min_disparity (" +
           std::to_string(params.min_disparity) + ") with min_disparity + disparity_size (" +
           std::to_string(disparity_size) + ") <= 255");
    }
    const int w = params.block_size;
    matcher_ = cv::StereoSGBM::create(
        params.min_disparity, disparity_size, w, params.p1, params.p2,
        params.lr_check ? params.lr_max_diff_px : -1, params.pre_filter_cap,
        UniquenessRatioPercent(params.uniqueness), params.speckle_window_px,
        params.speckle_range_px, OpenCvMode(params.path_count));
    if (params.post_filter == PostFilter::kWls) {
      wls_ = cv::ximgproc::createDisparityWLSFilter(matcher_);
      right_matcher_ = cv::ximgproc::createRightMatcher(matcher_);
    }
    internal_invalid_ = (params.min_disparity - 1) * cv::StereoMatcher::DISP_SCALE;
  }

  void Execute(const cv::Mat& left, const cv::Mat& right, cv::Mat* disparity) {
    ROMO_THROW_UNLESS(disparity != nullptr);
    const cv::Mat& l = Prepare(left, "left", &left8_);
    const cv::Mat& r = Prepare(right, "right", &right8_);
    const bool direct = output_bits_ == 16 && params_.subpixel &&
                        params_.post_filter == PostFilter::kNone;
    // The common case writes straight into the caller's buffer: no wrapper cost but the checks.
    cv::Mat& raw = direct ? *disparity : raw_;
    matcher_->compute(l, r, raw);
    switch (params_.post_filter) {
      case PostFilter::kNone: break;
      case PostFilter::kMedian3: MedianFilterValid(&raw, internal_invalid_); break;
      case PostFilter::kWls: {
        right_matcher_->compute(r, l, right_raw_);
        wls_->filter(raw, l, filtered_, right_raw_);
        // WLS output (same 1/16 px scale) replaces the raw map; it fills most invalid pixels.
        filtered_.copyTo(raw);
        break;
      }
    }
    if (params_.subpixel && params_.gradient_refine_radius_px > 0) {
      RefineDisparityByGradient(l, r, params_.gradient_refine_radius_px, kSubpixelScale, internal_invalid_, &raw);
    }
    if (direct) return;
    if (output_bits_ == 16 && params_.subpixel) {
      raw.copyTo(*disparity);
      return;
    }
    const int out_type = output_bits_ == 16 ? CV_16SC1 : CV_8UC1;
    disparity->create(height_, width_, out_type);
    const int invalid_out = InvalidOut();
    for (int y = 0; y < height_; ++y) {
      const short* src = raw.ptr<short>(y);
      if (out_type == CV_16SC1) {
        short* dst = disparity->ptr<short>(y);
        for (int x = 0; x < width_; ++x) {
          dst[x] = src[x] <= internal_invalid_
                       ? static_cast<short>(invalid_out)
                       : static_cast<short>((src[x] + cv::StereoMatcher::DISP_SCALE / 2) >> 4);
        }
      } else {
        std::uint8_t* dst = disparity->ptr<std::uint8_t>(y);
        for (int x = 0; x < width_; ++x) {
          dst[x] = src[x] <= internal_invalid_
                       ? static_cast<std::uint8_t>(invalid_out)
                       : cv::saturate_cast<std::uint8_t>((src[x] + cv::StereoMatcher::DISP_SCALE / 2) >> 4);
        }
      }
    }
  }

  int InvalidOut() const {
    if (output_bits_ == 8) return 255;
    return (params_.min_disparity - 1) * (params_.subpixel ? kSubpixelScale : 1);
  }

  int width_, height_, disparity_size_, input_bits_, output_bits_;
  Parameters params_;

 private:
  // Checks one input image and returns it as CV_8UC1.
  const cv::Mat& Prepare(const cv::Mat& image, const char* which, cv::Mat* scratch) const {
    if (image.empty()) Fail(std::string("StereoSgm::execute: ") + which + " image is empty");
    if (image.cols != width_ || image.rows != height_) {
      Fail(std::string("StereoSgm::execute: ") + which + " image is " + SizeText(image.cols, image.rows) +
           ", the matcher was built for " + SizeText(width_, height_));
    }
    const int expected = input_bits_ == 8 ? CV_8UC1 : CV_16UC1;
    if (image.type() != expected) {
      Fail(std::string("StereoSgm::execute: ") + which + " image has OpenCV type " +
           std::to_string(image.type()) + ", expected " + (input_bits_ == 8 ? "CV_8UC1" : "CV_16UC1") +
           " for input_depth_bits = " + std::to_string(input_bits_));
    }
    double lo = 0.0, hi = 0.0;
    cv::minMaxLoc(image, &lo, &hi);
    if (lo == hi) {
      Fail(std::string("StereoSgm::execute: ") + which + " image is constant (every pixel " +
           std::to_string(static_cast<long>(lo)) + "): nothing to match");
    }
    if (input_bits_ == 8) return image;
    image.convertTo(*scratch, CV_8U, 1.0 / (1 << (input_bits_ - 8)));
    return *scratch;
  }

  cv::Ptr<cv::StereoSGBM> matcher_;
  cv::Ptr<cv::StereoMatcher> right_matcher_;
  cv::Ptr<cv::ximgproc::DisparityWLSFilter> wls_;
  int internal_invalid_ = -16;
  cv::Mat left8_, right8_, raw_, right_raw_, filtered_;
};

StereoSgm::StereoSgm(int width, int height, int disparity_size, int input_depth_bits,
                     int output_depth_bits, const Parameters& params)
    : impl_(std::make_unique<Impl>(width, height, disparity_size, input_depth_bits,
                                   output_depth_bits, params)) {}
StereoSgm::~StereoSgm() = default;
StereoSgm::StereoSgm(StereoSgm&&) noexcept = default;
StereoSgm& StereoSgm::operator=(StereoSgm&&) noexcept = default;

void StereoSgm::execute(const cv::Mat& left, const cv::Mat& right, cv::Mat* disparity) {
  impl_->Execute(left, right, disparity);
}
int StereoSgm::get_invalid_disparity() const { return impl_->InvalidOut(); }
int StereoSgm::subpixel_scale() const { return impl_->params_.subpixel ? kSubpixelScale : 1; }
int StereoSgm::width() const { return impl_->width_; }
int StereoSgm::height() const { return impl_->height_; }
int StereoSgm::disparity_size() const { return impl_->disparity_size_; }
const StereoSgm::Parameters& StereoSgm::parameters() const { return impl_->params_; }

cv::Mat DisparityToFloat(const cv::Mat& disparity, int subpixel_scale, int invalid_disparity,
                         float invalid_value_px) {
  ROMO_THROW_UNLESS(disparity.type() == CV_16SC1 || disparity.type() == CV_8UC1);
  ROMO_THROW_UNLESS(subpixel_scale > 0);
  cv::Mat out(disparity.size(), CV_32FC1);
  const float inv_scale = 1.f / static_cast<float>(subpixel_scale);
  for (int y = 0; y < disparity.rows; ++y) {
    float* dst = out.ptr<float>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      const int v = disparity.type() == CV_16SC1 ? disparity.at<short>(y, x)
                                                 : disparity.at<std::uint8_t>(y, x);
      dst[x] = v == invalid_disparity ? invalid_value_px : static_cast<float>(v) * inv_scale;
    }
  }
  return out;
}

void MedianFilterValid(cv::Mat* disparity, int invalid_disparity) {
  ROMO_THROW_UNLESS(disparity != nullptr && disparity->type() == CV_16SC1);
  const cv::Mat src = disparity->clone();
  const int rows = src.rows, cols = src.cols;
  short window[9];
  for (int y = 0; y < rows; ++y) {
    short* dst = disparity->ptr<short>(y);
    for (int x = 0; x < cols; ++x) {
      if (src.at<short>(y, x) <= invalid_disparity) continue;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= rows) continue;
        const short* row = src.ptr<short>(yy);
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= cols || row[xx] <= invalid_disparity) continue;
          window[n++] = row[xx];
        }
      }
      dst[x] = Median(window, n);
    }
  }
}

namespace {

// The rectified pair as float intensities and their x-gradients (central differences).
struct GradientPair {
  cv::Mat left, right, left_dx, right_dx;
};

// One Gauss-Newton step of disparity @p d at (@p x, @p y): the zero-mean intensity difference
// between the left window and the right one shifted by d, over the gradient averaged over both.
// nullopt where the window leaves the right image or lacks x-texture.
std::optional<double> LucasKanadeStep(const GradientPair& p, int x, int y, int radius, double d) {
  const int n = (2 * radius + 1) * (2 * radius + 1);
  // Below ~1 grey level of x-gradient per pixel the step is noise.
  const double min_gradient_variance = 1.0 * n;
  double sg = 0, se = 0, sgg = 0, sge = 0;
  for (int v = y - radius; v <= y + radius; ++v) {
    const float* l = p.left.ptr<float>(v);
    const float* ldx = p.left_dx.ptr<float>(v);
    const float* r = p.right.ptr<float>(v);
    const float* rdx = p.right_dx.ptr<float>(v);
    for (int u = x - radius; u <= x + radius; ++u) {
      const double xr = u - d;
      const int x0 = static_cast<int>(std::floor(xr));
      if (x0 < 1 || x0 + 2 >= p.right.cols) return std::nullopt;
      const double a = xr - x0;
      const double g = 0.5 * (ldx[u] + (1 - a) * rdx[x0] + a * rdx[x0 + 1]);
      const double e = (1 - a) * r[x0] + a * r[x0 + 1] - l[u];
      sg += g;
      se += e;
      sgg += g * g;
      sge += g * e;
    }
  }
  const double var_g = sgg - sg * sg / n;
  if (var_g < min_gradient_variance) return std::nullopt;
  return (sge - sg * se / n) / var_g;
}

}  // namespace

void RefineDisparityByGradient(const cv::Mat& left8, const cv::Mat& right8, int radius, int subpixel_scale,
                               int invalid_disparity, cv::Mat* disparity) {
  ROMO_THROW_UNLESS(disparity != nullptr && disparity->type() == CV_16SC1);
  ROMO_THROW_UNLESS(left8.type() == CV_8UC1 && right8.type() == CV_8UC1 && left8.size() == right8.size() &&
                    left8.size() == disparity->size());
  ROMO_THROW_UNLESS(radius >= 1 && subpixel_scale > 0);
  GradientPair pair;
  left8.convertTo(pair.left, CV_32F);
  right8.convertTo(pair.right, CV_32F);
  cv::Sobel(pair.left, pair.left_dx, CV_32F, 1, 0, 1, 0.5);
  cv::Sobel(pair.right, pair.right_dx, CV_32F, 1, 0, 1, 0.5);
  const double scale = subpixel_scale;
  constexpr int kSteps = 2;
  for (int y = radius; y < left8.rows - radius; ++y) {
    short* out = disparity->ptr<short>(y);
    for (int x = radius; x < left8.cols - radius; ++x) {
      if (out[x] <= invalid_disparity) continue;
      const double d0 = out[x] / scale;
      std::optional<double> d = d0;
      for (int step = 0; step < kSteps && d; ++step) {
        const std::optional<double> delta = LucasKanadeStep(pair, x, y, radius, *d);
        d = delta ? std::optional<double>(*d + *delta) : std::nullopt;
      }
      // A step of a pixel or more crossed a depth edge: keep the matcher's value.
      if (d && std::abs(*d - d0) < 1.0) out[x] = static_cast<short>(std::lround(*d * scale));
    }
  }
}

}  // namespace romo::stereo
