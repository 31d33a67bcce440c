// `romo record --source URI --out FILE.lcmlog [--frames N] [--png]`: any frame source to an LCM log.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/recording.hpp"

namespace romo::tools {
namespace {

std::atomic<bool> g_stop{false};

extern "C" void OnStopSignal(int) { g_stop = true; }

struct RecordOptions {
  std::string source;
  std::string out;
  std::uint64_t frames = 0;
  bool png = false;
};

void PrintSourceEvents(const drivers::FrameSource& source) {
  const drivers::SourceStatus status = source.status();
  for (const auto& event : status.events) std::fprintf(stderr, "romo record: %s\n", event.c_str());
  for (const auto& cam : status.cameras) {
    if (cam.incomplete + cam.unpaired + cam.dropped + cam.reconnects == 0) continue;
    std::fprintf(stderr,
                 "romo record: %s: %llu completed, %llu incomplete, %llu unpaired, %llu dropped, "
                 "%llu reconnects\n",
                 cam.camera_id.c_str(), static_cast<unsigned long long>(cam.completed),
                 static_cast<unsigned long long>(cam.incomplete),
                 static_cast<unsigned long long>(cam.unpaired),
                 static_cast<unsigned long long>(cam.dropped),
                 static_cast<unsigned long long>(cam.reconnects));
  }
}

void Record(const RecordOptions& options) {
  // SIGINT/SIGTERM stop the loop; the writer then closes and renames the file as usual.
  // Installed first: a signal while the source opens must not kill the process either.
  g_stop = false;
  auto* old_int = std::signal(SIGINT, OnStopSignal);
  auto* old_term = std::signal(SIGTERM, OnStopSignal);
  // Opening errors (bad URI, missing file, no camera) are bad input: romo::Error -> exit 2.
  std::unique_ptr<drivers::FrameSource> source = drivers::OpenSource(options.source);
  drivers::LogWriter writer(options.out,
                            options.png ? drivers::ImageEncoding::kPng : drivers::ImageEncoding::kRaw);

  Progress progress("record", options.frames);
  std::uint64_t count = 0;
  bool calibration_written = false;
  std::optional<std::string> failure;
  while (!g_stop && (options.frames == 0 || count < options.frames)) {
    std::optional<drivers::FrameSet> frames;
    try {
      frames = source->Next();
      if (!frames) break;
      if (!calibration_written) {
        // Written first, stamped like the first frame set so seek offsets start there.
        if (const auto* calibration = source->calibration()) {
          writer.WriteCalibration(*calibration, frames->stamp_ns);
        }
        calibration_written = true;
      }
      writer.Write(*frames);
    } catch (const std::exception& e) {
      failure = e.what();
      break;
    }
    ++count;
    progress.Update(count, std::to_string(writer.bytes_written() / (1024 * 1024)) + " MB");
  }
  if (!calibration_written && source->calibration() != nullptr) {
    writer.WriteCalibration(*source->calibration(), 0);
  }
  progress.Finish(std::to_string(writer.bytes_written() / (1024 * 1024)) + " MB");
  writer.Close();
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);
  PrintSourceEvents(*source);
  std::printf("recorded %llu frame sets (%llu events, %.1f MB) to %s%s\n",
              static_cast<unsigned long long>(count),
              static_cast<unsigned long long>(writer.events_written()),
              static_cast<double>(writer.bytes_written()) / 1e6, options.out.c_str(),
              g_stop ? " (interrupted)" : "");
  if (failure) {
    std::fprintf(stderr, "romo record: source failed after %llu frame sets: %s (all %llu kept in %s)\n",
                 static_cast<unsigned long long>(count), failure->c_str(),
                 static_cast<unsigned long long>(count), options.out.c_str());
    throw CLI::RuntimeError(kExitRuntimeFailure);
  }
}

void Register(CLI::App& root) {
  auto options = std::make_shared<RecordOptions>();
  auto* command = root.add_subcommand(
      "record", "Record a frame source (gige://, log://, rgbd://, kinect://, sim://) to an LCM log");
  command->add_option("--source", options->source, "Source URI, e.g. rgbd:///data/tum")->required();
  command->add_option("--out", options->out, "Output LCM log file (.lcmlog)")->required();
  command->add_option("--frames", options->frames, "Stop after N frame sets (0 = until the end)");
  command->add_flag("--png", options->png, "Store images as lossless PNG instead of raw");
  command->callback([options] { Record(*options); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
