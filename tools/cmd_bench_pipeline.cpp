// `romo bench pipeline`: per-stage and end-to-end latency and rate of the 6-rig frame at full and
// half resolution with 1 and 2 threads, and each stage's share. Frames are rendered first (the
// simulator is not part of the measurement).
#include <cstdio>
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
  std::ostringstream js;
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
    for (int threads : {1, 2}) {
      pipeline::PipelineParams params;
      params.threads = threads;
      params.disparity_size = scale < 0.75 ? 64 : 128;
      pipeline::Pipeline pipe(*source.calibration(), params);
      std::map<std::string, double> sum;
      std::vector<std::string> order;
      double total = 0;
      for (std::size_t i = 0; i < frames.size(); ++i) {
        const auto r = pipe.Process(frames[i]);
        if (i == 0) continue;  // warm-up: allocations, first RANSAC
        for (const auto& st : r.status.stages) {
          if (!sum.count(st.name)) order.push_back(st.name);
          sum[st.name] += st.latency_ms;
        }
        total += r.status.total_latency_ms;
      }
      const double n = static_cast<double>(frames.size() - 1);
      std::printf("\n%s resolution (%dx%d), %d thread%s: end-to-end %.1f ms = %.2f Hz\n",
                  scale == 1.0 ? "full" : "half", source.calibration()->rigs[0].width_px,
                  source.calibration()->rigs[0].height_px, threads, threads > 1 ? "s" : "", total / n,
                  1000.0 * n / total);
      js << (first ? "" : ",") << "{\"scale\":" << scale << ",\"threads\":" << threads
         << ",\"total_ms\":" << total / n << ",\"hz\":" << 1000.0 * n / total << ",\"stages\":{";
      first = false;
      for (std::size_t k = 0; k < order.size(); ++k) {
        const double ms = sum[order[k]] / n;
        std::printf("  %-13s %8.1f ms  %5.1f %%\n", order[k].c_str(), ms, 100.0 * ms / (total / n));
        js << (k ? "," : "") << "\"" << order[k] << "\":" << ms;
      }
      js << "}}";
    }
  }
  js << "]}";
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
