// `romo replay FILE.lcmlog --out DIR`: the whole vehicle pipeline over a recording.
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "cli/picture_options.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/pipeline/outputs.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/pipeline/run_loop.hpp"

namespace romo::tools {
namespace {

struct ReplayOptions {
  std::string log;
  std::string out_dir;
  std::string calib;
  std::string lcm_url;
  bool realtime = false;
  long long frames = 0;
  int threads = 2;
  pipeline::OutputOptions pictures;  ///< --no-pictures, --picture-span (the rest comes from the fields above)
  bool loop = false;
  double duration_s = 0.0;
};

void Replay(const ReplayOptions& o) {
  drivers::LogReader reader(o.log);
  drivers::Calibration calibration;
  if (!o.calib.empty()) {
    calibration = drivers::Calibration::Load(o.calib);
  } else if (reader.calibration() != nullptr) {
    calibration = *reader.calibration();
  } else {
    Fail("replay: recording " + o.log +
         " has no calibration (no ROMO_CALIBRATION event): pass one with --calib FILE");
  }
  pipeline::Pipeline pipe(calibration, pipeline::PipelineParams::ForCalibration(calibration, o.threads));
  pipeline::OutputOptions out = o.pictures;
  out.out_dir = o.out_dir;
  out.lcm_url = o.lcm_url;
  pipeline::OutputSink sink(calibration, out);
  Progress progress("replay", o.frames > 0 ? static_cast<std::uint64_t>(o.frames) : 0);
  pipeline::RunOptions run;
  run.realtime = o.realtime;
  run.max_frames = o.frames;
  run.duration_s = o.duration_s;
  if (o.loop && o.frames <= 0 && o.duration_s <= 0.0) {
    Fail("replay: --loop needs --duration SECONDS or --frames N to end");
  }
  pipeline::LoopedLog looped(reader);
  drivers::FrameSource& source = o.loop ? static_cast<drivers::FrameSource&>(looped) : reader;
  const auto stats = pipeline::RunFrames(
      source, pipe, sink, run, [&reader] { return reader.other_events(); },
      [&](std::int64_t done, const pipeline::FrameResult& r) {
        progress.Update(static_cast<std::uint64_t>(done),
                        std::to_string(r.obstacles.obstacles.size()) + " obstacles, " +
                            std::to_string(r.slots.slots.size()) + " slots");
      });
  progress.Finish();
  std::string extra = "\"source\": \"" + pipeline::JsonEscape(o.log) +
                      "\", \"skipped_out_of_order\": " + std::to_string(stats.skipped_out_of_order) +
                      ", \"wall_s\": " + std::to_string(stats.wall_s);
  if (o.loop) extra += ", \"loops\": " + std::to_string(looped.loops());
  if (reader.truncated()) {
    extra += ", \"log_truncated_at\": " + std::to_string(reader.truncation_offset());
    std::fprintf(stderr, "romo: replay: %s is truncated at byte %lld; replayed every complete frame\n",
                 o.log.c_str(), static_cast<long long>(reader.truncation_offset()));
  }
  sink.Finish(extra);
  if (stats.frames == 0) Fail("replay: " + o.log + " holds no frames");
  std::printf("replayed %lld frames in %.1f s (%.2f Hz)%s; outputs in %s\n",
              static_cast<long long>(stats.frames), stats.wall_s, stats.frames / std::max(stats.wall_s, 1e-9),
              stats.skipped_out_of_order ? " (out-of-order frames skipped: see summary.json)" : "",
              o.out_dir.c_str());
}

}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<ReplayOptions>();
  CLI::App* cmd = root.add_subcommand("replay", "Run the vehicle pipeline over a recording (LCM log)");
  cmd->add_option("log", opts->log, "recording (.lcmlog) with stereo frames")->required();
  cmd->add_option("--out", opts->out_dir, "output folder: outputs.lcmlog, predictions.csv, frames/, "
                                          "stage_*.png, summary.json")->required();
  cmd->add_option("--calib", opts->calib, "calibration file when the recording carries none");
  cmd->add_option("--lcm-url", opts->lcm_url, "also publish the outputs on this LCM URL (e.g. memq://)");
  cmd->add_flag("--realtime", opts->realtime, "pace frames by their stamps (default: as fast as possible)");
  cmd->add_option("--frames", opts->frames, "stop after this many frames (0 = all)")->capture_default_str();
  cmd->add_option("--threads", opts->threads, "stereo threads (rigs in parallel)")->capture_default_str();
  AddPictureOptions(*cmd, opts->pictures);
  cmd->add_flag("--loop", opts->loop, "start over at the end (stamps keep increasing); needs --duration or --frames");
  cmd->add_option("--duration", opts->duration_s, "stop after this many seconds of wall time (0 = no limit)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([opts] { Replay(*opts); });
});

}  // namespace romo::tools
