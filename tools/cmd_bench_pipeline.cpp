// `romo bench pipeline`: per-stage and end-to-end latency and rate of the 6-rig frame at full and
// half resolution with 1 and 2 threads, and each stage's share. Frames are rendered first (the
// simulator is not part of the measurement). Two optional steps are also timed against their
// baseline, the same frames without them (2 threads): the stereo outline filter
// (max_disparity_spread) in the stereo stage, the de-noised heading in the boxes stage.
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::tools {
namespace {

struct BenchOptions {
  int frames = 3;
  bool json = false;
};

void Bench(const BenchOptions& o) {
  std::ostringstream js, baselines;
  js << "{\"cases\":[";
  bool first = true;
  for (double scale : {1.0, 0.5}) {
    sim::SimParams sp;
    sp.frames = o.frames + 1;
    sp.scale = scale;
    sp.render.threads = 2;
    sim::SimSource source(sp);
    std::vector<drivers::FrameSet> frames;
    while (auto f = source.Next()) frames.push_back(std::move(*f));
    auto params_for = [&](int threads) {
      return pipeline::PipelineParams::ForCalibration(*source.calibration(), threads);
    };
    const double n = static_cast<double>(frames.size() - 1);
    // Mean stage and end-to-end latencies over the frames after a warm-up (allocations, first RANSAC).
    auto measure = [&](const pipeline::PipelineParams& params, std::vector<std::string>* order, double* total) {
      pipeline::Pipeline pipe(*source.calibration(), params);
      std::map<std::string, double> sum;
      *total = 0;
      for (std::size_t i = 0; i < frames.size(); ++i) {
        const auto r = pipe.Process(frames[i]);
        if (i == 0) continue;
        for (const auto& st : r.status.stages) {
          if (!sum.count(st.name) && order) order->push_back(st.name);
          sum[st.name] += st.latency_ms / n;
        }
        *total += r.status.total_latency_ms / n;
      }
      return sum;
    };
    std::map<std::string, double> with_both;
    for (int threads : {1, 2}) {
      std::vector<std::string> order;
      double total = 0;
      std::map<std::string, double> sum = measure(params_for(threads), &order, &total);
      if (threads == 2) with_both = sum;
      std::printf("\n%s resolution (%dx%d), %d thread%s: end-to-end %.1f ms = %.2f Hz\n",
                  scale == 1.0 ? "full" : "half", source.calibration()->rigs[0].width_px,
                  source.calibration()->rigs[0].height_px, threads, threads > 1 ? "s" : "", total, 1000.0 / total);
      js << (first ? "" : ",") << "{\"scale\":" << scale << ",\"threads\":" << threads
         << ",\"total_ms\":" << total << ",\"hz\":" << 1000.0 / total << ",\"stages\":{";
      first = false;
      for (std::size_t k = 0; k < order.size(); ++k) {
        const double ms = sum[order[k]];
        std::printf("  %-13s %8.1f ms  %5.1f %%\n", order[k].c_str(), ms, 100.0 * ms / total);
        js << (k ? "," : "") << "\"" << order[k] << "\":" << ms;
      }
      js << "}}";
    }
    // Baselines: the same frames without each optional step.
    double unused = 0;
    pipeline::PipelineParams no_filter = params_for(2);
    no_filter.max_disparity_spread = 0.0;
    const double stereo_without = measure(no_filter, nullptr, &unused)["stereo"];
    pipeline::PipelineParams no_denoise = params_for(2);
    no_denoise.noise_dominated_fraction = std::numeric_limits<double>::infinity();
    const double boxes_without = measure(no_denoise, nullptr, &unused)["boxes"];
    pipeline::PipelineParams line_of_sight_only = params_for(2);
    line_of_sight_only.completion.face_max_thickness_m = 0.0;
    line_of_sight_only.tandem_min_length_m = 0.0;
    line_of_sight_only.framed_min_length_m = 0.0;
    const double classes_without = measure(line_of_sight_only, nullptr, &unused)["classes"];
    std::printf("  vs baselines (2 threads): stereo with the outline filter %.1f ms / %.1f ms without = %.3f; "
                "boxes with the de-noised heading %.1f ms / %.1f ms without = %.3f; classes with lone faces, "
                "tandem split and framed faces %.2f ms / %.2f ms without = %.3f\n",
                with_both["stereo"], stereo_without, with_both["stereo"] / stereo_without, with_both["boxes"],
                boxes_without, with_both["boxes"] / boxes_without, with_both["classes"], classes_without,
                with_both["classes"] / classes_without);
    baselines << (baselines.tellp() > 0 ? "," : "") << "{\"scale\":" << scale
              << ",\"stereo_outline_filter_ratio\":" << with_both["stereo"] / stereo_without
              << ",\"boxes_denoised_heading_ratio\":" << with_both["boxes"] / boxes_without
              << ",\"classes_extra_readings_ratio\":" << with_both["classes"] / classes_without << "}";
  }
  js << "],\"baselines\":[" << baselines.str() << "]}";
  if (o.json) std::printf("%s\n", js.str().c_str());
}

}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<BenchOptions>();
  CLI::App& bench = CommandGroup(root, "bench", "Benchmarks (ratios against named baselines)");
  CLI::App* cmd = bench.add_subcommand("pipeline", "Per-stage and end-to-end latency of the 6-rig frame");
  cmd->add_option("--frames", opts->frames, "frames measured per case (after one warm-up)")->capture_default_str();
  cmd->add_flag("--json", opts->json, "also print one JSON object");
  cmd->callback([opts] { Bench(*opts); });
});

}  // namespace romo::tools
