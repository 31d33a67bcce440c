// `romo sim`: renders the simulated parking scene into a recording (calibration first, then per
// frame the frame set and the ground truth on its own channels). Also makes sim:// available to
// every other command (romo run / replay / gige-serve can read sim://parking?... directly).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::tools {
namespace {

struct Options {
  sim::SimParams sim;
  std::string out;
  bool png = false;
  bool no_distortion = false;
};

void Run(Options o) {
  o.sim.distortion = !o.no_distortion;
  o.sim.Validate();
  if (o.out.empty()) Fail("romo sim: --out FILE.lcmlog is required");
  const auto start = std::chrono::steady_clock::now();
  sim::SimSource source(o.sim);
  drivers::LogWriter writer(o.out, o.png ? drivers::ImageEncoding::kPng : drivers::ImageEncoding::kRaw);
  if (!writer.kept_interrupted().empty()) {
    std::fprintf(stderr, "romo sim: an interrupted recording was kept as %s\n", writer.kept_interrupted().c_str());
  }
  const std::int64_t first_stamp = source.TruthAt(static_cast<std::uint64_t>(o.sim.first_frame)).stamp_ns;
  writer.WriteCalibration(*source.calibration(), first_stamp);
  Progress progress("sim " + o.sim.scene, static_cast<std::uint64_t>(o.sim.frames));
  std::uint64_t done = 0;
  while (auto frames = source.Next()) {
    writer.Write(*frames);
    const auto truth = sim::Encode(source.ground_truth());
    writer.WriteRaw(sim::kGroundTruthChannel, frames->stamp_ns, truth.data(), truth.size());
    for (const sim::GtDepth& depth : source.depth()) {
      const auto bytes = sim::Encode(depth);
      writer.WriteRaw(sim::DepthChannel(depth.rig_id), frames->stamp_ns, bytes.data(), bytes.size());
    }
    progress.Update(++done, source.ground_truth().ego_phase);
  }
  writer.Close();
  progress.Finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s: %llu frames of %zu rigs, %llu events, %.1f MB in %.1f s (seed %llu)\n",
              writer.path().c_str(), static_cast<unsigned long long>(done),
              source.calibration()->rigs.size(),
              static_cast<unsigned long long>(writer.events_written()),
              writer.bytes_written() / 1e6, seconds, static_cast<unsigned long long>(o.sim.seed));
}

void Register(CLI::App& root) {
  auto o = std::make_shared<Options>();
  o->sim.render.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  auto* cmd = root.add_subcommand(
      "sim", "Render the simulated 360-degree parking scene (6 stereo rigs) with ground truth into "
             "a recording; same seed, same bytes, for any --threads");
  cmd->add_option("--scene", o->sim.scene, "Scene name (parking)");
  cmd->add_option("--seed", o->sim.seed, "Scene and noise seed");
  cmd->add_option("--frames", o->sim.frames, "Frames to render (> 0; 150 = the whole maneuver)");
  cmd->add_option("--first", o->sim.first_frame, "Index of the first frame (>= 0)");
  cmd->add_option("--out", o->out, "Output recording (.lcmlog)")->required();
  cmd->add_option("--threads", o->sim.render.threads, "Render threads (output is identical for any)");
  cmd->add_option("--scale", o->sim.scale, "Image scale (0, 4]; the calibration is scaled to match");
  cmd->add_option("--rate", o->sim.rate_hz, "Frame rate in Hz (default 10)");
  cmd->add_option("--aa", o->sim.render.samples_per_axis, "Anti-aliasing rays per pixel axis (1-4)");
  cmd->add_option("--noise", o->sim.render.noise_sigma, "Sensor noise sigma in grey levels");
  cmd->add_option("--calib", o->sim.calibration_path, "Calibration (default: the sample RoMo calibration)");
  cmd->add_flag("--depth", o->sim.depth, "Also record per-pixel depth and object ids (ROMO_GT_DEPTH_RIG<k>)");
  cmd->add_flag("--no-distortion", o->no_distortion, "Render (and record) cameras without lens distortion");
  cmd->add_flag("--png", o->png, "Store images PNG-compressed");
  cmd->callback([o] { Run(*o); });
}

ROMO_REGISTER_COMMAND(Register);

// sim:// is usable from every command of this executable.
const bool kSimRegistered = (sim::RegisterSimSource(), true);

}  // namespace
}  // namespace romo::tools
