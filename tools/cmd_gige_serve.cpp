// `romo gige-serve`: a recording's cameras served as emulated GigE Vision cameras (one address
// each) so the real acquisition path (gige://) can run against recorded frames.
#include <arpa/inet.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/gige.hpp"
#include "romo/drivers/recording.hpp"

namespace romo::tools {
namespace {

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

struct Options {
  std::string log;
  double rate_hz = 0.0;
  bool loop = false;
  std::string base_address = "127.0.0.2";
  std::string rig_config_out;
  int max_frames = 300;
  double duration_s = 0.0;
};

std::string AddressPlus(const std::string& base, std::uint32_t offset) {
  in_addr addr{};
  if (inet_pton(AF_INET, base.c_str(), &addr) != 1) {
    Fail("--base-address '" + base + "' is not an IPv4 address");
  }
  addr.s_addr = htonl(ntohl(addr.s_addr) + offset);
  char text[INET_ADDRSTRLEN];
  inet_ntop(AF_INET, &addr, text, sizeof text);
  return text;
}

struct RecordedRig {
  std::vector<drivers::Image> left;
  std::vector<drivers::Image> right;
};

void Serve(const Options& options) {
  namespace fs = std::filesystem;
  drivers::LogReader reader(options.log);
  std::map<int, RecordedRig> rigs;
  std::vector<std::int64_t> stamps;
  bool capped = false;
  while (auto frames = reader.Next()) {
    if (frames->stereo.empty()) continue;
    if (static_cast<int>(stamps.size()) >= options.max_frames) {
      capped = true;
      break;
    }
    stamps.push_back(frames->stamp_ns);
    for (auto& stereo : frames->stereo) {
      rigs[stereo.rig_id].left.push_back(std::move(stereo.left.image));
      rigs[stereo.rig_id].right.push_back(std::move(stereo.right.image));
    }
  }
  if (rigs.empty()) Fail(options.log + ": no stereo frames (ROMO_STEREO_RIG<k> channels) to serve");
  if (capped) {
    std::fprintf(stderr, "gige-serve: serving the first %d frame sets of %s (--max-frames)\n",
                 options.max_frames, options.log.c_str());
  }
  double rate_hz = options.rate_hz;
  if (rate_hz <= 0.0) {
    // The recording's own rate: median spacing of its frame sets.
    std::vector<std::int64_t> steps;
    for (std::size_t i = 1; i < stamps.size(); ++i) {
      if (stamps[i] > stamps[i - 1]) steps.push_back(stamps[i] - stamps[i - 1]);
    }
    if (steps.empty()) Fail(options.log + ": cannot tell the recording's frame rate: give --rate HZ");
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    rate_hz = 1e9 / static_cast<double>(steps[steps.size() / 2]);
  }

  drivers::GigeConfig config;
  std::string calibration_path;
  if (!options.rig_config_out.empty() && reader.calibration()) {
    calibration_path = options.rig_config_out + ".calibration.yaml";
    reader.calibration()->Save(calibration_path);
  }
  std::vector<drivers::GigeEmulator::Camera> cameras;
  std::uint32_t offset = 0;
  for (auto& [rig_id, recorded] : rigs) {
    drivers::GigeRigConfig rig;
    rig.rig_id = rig_id;
    rig.pixel_format = drivers::ServedFormat(recorded.left.front().format);
    rig.frame_rate_hz = rate_hz;
    rig.pairing_tolerance_ms = std::min(5.0, 250.0 / rate_hz);  // served stamps are identical
    if (!calibration_path.empty()) {
      for (const auto& calib : reader.calibration()->rigs) {
        if (calib.rig_id == rig_id) rig.calibration_path = fs::absolute(calibration_path).string();
      }
    }
    for (bool is_left : {true, false}) {
      drivers::GigeEmulator::Camera camera;
      camera.address = AddressPlus(options.base_address, offset++);
      camera.serial = "romo-r" + std::to_string(rig_id) + (is_left ? "-l" : "-r");
      camera.frames = std::move(is_left ? recorded.left : recorded.right);
      (is_left ? rig.left : rig.right).address = camera.address;
      std::printf("serving rig %d %s as %s at %s: %d frames %dx%d %s\n", rig_id,
                  is_left ? "left " : "right", camera.serial.c_str(), camera.address.c_str(),
                  static_cast<int>(camera.frames.size()), camera.frames.front().width,
                  camera.frames.front().height, drivers::ToString(rig.pixel_format));
      cameras.push_back(std::move(camera));
    }
    config.rigs.push_back(rig);
  }
  std::printf("rate %.3f Hz%s\n", rate_hz, options.loop ? ", looping" : "");
  std::fflush(stdout);

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  drivers::GigeEmulator emulator(std::move(cameras), rate_hz, options.loop);
  // Written only once the cameras answer, so a client waiting for the file can connect at once.
  if (!options.rig_config_out.empty()) config.Save(options.rig_config_out);

  const std::uint64_t total = options.loop ? 0 : stamps.size();
  Progress progress("gige-serve", total);
  const auto start = std::chrono::steady_clock::now();
  while (!g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto served = emulator.frames_served();
    const std::uint64_t least = *std::min_element(served.begin(), served.end());
    progress.Update(std::min<std::uint64_t>(least, total ? total : least),
                    std::to_string(served.size()) + " cameras");
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (options.duration_s > 0.0 && elapsed >= options.duration_s) break;
    if (emulator.finished()) {
      // Let the last frame leave before the cameras go away.
      std::this_thread::sleep_for(std::chrono::duration<double>(1.0 / rate_hz));
      break;
    }
  }
  progress.Finish(g_stop ? "stopped" : "done");
}

void Register(CLI::App& root) {
  auto options = std::make_shared<Options>();
  auto* command = root.add_subcommand(
      "gige-serve",
      "Serve a recording's cameras as emulated GigE Vision cameras (one address each; run inside "
      "netns-run in tests)");
  command->add_option("--log", options->log, "Recording (.lcmlog) with ROMO_STEREO_RIG<k> channels")
      ->required();
  command->add_option("--rate", options->rate_hz, "Frame rate in Hz (default: the recording's rate)")
      ->check(CLI::PositiveNumber);
  command->add_flag("--loop", options->loop, "Start over at the end of the recording");
  command->add_option("--base-address", options->base_address,
                      "IPv4 address of the first camera; the others follow (rig k left, right, ...)");
  command->add_option("--rig-config-out", options->rig_config_out,
                      "Write a rig configuration for gige:// that connects to the served cameras");
  command->add_option("--max-frames", options->max_frames,
                      "Frame sets held in memory and served (default 300)")
      ->check(CLI::PositiveNumber);
  command->add_option("--duration", options->duration_s, "Stop after this many seconds (default: never)")
      ->check(CLI::NonNegativeNumber);
  command->callback([options] { Serve(*options); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
