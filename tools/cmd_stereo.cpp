// `romo stereo`: one image pair -> disparity (16-bit PNG), a colour-mapped picture and the point
// cloud (PCD). With --calib the raw pair is rectified and the cloud is in the vehicle frame;
// without it the pair must already be rectified and the cloud is in the left camera frame.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/stereo/pcd_io.hpp"
#include "romo/stereo/rectification.hpp"
#include "romo/stereo/reprojection.hpp"
#include "romo/stereo/sgm.hpp"

namespace romo::tools {
namespace {

namespace fs = std::filesystem;

struct Options {
  std::string left, right, calib, out;
  int rig = 0;
  int ndisp = 128;
  double focal_px = 400.0;   // the sample RoMo cameras
  double baseline_m = 0.25;  // the sample RoMo rigs
  double max_range_m = 40.0;
};

cv::Mat ReadGrey(const std::string& path) {
  const cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) Fail("image '" + path + "' is missing or not an image");
  return img;
}

void WritePng(const std::string& path, const cv::Mat& img) {
  if (!cv::imwrite(path, img)) Fail("cannot write '" + path + "'");
}

void Run(const Options& o) {
  cv::Mat left = ReadGrey(o.left);
  cv::Mat right = ReadGrey(o.right);
  if (left.size() != right.size()) {
    Fail("left '" + o.left + "' is " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
         ", right '" + o.right + "' is " + std::to_string(right.cols) + "x" + std::to_string(right.rows));
  }
  stereo::RectifiedGeometry geometry;
  Eigen::Isometry3d T_out_rig = Eigen::Isometry3d::Identity();
  const char* frame = "rig (left camera: x right, y down, z forward)";
  if (!o.calib.empty()) {
    const drivers::Calibration calibration = drivers::Calibration::Load(o.calib);
    const drivers::RigCalibration& rig = calibration.rig(o.rig);
    const stereo::Rectifier rectifier(rig);
    cv::Mat l, r;
    rectifier.Rectify(left, right, &l, &r);
    left = l;
    right = r;
    geometry = rectifier.geometry();
    T_out_rig = rig.T_vehicle_rig;
    frame = "vehicle (x forward, y left, z up)";
  } else {
    if (!(o.focal_px > 0.0)) Fail("--focal " + std::to_string(o.focal_px) + " must be > 0");
    if (!(o.baseline_m > 0.0)) Fail("--baseline " + std::to_string(o.baseline_m) + " must be > 0");
    geometry.focal_px = o.focal_px;
    geometry.baseline_m = o.baseline_m;
    geometry.cx_px = (left.cols - 1) / 2.0;
    geometry.cy_px = (left.rows - 1) / 2.0;
  }

  stereo::StereoSgm sgm(left.cols, left.rows, o.ndisp, 8, 16);
  cv::Mat disparity;
  const auto t0 = std::chrono::steady_clock::now();
  sgm.execute(left, right, &disparity);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  stereo::ReprojectionParams reprojection;
  reprojection.max_range_m = o.max_range_m;
  const PointCloud cloud = stereo::ReprojectDisparity(disparity, sgm.subpixel_scale(), sgm.get_invalid_disparity(),
                                                      left, geometry, reprojection, T_out_rig);

  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) Fail("cannot create output folder '" + o.out + "': " + ec.message());
  // 16-bit PNG: value = disparity x 16 (1/16 px), 0 = no disparity.
  const cv::Mat valid = disparity > 0;
  cv::Mat png16 = cv::Mat::zeros(disparity.size(), CV_16UC1);
  disparity.convertTo(png16, CV_16U);
  png16.setTo(0, ~valid);
  WritePng((fs::path(o.out) / "disparity.png").string(), png16);
  // Colour picture: near = warm, far = cold, black = no disparity.
  cv::Mat scaled, colour;
  disparity.convertTo(scaled, CV_8U, 255.0 / (o.ndisp * sgm.subpixel_scale()));
  cv::applyColorMap(scaled, colour, cv::COLORMAP_TURBO);
  colour.setTo(cv::Scalar::all(0), ~valid);
  WritePng((fs::path(o.out) / "disparity_color.png").string(), colour);
  const std::string pcd = (fs::path(o.out) / "cloud.pcd").string();
  stereo::SavePcd(cloud, pcd);

  const double density = static_cast<double>(cv::countNonZero(valid)) / static_cast<double>(disparity.total());
  std::printf("%dx%d, %d disparities: %.1f ms, %.1f%% of pixels matched, %zu points (%s frame, f %.1f px, b %.3f m)\n",
              left.cols, left.rows, o.ndisp, ms, 100.0 * density, cloud.size(), frame, geometry.focal_px,
              geometry.baseline_m);
  std::printf("wrote %s/{disparity.png (value/16 = px), disparity_color.png, cloud.pcd}\n", o.out.c_str());
}

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = root.add_subcommand("stereo", "Disparity, picture and point cloud of one stereo pair");
  cmd->add_option("--left", opts->left, "left image")->required();
  cmd->add_option("--right", opts->right, "right image")->required();
  cmd->add_option("--calib", opts->calib, "calibration YAML; without it the pair must be rectified");
  cmd->add_option("--rig", opts->rig, "rig id in --calib")->capture_default_str();
  cmd->add_option("--out", opts->out, "output folder")->required();
  cmd->add_option("--ndisp", opts->ndisp, "disparities searched (multiple of 16, 16..256)")->capture_default_str();
  cmd->add_option("--focal", opts->focal_px, "focal length in px of a rectified pair (without --calib)")
      ->capture_default_str();
  cmd->add_option("--baseline", opts->baseline_m, "baseline in m of a rectified pair (without --calib)")
      ->capture_default_str();
  cmd->add_option("--max-range", opts->max_range_m, "drop points farther than this, m")->capture_default_str();
  cmd->callback([opts] { Run(*opts); });
});

}  // namespace
}  // namespace romo::tools
