// `romo gige-serve`: a recording's cameras served as emulated GigE Vision cameras (one address
// each) so the real acquisition path (gige://) can run against recorded frames.
#include <arpa/inet.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
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
  // Fault injection.
  double packet_loss_percent = 0.0;
  std::vector<std::string> stalls;       // "SERIAL:AT_S:FOR_S"
  std::vector<std::string> stamp_jumps;  // "AT_S:OFFSET_S"
};

// A fault scheduled at a time after the first frame is served.
struct Fault {
  double at_s = 0.0;
  std::string what;
  std::function<void(drivers::GigeEmulator&)> apply;
};

std::vector<std::string> SplitColons(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t colon = text.find(':', start);
    parts.push_back(text.substr(start, colon - start));
    if (colon == std::string::npos) return parts;
    start = colon + 1;
  }
}

double ParseSeconds(const std::string& text, const std::string& option, const std::string& value) {
  try {
    std::size_t used = 0;
    const double seconds = std::stod(text, &used);
    if (used == text.size() && std::isfinite(seconds)) return seconds;
  } catch (const std::exception&) {
  }
  Fail(option + " '" + value + "': '" + text + "' is not a number of seconds");
}

std::vector<Fault> ScheduleFaults(const Options& options,
                                  const std::vector<drivers::GigeEmulator::Camera>& cameras) {
  std::vector<Fault> faults;
  for (const std::string& stall : options.stalls) {
    const auto parts = SplitColons(stall);
    if (parts.size() != 3) Fail("--stall '" + stall + "' must be SERIAL:AT_S:FOR_S, e.g. romo-r0-r:3:2");
    std::size_t index = cameras.size();
    for (std::size_t i = 0; i < cameras.size(); ++i) {
      if (cameras[i].serial == parts[0]) index = i;
    }
    if (index == cameras.size()) {
      std::string known;
      for (const auto& camera : cameras) known += (known.empty() ? "" : ", ") + camera.serial;
      Fail("--stall '" + stall + "': no served camera has serial '" + parts[0] + "' (served: " + known + ")");
    }
    const double at_s = ParseSeconds(parts[1], "--stall", stall);
    const double for_s = ParseSeconds(parts[2], "--stall", stall);
    if (at_s < 0.0 || for_s <= 0.0) Fail("--stall '" + stall + "': AT_S must be >= 0 and FOR_S > 0");
    faults.push_back({at_s, "camera " + parts[0] + " stalled (answers control, sends no frames)",
                      [index](drivers::GigeEmulator& e) { e.SetStalled(index, true); }});
    faults.push_back({at_s + for_s, "camera " + parts[0] + " sends frames again",
                      [index](drivers::GigeEmulator& e) { e.SetStalled(index, false); }});
  }
  for (const std::string& jump : options.stamp_jumps) {
    const auto parts = SplitColons(jump);
    if (parts.size() != 2) Fail("--stamp-jump '" + jump + "' must be AT_S:OFFSET_S, e.g. 3:-5 (back 5 s)");
    const double at_s = ParseSeconds(parts[0], "--stamp-jump", jump);
    const double offset_s = ParseSeconds(parts[1], "--stamp-jump", jump);
    if (at_s < 0.0 || offset_s == 0.0) Fail("--stamp-jump '" + jump + "': AT_S must be >= 0, OFFSET_S non-zero");
    const auto offset_ns = static_cast<std::int64_t>(offset_s * 1e9);
    faults.push_back({at_s, "device timestamps of every camera jump by " + parts[1] + " s",
                      [offset_ns](drivers::GigeEmulator& e) { e.ShiftStamps(offset_ns); }});
  }
  std::sort(faults.begin(), faults.end(), [](const Fault& a, const Fault& b) { return a.at_s < b.at_s; });
  return faults;
}

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

  std::vector<Fault> faults = ScheduleFaults(options, cameras);
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  drivers::GigeEmulator emulator(std::move(cameras), rate_hz, options.loop);
  if (options.packet_loss_percent > 0.0) {
    emulator.SetPacketLoss(options.packet_loss_percent / 100.0);
    std::printf("fault: every camera drops %.3f %% of its GVSP packets\n", options.packet_loss_percent);
  }
  // Written only once the cameras answer, so a client waiting for the file can connect at once.
  if (!options.rig_config_out.empty()) config.Save(options.rig_config_out);

  const std::uint64_t total = options.loop ? 0 : stamps.size();
  Progress progress("gige-serve", total);
  const auto start = std::chrono::steady_clock::now();
  // Faults are timed from the first frame a client receives, not from start-up: a client that
  // takes seconds to open the cameras (discovery on a loaded machine) still sees each fault at
  // the same point of its acquisition.
  std::optional<std::chrono::steady_clock::time_point> acquiring_since;
  while (!g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto served = emulator.frames_served();
    const std::uint64_t least = *std::min_element(served.begin(), served.end());
    const std::uint64_t most = *std::max_element(served.begin(), served.end());
    progress.Update(std::min<std::uint64_t>(least, total ? total : least),
                    std::to_string(served.size()) + " cameras");
    const auto now = std::chrono::steady_clock::now();
    if (!acquiring_since && most > 0) acquiring_since = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    const double acquiring_s =
        acquiring_since ? std::chrono::duration<double>(now - *acquiring_since).count() : -1.0;
    while (!faults.empty() && acquiring_s >= faults.front().at_s) {
      faults.front().apply(emulator);
      // On stdout, flushed: tests and operators line faults up with what the client reports.
      std::printf("fault at %.2f s of acquisition: %s\n", acquiring_s, faults.front().what.c_str());
      std::fflush(stdout);
      faults.erase(faults.begin());
    }
    if (options.duration_s > 0.0 && elapsed >= options.duration_s) break;
    if (emulator.finished()) {
      // Let the last frame leave before the cameras go away.
      std::this_thread::sleep_for(std::chrono::duration<double>(1.0 / rate_hz));
      break;
    }
  }
  progress.Finish(g_stop ? "stopped" : "done");
  const auto stalled = emulator.frames_stalled();
  for (std::size_t i = 0; i < stalled.size(); ++i) {
    if (stalled[i] > 0) std::printf("camera %zu: %llu frames not sent while stalled\n", i,
                                    static_cast<unsigned long long>(stalled[i]));
  }
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
  command->add_option("--packet-loss", options->packet_loss_percent,
                      "Fault injection: every camera drops this percentage of its GVSP packets")
      ->check(CLI::Range(0.0, 100.0));
  command->add_option("--stall", options->stalls,
                      "Fault injection: SERIAL:AT_S:FOR_S stalls a camera AT_S seconds after the first "
                      "frame is served, for FOR_S seconds (it stays discoverable but sends no "
                      "frames); repeatable");
  command->add_option("--stamp-jump", options->stamp_jumps,
                      "Fault injection: AT_S:OFFSET_S shifts every camera's device timestamps by "
                      "OFFSET_S (negative: back in time) from AT_S seconds after the first frame is "
                      "served; repeatable");
  command->callback([options] { Serve(*options); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
