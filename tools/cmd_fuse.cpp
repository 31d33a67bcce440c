// `romo fuse --lcm-url URL`: mapping, objects and planning on the rig clouds that stereo workers
// publish. Frames are assembled by stamp; a rig that has not arrived within --timeout-ms is
// reported missing (sector not covered) and the frame goes on without it. Malformed messages
// are counted and reported, never fatal.
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/check.hpp"
#include "romo/pipeline/outputs.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/planning_iface/lcm_bus.hpp"
#include "romo/planning_iface/messages.hpp"

namespace romo::tools {
namespace {

struct FuseOptions {
  std::string lcm_url;
  std::string calib;
  std::string out_dir;
  int timeout_ms = 500;
  double idle_exit_s = 10.0;
  long long frames = 0;
  // A full-resolution rig cloud (782 x 582 points at 8 bytes) is 3.6 MB; anything far larger is
  // refused before decoding so a bad or hostile sender cannot make fuse allocate without bound.
  std::size_t max_message_bytes = 8u << 20;
};

void Fuse(const FuseOptions& o) {
  using Clock = std::chrono::steady_clock;
  const drivers::Calibration calibration =
      drivers::Calibration::Load(o.calib.empty() ? drivers::SampleCalibrationPath() : o.calib);
  pipeline::PipelineParams params;
  pipeline::Pipeline pipe(calibration, params);
  pipeline::OutputOptions out;
  out.out_dir = o.out_dir;
  out.lcm_url = o.lcm_url;
  out.log_inputs = false;
  pipeline::OutputSink sink(calibration, out);

  struct Pending {
    Clock::time_point first_arrival;
    std::int64_t sequence = 0;
    std::map<int, pipeline::RigInput> rigs;
    std::optional<drivers::VehicleState> vehicle;
  };
  std::map<std::int64_t, Pending> pending;  // by stamp
  std::int64_t last_done_stamp = -1;
  long long processed = 0, late = 0;
  auto last_message = Clock::now();

  planning_iface::LcmBus bus(o.lcm_url);
  bus.Subscribe(std::string(planning_iface::kRigCloudChannelPrefix) + "[0-9]+",
                [&](const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t) {
                  last_message = Clock::now();
                  if (size > o.max_message_bytes) {
                    pipe.CountMalformed();
                    pipe.ReportEvent("oversized message on " + channel + ": " + std::to_string(size) +
                                     " bytes > --max-message-bytes " + std::to_string(o.max_message_bytes) +
                                     "; dropped undecoded");
                    return;
                  }
                  std::string why;
                  auto rc = planning_iface::DecodeRigCloud(data, size, &why);
                  if (!rc || channel != planning_iface::RigCloudChannel(rc->rig_id)) {
                    pipe.CountMalformed();
                    pipe.ReportEvent("malformed message on " + channel + ": " +
                                     (why.empty() ? "rig id does not match the channel" : why));
                    return;
                  }
                  bool known = false;
                  for (const auto& r : calibration.rigs) known = known || r.rig_id == rc->rig_id;
                  if (!known) {
                    pipe.CountMalformed();
                    pipe.ReportEvent("cloud of rig " + std::to_string(rc->rig_id) + " not in the calibration");
                    return;
                  }
                  if (rc->stamp_ns <= last_done_stamp) {
                    ++late;  // its frame was already processed without it
                    pipe.CountDropped(rc->rig_id);
                    return;
                  }
                  Pending& p = pending[rc->stamp_ns];
                  if (p.rigs.empty()) p.first_arrival = Clock::now();
                  p.sequence = rc->frame_sequence;
                  if (rc->vehicle) p.vehicle = rc->vehicle;
                  pipeline::RigInput in;
                  in.rig_id = rc->rig_id;
                  in.stamp_ns = rc->stamp_ns;
                  in.cloud = std::move(rc->cloud);
                  in.stereo_ms = rc->stereo_ms;
                  p.rigs[in.rig_id] = std::move(in);
                });

  auto process = [&](std::map<std::int64_t, Pending>::iterator it) {
    std::vector<pipeline::RigInput> rigs;
    for (auto& [id, in] : it->second.rigs) rigs.push_back(std::move(in));
    const auto result = pipe.ProcessClouds(it->first, it->second.sequence, rigs, it->second.vehicle, std::nullopt);
    sink.Write(nullptr, result, {});
    last_done_stamp = it->first;
    ++processed;
    pending.erase(pending.begin(), std::next(it));
  };

  const std::size_t all = calibration.rigs.size();
  // Subscribed from here on: a sender (or test) may start once this line is out.
  std::fprintf(stderr, "romo fuse: listening on %s for %zu rigs\n", o.lcm_url.c_str(), all);
  std::fflush(stderr);
  while (o.frames <= 0 || processed < o.frames) {
    bus.Handle(20);
    // Oldest first: complete frames at once, incomplete ones after the timeout or when a newer
    // frame is already complete (its rigs will not come back for the old stamp).
    while (!pending.empty()) {
      auto it = pending.begin();
      const bool complete = it->second.rigs.size() >= all;
      const bool timed_out = Clock::now() - it->second.first_arrival > std::chrono::milliseconds(o.timeout_ms);
      bool newer_complete = false;
      for (auto jt = std::next(it); jt != pending.end(); ++jt) newer_complete |= jt->second.rigs.size() >= all;
      if (!(complete || timed_out || newer_complete)) break;
      process(it);
    }
    if (Clock::now() - last_message > std::chrono::duration<double>(o.idle_exit_s)) break;
  }
  while (!pending.empty() && (o.frames <= 0 || processed < o.frames)) process(pending.begin());
  sink.Finish("\"late_clouds\": " + std::to_string(late));
  std::fprintf(stderr, "romo fuse: %lld frames processed, %lld late clouds\n", processed, late);
}

}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<FuseOptions>();
  CLI::App* cmd = root.add_subcommand("fuse", "Mapping, objects and planning on the clouds of romo stereo-workers");
  cmd->add_option("--lcm-url", opts->lcm_url, "LCM URL the workers publish on")->required();
  cmd->add_option("--calib", opts->calib, "calibration (default: the sample RoMo calibration)");
  cmd->add_option("--out", opts->out_dir, "also write outputs like romo replay");
  cmd->add_option("--timeout-ms", opts->timeout_ms, "wait this long for a frame's missing rigs")->capture_default_str();
  cmd->add_option("--idle-exit", opts->idle_exit_s, "exit after this many seconds without messages")->capture_default_str();
  cmd->add_option("--frames", opts->frames, "exit after this many frames (0 = until idle)");
  cmd->add_option("--max-message-bytes", opts->max_message_bytes,
                  "refuse (count as malformed) rig clouds larger than this")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->callback([opts] { Fuse(*opts); });
});

}  // namespace romo::tools
