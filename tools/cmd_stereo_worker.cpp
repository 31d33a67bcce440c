// `romo stereo-worker --rig K --source URI --lcm-url URL`: one rig's stereo in its own process,
// publishing the rig's cloud (compact int16 mm encoding) on ROMO_RIG_CLOUD<K> for `romo fuse`, and
// with --publish-gnss the source's GNSS fixes on ROMO_GNSS (replaying a recording over workers; on
// the vehicle the GNSS receiver's driver publishes them).
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/planning_iface/lcm_bus.hpp"
#include "romo/planning_iface/messages.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::tools {
namespace {

struct WorkerOptions {
  int rig = 0;
  std::string source;
  std::string lcm_url;
  long long frames = 0;
  bool publish_gnss = false;
};

void Work(const WorkerOptions& o) {
  sim::RegisterSimSource();
  auto source = drivers::OpenSource(o.source);
  if (source->calibration() == nullptr) Fail("stereo-worker: source " + o.source + " has no calibration");
  const drivers::Calibration calibration = *source->calibration();
  calibration.rig(o.rig);  // names the rig when it is not in the calibration
  // One rig per process: the vehicle network spreads the rigs over cores.
  pipeline::PipelineParams params = pipeline::PipelineParams::ForCalibration(calibration, 1);
  pipeline::Pipeline pipe(calibration, params);
  planning_iface::LcmBus bus(o.lcm_url);
  long long sent = 0, missing = 0;
  while (o.frames <= 0 || sent + missing < o.frames) {
    auto frames = source->Next();
    if (!frames) break;
    // Before the cloud, so the fix is in when fuse completes the frame.
    if (o.publish_gnss && frames->gnss) bus.Publish(drivers::kGnssChannel, drivers::EncodeGnssMessage(*frames->gnss));
    const drivers::StereoFrame* mine = nullptr;
    for (const auto& st : frames->stereo) {
      if (st.rig_id == o.rig) mine = &st;
    }
    if (mine == nullptr) {
      ++missing;  // the fuse process reports the sector missing after its timeout
      continue;
    }
    auto in = pipe.Stereo(*mine);
    if (!in) {
      ++missing;
      continue;
    }
    planning_iface::RigCloud rc;
    rc.stamp_ns = frames->stamp_ns;
    rc.frame_sequence = static_cast<std::int64_t>(frames->sequence);
    rc.capture_stamp_ns = in->stamp_ns;
    rc.rig_id = o.rig;
    rc.cloud = std::move(in->cloud);
    rc.stereo_ms = in->stereo_ms;
    rc.vehicle = frames->vehicle;
    rc.image_width_px = calibration.rig(o.rig).width_px;  // fuse takes its defaults for this size
    bus.Publish(planning_iface::RigCloudChannel(o.rig), planning_iface::Encode(rc));
    ++sent;
  }
  std::fprintf(stderr, "romo stereo-worker rig %d: %lld clouds published, %lld frames without the rig\n", o.rig,
               sent, missing);
}

}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<WorkerOptions>();
  CLI::App* cmd = root.add_subcommand("stereo-worker", "One rig's stereo, publishing its cloud on LCM for romo fuse");
  cmd->add_option("--rig", opts->rig, "rig id (0 front .. 5 right_front)")->required();
  cmd->add_option("--source", opts->source, "frame source URI (sim://..., log://..., gige://...)")->required();
  cmd->add_option("--lcm-url", opts->lcm_url, "LCM URL (udpm://... inside netns-run, memq:// in-process)")
      ->required();
  cmd->add_option("--frames", opts->frames, "stop after this many frames (0 = until the source ends)");
  cmd->add_flag("--publish-gnss", opts->publish_gnss, "also publish the source's GNSS fixes on ROMO_GNSS");
  cmd->callback([opts] { Work(*opts); });
});

}  // namespace romo::tools
