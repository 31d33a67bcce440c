// `romo run`: the embedded default (DESIGN.md): the simulated parking scene through the whole
// pipeline, outputs on LCM and written like `romo replay`, and a report against the truth.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "cli/picture_options.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/pipeline/outputs.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/pipeline/run_loop.hpp"
#include "romo/pipeline/scene_eval.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::tools {
namespace {

struct RunCmdOptions {
  std::string source;
  long long seed = 1;
  long long frames = 40;
  double scale = 0.5;
  double rate_hz = 2.7;
  std::string out_dir = "out/run";
  std::string lcm_url = "memq://";
  bool realtime = false;
  int threads = 2;
  pipeline::OutputOptions pictures;  ///< --no-pictures, --picture-span (the rest comes from the fields above)
};

void RunDefault(const RunCmdOptions& o) {
  sim::RegisterSimSource();
  std::string uri = o.source;
  if (uri.empty()) {
    // The whole maneuver (approach, turn, sideways entry: 15 s) in o.frames frames.
    std::ostringstream u;
    u << "sim://parking?seed=" << o.seed << "&frames=" << o.frames << "&scale=" << o.scale
      << "&rate_hz=" << o.rate_hz << "&threads=" << o.threads;
    uri = u.str();
  }
  std::unique_ptr<drivers::FrameSource> source = drivers::OpenSource(uri);
  if (source->calibration() == nullptr) Fail("run: source " + uri + " has no calibration");
  const drivers::Calibration calibration = *source->calibration();
  auto* sim_source = dynamic_cast<sim::SimSource*>(source.get());

  pipeline::Pipeline pipe(calibration, pipeline::PipelineParams::ForCalibration(calibration, o.threads));
  pipeline::OutputOptions out = o.pictures;
  out.out_dir = o.out_dir;
  out.lcm_url = o.lcm_url;
  pipeline::OutputSink sink(calibration, out);

  std::fprintf(stderr, "romo run: %s -> %s (LCM %s)\n", uri.c_str(), o.out_dir.c_str(),
               o.lcm_url.empty() ? "off" : o.lcm_url.c_str());
  Progress progress("run", static_cast<std::uint64_t>(o.frames));
  pipeline::RunOptions run;
  run.realtime = o.realtime;
  auto passthrough = [sim_source]() {
    std::vector<drivers::LogEvent> events;
    if (sim_source != nullptr) {
      const sim::GroundTruth& gt = sim_source->ground_truth();
      drivers::LogEvent e;
      e.timestamp_us = gt.stamp_ns / 1000;
      e.channel = sim::kGroundTruthChannel;
      e.data = sim::Encode(gt);
      events.push_back(std::move(e));
    }
    return events;
  };
  const auto stats = pipeline::RunFrames(*source, pipe, sink, run, passthrough,
                                         [&](std::int64_t done, const pipeline::FrameResult& r) {
                                           progress.Update(static_cast<std::uint64_t>(done),
                                                           std::string("stage ") +
                                                               planning_iface::ToString(r.slots.stage));
                                         });
  progress.Finish();
  sink.Finish("\"source\": \"" + pipeline::JsonEscape(uri) + "\", \"wall_s\": " + std::to_string(stats.wall_s));
  std::printf("romo run: %lld frames in %.1f s (%.2f Hz); outputs in %s\n", static_cast<long long>(stats.frames),
              stats.wall_s, stats.frames / std::max(stats.wall_s, 1e-9), o.out_dir.c_str());
  if (sim_source != nullptr && !o.out_dir.empty()) {
    const pipeline::SceneEval e = pipeline::EvaluateSceneLog(sink.log_path());
    std::printf("\nAgainst the scene's ground truth:\n%s", e.ToText().c_str());
    std::ofstream(o.out_dir + "/eval.json") << e.ToJson() << "\n";
  }
}

}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<RunCmdOptions>();
  CLI::App* cmd = root.add_subcommand(
      "run", "The whole vehicle pipeline; without arguments on the built-in simulated parking scene");
  cmd->add_option("--source", opts->source, "frame source URI instead of the simulated scene "
                                            "(gige://rigs.yaml, log://file.lcmlog, sim://...)");
  cmd->add_option("--seed", opts->seed, "scene seed")->capture_default_str();
  cmd->add_option("--frames", opts->frames, "frames to run")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--scale", opts->scale, "image scale (1 = 782x582)")->capture_default_str();
  cmd->add_option("--rate-hz", opts->rate_hz, "frame rate of the simulated cameras")->capture_default_str();
  cmd->add_option("--out", opts->out_dir, "output folder (like romo replay)")->capture_default_str();
  cmd->add_option("--lcm-url", opts->lcm_url, "publish outputs here (\"\" = off)")->capture_default_str();
  cmd->add_flag("--realtime", opts->realtime, "pace frames by their stamps");
  cmd->add_option("--threads", opts->threads, "threads for rendering and stereo")->capture_default_str();
  AddPictureOptions(*cmd, opts->pictures);
  cmd->callback([opts] { RunDefault(*opts); });
});

}  // namespace romo::tools
