// `romo bench stereo`: ms per 782x582 pair at 128 disparities on one core and on all cores,
// romo's StereoSgm against plain OpenCV StereoSGBM (MODE_SGBM, MODE_SGBM_3WAY) in the same run,
// the wrapper's overhead ratio, romo's defaults, and a whole 6-rig frame set.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/core/statistics.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/stereo/multi_rig.hpp"
#include "romo/stereo/sgm.hpp"
#include "romo/stereo/synthetic.hpp"

namespace romo::tools {
namespace {

struct Options {
  int width = 782, height = 582, ndisp = 128, repeat = 7, block = 5;
  std::string kitti_dir;  // use a real KITTI pair resized instead of the synthetic one
  std::string calib;
  bool json = false;
};

double TimeMs(const std::function<void()>& run) {
  const auto t0 = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double MedianMs(const std::function<void()>& run, int repeat) {
  run();  // warm-up: allocations, caches
  std::vector<double> ms;
  for (int i = 0; i < repeat; ++i) ms.push_back(TimeMs(run));
  return Median(ms);
}

// Baseline and candidate run alternately so load changes on a shared machine hit both alike; the
// ratio is the median of the per-round ratios.
struct Paired {
  double base_ms, candidate_ms, ratio;
};
Paired MeasurePaired(const std::function<void()>& base, const std::function<void()>& candidate, int repeat) {
  base();
  candidate();
  std::vector<double> b, c, r;
  for (int i = 0; i < repeat; ++i) {
    b.push_back(TimeMs(base));
    c.push_back(TimeMs(candidate));
    r.push_back(c.back() / b.back());
  }
  return {Median(b), Median(c), Median(r)};
}

struct Row {
  std::string name;
  int threads;
  double ms;
};

void Run(const Options& o) {
  if (o.repeat < 1) Fail("--repeat " + std::to_string(o.repeat) + " must be >= 1");
  cv::Mat left, right;
  std::string source;
  if (!o.kitti_dir.empty()) {
    const cv::Mat l = cv::imread(o.kitti_dir + "/left.png", cv::IMREAD_GRAYSCALE);
    const cv::Mat r = cv::imread(o.kitti_dir + "/right.png", cv::IMREAD_GRAYSCALE);
    if (l.empty() || r.empty()) Fail("no left.png/right.png in '" + o.kitti_dir + "'");
    cv::resize(l, left, cv::Size(o.width, o.height), 0, 0, cv::INTER_AREA);
    cv::resize(r, right, cv::Size(o.width, o.height), 0, 0, cv::INTER_AREA);
    source = "KITTI pair resized";
  } else {
    // A ground-like tilted plane: disparities from ~67 px at the top to ~100 px at the bottom.
    stereo::RectifiedGeometry g;
    g.focal_px = 400.0;
    g.baseline_m = 0.25;
    g.cx_px = (o.width - 1) / 2.0;
    g.cy_px = (o.height - 1) / 2.0;
    const stereo::SyntheticPair pair =
        stereo::RenderPlanePair(g, o.width, o.height, Eigen::Vector3d(0.0, 0.26, 0.97), 1.16, 7);
    left = pair.left;
    right = pair.right;
    source = "synthetic textured plane";
  }
  const int all = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int w = o.block;
  // The same parameters for OpenCV and romo's wrapper (post-processing off): the difference is
  // the wrapper's own cost.
  stereo::SgmParameters same;
  same.block_size = w;
  same.p1 = 8 * w * w;
  same.p2 = 32 * w * w;
  same.uniqueness = 1.0f / 1.10f;  // OpenCV uniquenessRatio 10
  same.lr_max_diff_px = 1;
  same.speckle_window_px = 100;
  same.speckle_range_px = 2;
  same.post_filter = stereo::PostFilter::kNone;

  std::vector<Row> rows;
  std::vector<std::pair<std::string, double>> ratios;
  const int steps = 2 * 5 + 2;
  Progress progress("bench stereo", steps);
  int done = 0;
  cv::Mat out;
  for (int threads : {1, all}) {
    cv::setNumThreads(threads);
    for (const auto& [mode_name, mode, paths] :
         {std::tuple<const char*, int, stereo::PathCount>{"SGBM", cv::StereoSGBM::MODE_SGBM, stereo::PathCount::k5},
          std::tuple<const char*, int, stereo::PathCount>{"SGBM_3WAY", cv::StereoSGBM::MODE_SGBM_3WAY,
                                                          stereo::PathCount::k3}}) {
      cv::Ptr<cv::StereoSGBM> ocv = cv::StereoSGBM::create(0, o.ndisp, w, same.p1, same.p2, 1, same.pre_filter_cap,
                                                           10, same.speckle_window_px, same.speckle_range_px, mode);
      stereo::SgmParameters p = same;
      p.path_count = paths;
      stereo::StereoSgm romo(o.width, o.height, o.ndisp, 8, 16, p);
      const Paired m = MeasurePaired([&] { ocv->compute(left, right, out); },
                                     [&] { romo.execute(left, right, &out); }, o.repeat);
      done += 2;
      progress.Update(done);
      rows.push_back({std::string("opencv ") + mode_name, threads, m.base_ms});
      rows.push_back({std::string("romo wrapper ") + mode_name, threads, m.candidate_ms});
      ratios.emplace_back(std::string(mode_name) + " " + std::to_string(threads) + "T", m.ratio);
    }
    stereo::StereoSgm defaults(o.width, o.height, o.ndisp, 8, 16);
    rows.push_back({"romo defaults (3 paths, block 1)", threads,
                    MedianMs([&] { defaults.execute(left, right, &out); }, o.repeat)});
    progress.Update(++done);
  }

  // A whole frame set: the sample calibration's 6 rigs, raw images (rectification included).
  const drivers::Calibration calibration =
      drivers::Calibration::Load(o.calib.empty() ? drivers::SampleCalibrationPath() : o.calib);
  drivers::FrameSet frames;
  for (const auto& rig : calibration.rigs) {
    if (rig.width_px != o.width || rig.height_px != o.height) {
      Fail("rig " + std::to_string(rig.rig_id) + " is " + std::to_string(rig.width_px) + "x" +
           std::to_string(rig.height_px) + "; the 6-rig bench needs --width/--height to match");
    }
    drivers::StereoFrame f;
    f.rig_id = rig.rig_id;
    for (auto [img, cam] : {std::pair{&left, &f.left}, std::pair{&right, &f.right}}) {
      cam->image = drivers::Image::Allocate(drivers::PixelFormat::kMono8, o.width, o.height);
      std::copy(img->datastart, img->dataend, cam->image.data.begin());
    }
    frames.stereo.push_back(std::move(f));
  }
  stereo::StereoParams params;
  params.disparity_size = o.ndisp;
  for (int threads : {1, all}) {
    cv::setNumThreads(threads);
    stereo::MultiRigStereo multi(calibration, params, threads);
    rows.push_back({"romo 6-rig frame set (defaults, pool of " + std::to_string(threads) + ")", threads,
                    MedianMs([&] { multi.Process(frames); }, std::max(1, o.repeat / 2))});
    progress.Update(++done);
  }
  progress.Finish();
  cv::setNumThreads(-1);

  if (o.json) {
    std::printf("{\"width\": %d, \"height\": %d, \"ndisp\": %d, \"block\": %d, \"cores\": %d, \"rows\": [", o.width,
                o.height, o.ndisp, w, all);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      std::printf("%s{\"name\": \"%s\", \"threads\": %d, \"ms\": %.3f}", i ? ", " : "", rows[i].name.c_str(),
                  rows[i].threads, rows[i].ms);
    }
    std::printf("], \"wrapper_ratio\": {");
    for (std::size_t i = 0; i < ratios.size(); ++i) {
      std::printf("%s\"%s\": %.4f", i ? ", " : "", ratios[i].first.c_str(), ratios[i].second);
    }
    std::printf("}}\n");
    return;
  }
  std::printf("%dx%d %s, %d disparities, block %d, median of %d runs, %d cores\n", o.width, o.height,
              source.c_str(), o.ndisp, w, o.repeat, all);
  for (const Row& r : rows) std::printf("  %-52s %2d thread(s) %8.1f ms\n", r.name.c_str(), r.threads, r.ms);
  std::printf("wrapper overhead (romo / opencv, same parameters; must be < 1.05):\n");
  for (const auto& [name, ratio] : ratios) std::printf("  %-16s %.3f\n", name.c_str(), ratio);
}

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<Options>();
  CLI::App& bench = CommandGroup(root, "bench", "Benchmarks (ratios against a named baseline in the same run)");
  CLI::App* cmd = bench.add_subcommand("stereo", "SGM ms per pair vs plain OpenCV StereoSGBM, and a 6-rig frame");
  cmd->add_option("--width", opts->width, "image width")->capture_default_str();
  cmd->add_option("--height", opts->height, "image height")->capture_default_str();
  cmd->add_option("--ndisp", opts->ndisp, "disparities (multiple of 16)")->capture_default_str();
  cmd->add_option("--block", opts->block, "block size for the OpenCV-vs-wrapper rows")->capture_default_str();
  cmd->add_option("--repeat", opts->repeat, "timed runs per row (medians reported; OpenCV and romo alternate)")->capture_default_str();
  cmd->add_option("--kitti", opts->kitti_dir, "folder with a KITTI left.png/right.png to resize instead");
  cmd->add_option("--calib", opts->calib, "calibration for the 6-rig row (default: the sample)");
  cmd->add_flag("--json", opts->json, "print one JSON object");
  cmd->callback([opts] { Run(*opts); });
});

}  // namespace
}  // namespace romo::tools
