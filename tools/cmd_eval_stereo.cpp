// `romo eval stereo`: romo's default matcher against Middlebury ground truth, side by side with
// plain OpenCV StereoSGBM run with OpenCV's own regression-test settings, same metric for both.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/check.hpp"
#include "romo/stereo/evaluation.hpp"
#include "romo/stereo/sgm.hpp"

namespace romo::tools {
namespace {

namespace fs = std::filesystem;

struct Options {
  std::string left, right, gt, gt_right, opencv_params;
  double gt_scale = 0.0;
  int ndisp = 0;
  int refine_radius_px = 0;
  int opencv_window = 0;
  bool json = false;
};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}
std::string Num(const std::optional<double>& v) { return v ? Num(*v) : "null"; }

cv::Mat ReadImage(const std::string& path, int flags) {
  const cv::Mat img = cv::imread(path, flags);
  if (img.empty()) Fail("image '" + path + "' is missing or not an image");
  return img;
}

// The scene's window and ndisp from OpenCV's stereosgbm_params.xml (case "<scene>_0").
std::optional<stereo::OpenCvSgbmCase> FindOpenCvCase(const std::string& xml, const std::string& scene) {
  std::error_code ec;
  if (xml.empty() || !fs::is_regular_file(xml, ec)) return std::nullopt;
  cv::FileStorage store(xml, cv::FileStorage::READ);
  const cv::FileNode params = store["params"];
  if (!params.isSeq()) Fail("OpenCV parameter file '" + xml + "': no <params> sequence");
  for (std::size_t i = 0; i + 4 < params.size(); i += 5) {
    if (static_cast<std::string>(params[static_cast<int>(i) + 1]) != scene) continue;
    stereo::OpenCvSgbmCase c;
    c.ndisp = std::stoi(static_cast<std::string>(params[static_cast<int>(i) + 2]));
    c.window = std::stoi(static_cast<std::string>(params[static_cast<int>(i) + 3]));
    c.full_dp = std::stoi(static_cast<std::string>(params[static_cast<int>(i) + 4])) != 0;
    return c;
  }
  return std::nullopt;
}

void Print(const char* who, const stereo::DisparityMetrics& m) {
  std::printf("%-7s bad1 all %.4f nonocc %s | bad2 all %.4f nonocc %s | rms %.3f px | density %.3f | %.1f ms\n",
              who, m.bad1_all, Num(m.bad1_nonocc).c_str(), m.bad2_all, Num(m.bad2_nonocc).c_str(),
              m.rms_all, m.density, m.ms);
}

std::string Json(const stereo::DisparityMetrics& m) {
  return "{\"bad1_all\": " + Num(m.bad1_all) + ", \"bad1_nonocc\": " + Num(m.bad1_nonocc) +
         ", \"bad2_all\": " + Num(m.bad2_all) + ", \"bad2_nonocc\": " + Num(m.bad2_nonocc) +
         ", \"rms_all\": " + Num(m.rms_all) + ", \"density\": " + Num(m.density) +
         ", \"ms\": " + Num(m.ms) + "}";
}

void Run(const Options& o) {
  const fs::path scene_dir = fs::path(o.left).parent_path();
  const std::string scene = scene_dir.filename().string();
  std::string gt_right = o.gt_right;
  if (gt_right.empty()) {
    // Middlebury layout: disp6.png (right view) beside disp2.png.
    const fs::path beside = fs::path(o.gt).parent_path() / "disp6.png";
    std::error_code ec;
    if (fs::path(o.gt).filename() == "disp2.png" && fs::is_regular_file(beside, ec)) gt_right = beside.string();
  }
  const stereo::DisparityGroundTruth gt = stereo::DisparityGroundTruth::Load(o.gt, gt_right, o.gt_scale);

  // romo: grey images (the vehicle's cameras are mono), default parameters.
  const cv::Mat left = ReadImage(o.left, cv::IMREAD_GRAYSCALE);
  const cv::Mat right = ReadImage(o.right, cv::IMREAD_GRAYSCALE);
  if (left.size() != right.size() || left.size() != gt.left_px.size()) {
    Fail("sizes differ: left '" + o.left + "' " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
         ", right " + std::to_string(right.cols) + "x" + std::to_string(right.rows) + ", ground truth " +
         std::to_string(gt.left_px.cols) + "x" + std::to_string(gt.left_px.rows));
  }
  stereo::SgmParameters params;
  params.gradient_refine_radius_px = o.refine_radius_px;
  stereo::StereoSgm sgm(left.cols, left.rows, o.ndisp, 8, 16, params);
  cv::Mat disparity;
  const auto t0 = std::chrono::steady_clock::now();
  sgm.execute(left, right, &disparity);
  const auto t1 = std::chrono::steady_clock::now();
  // Invalid pixels are compared as disparity min_disparity - 1 (-1 px), as OpenCV's test leaves them.
  const float invalid_px = static_cast<float>(sgm.parameters().min_disparity - 1);
  const cv::Mat romo_px =
      stereo::DisparityToFloat(disparity, sgm.subpixel_scale(), sgm.get_invalid_disparity(), invalid_px);
  const cv::Mat romo_valid = disparity != sgm.get_invalid_disparity();
  stereo::DisparityMetrics romo = stereo::EvaluateDisparity(romo_px, romo_valid, gt);
  romo.ms = std::chrono::duration<double, std::milli>(t1 - t0).count();

  // OpenCV: colour images and the scene's case as its regression test runs them.
  std::string xml = o.opencv_params;
  if (xml.empty()) xml = (scene_dir.parent_path() / "opencv_reference" / "stereosgbm_params.xml").string();
  stereo::OpenCvSgbmCase ocv_case;
  ocv_case.ndisp = o.ndisp;
  ocv_case.window = 3;
  if (const auto found = FindOpenCvCase(xml, scene)) ocv_case = *found;
  if (o.opencv_window > 0) ocv_case.window = o.opencv_window;
  const cv::Mat left_bgr = ReadImage(o.left, cv::IMREAD_COLOR);
  const cv::Mat right_bgr = ReadImage(o.right, cv::IMREAD_COLOR);
  stereo::DisparityMetrics ocv;
  const cv::Mat ocv_px = stereo::RunOpenCvReferenceSgbm(left_bgr, right_bgr, ocv_case, &ocv.ms);
  const double ms = ocv.ms;
  ocv = stereo::EvaluateDisparity(ocv_px, ocv_px >= 0.f, gt);
  ocv.ms = ms;

  if (o.json) {
    std::printf("{\"scene\": \"%s\", \"romo\": %s, \"opencv\": %s}\n", scene.c_str(), Json(romo).c_str(),
                Json(ocv).c_str());
  } else {
    std::printf("scene %s (%dx%d, romo ndisp %d; opencv ndisp %d window %d)\n", scene.c_str(), left.cols,
                left.rows, o.ndisp, ocv_case.ndisp, ocv_case.window);
    Print("romo", romo);
    Print("opencv", ocv);
  }
}

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<Options>();
  CLI::App& eval = CommandGroup(root, "eval", "Score romo's outputs against ground truth");
  CLI::App* cmd = eval.add_subcommand("stereo", "Disparity quality vs ground truth, romo and plain OpenCV SGBM");
  cmd->add_option("--left", opts->left, "left image (Middlebury im2.png)")->required();
  cmd->add_option("--right", opts->right, "right image (im6.png)")->required();
  cmd->add_option("--gt", opts->gt, "left ground-truth disparity PNG (disp2.png), 0 = unknown")->required();
  cmd->add_option("--gt-scale", opts->gt_scale, "disparity = PNG value / scale (Middlebury: 8, tsukuba 16)")
      ->required();
  cmd->add_option("--ndisp", opts->ndisp, "disparities searched by romo: multiple of 16 in [16, 256]")->required();
  cmd->add_option("--refine-radius", opts->refine_radius_px,
                  "romo's gradient subpixel refinement window radius, px (SgmParameters::gradient_refine_radius_px; 0 = off)")
      ->capture_default_str();
  cmd->add_option("--gt-right", opts->gt_right,
                  "right ground truth for the occlusion mask (default: disp6.png beside --gt if present)");
  cmd->add_option("--opencv-params", opts->opencv_params,
                  "OpenCV's stereosgbm_params.xml (default: ../opencv_reference/ beside the scene folder)");
  cmd->add_option("--opencv-window", opts->opencv_window, "override OpenCV's window size (default: from the xml, else 3)");
  cmd->add_flag("--json", opts->json, "print one JSON object");
  cmd->callback([opts] { Run(*opts); });
});

}  // namespace
}  // namespace romo::tools
