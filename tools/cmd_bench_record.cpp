// `romo bench record`: recording throughput of LogWriter against bare lcm::LogFile writing the
// very same encoded events, in one run (ratios, not absolute times, are what compare).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"

namespace romo::tools {
namespace {

struct BenchOptions {
  int frames = 50;
  int rigs = 6;
  bool png = false;
  std::string dir = "/tmp";
  bool json = false;
};

struct Figure {
  std::string name;
  double seconds = 0;
  std::uint64_t events = 0;
  std::uint64_t bytes = 0;
  double mb_per_s() const { return static_cast<double>(bytes) / 1e6 / seconds; }
  double events_per_s() const { return static_cast<double>(events) / seconds; }
};

// The RoMo camera: 782x582, 12-bit mono in 16-bit words. Sensor-like noise on a gradient so PNG
// has realistic work to do.
drivers::FrameSet MakeFrameSet(int k, int rigs, std::mt19937* rng) {
  drivers::FrameSet set;
  set.sequence = static_cast<std::uint64_t>(k);
  set.stamp_ns = 1'700'000'000'000'000'000 + static_cast<std::int64_t>(k) * 100'000'000;
  std::normal_distribution<float> noise(0.0f, 8.0f);
  for (int rig = 0; rig < rigs; ++rig) {
    drivers::StereoFrame stereo;
    stereo.rig_id = rig;
    for (drivers::CameraFrame* cam : {&stereo.left, &stereo.right}) {
      cam->image = drivers::Image::Allocate(drivers::PixelFormat::kMono16, 782, 582);
      for (int y = 0; y < 582; ++y) {
        auto* row = reinterpret_cast<std::uint16_t*>(cam->image.row(y));
        for (int x = 0; x < 782; ++x) {
          const float v = 1000.0f + 2.0f * static_cast<float>(x + y) + noise(*rng);
          row[x] = static_cast<std::uint16_t>(std::clamp(v, 0.0f, 4095.0f));
        }
      }
      cam->stamp_ns = set.stamp_ns;
    }
    set.stereo.push_back(std::move(stereo));
  }
  return set;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void Bench(const BenchOptions& options) {
  if (options.frames <= 0) Fail("--frames = " + std::to_string(options.frames) + " must be > 0");
  if (options.rigs <= 0) Fail("--rigs = " + std::to_string(options.rigs) + " must be > 0");
  const std::string base = options.dir + "/romo_bench_record_" + std::to_string(::getpid());
  const auto encoding = options.png ? drivers::ImageEncoding::kPng : drivers::ImageEncoding::kRaw;

  // Frames are made before timing: the benchmark measures recording, not the generator.
  std::mt19937 rng(1);
  std::vector<drivers::FrameSet> sets;
  Progress progress("bench record", static_cast<std::uint64_t>(options.frames) * 4);
  for (int k = 0; k < options.frames; ++k) {
    sets.push_back(MakeFrameSet(k, options.rigs, &rng));
    progress.Update(static_cast<std::uint64_t>(k + 1), "making frames");
  }
  std::uint64_t done = static_cast<std::uint64_t>(options.frames);

  // 1. LogWriter::Write: encoding + writing + flush per event.
  Figure writer_figure{"LogWriter.Write (encode+write)"};
  {
    const auto start = std::chrono::steady_clock::now();
    drivers::LogWriter writer(base + "_writer.lcmlog", encoding);
    for (const auto& set : sets) {
      writer.Write(set);
      progress.Update(++done, "LogWriter.Write");
    }
    writer.Close();
    writer_figure.seconds = Seconds(start);
    writer_figure.events = writer.events_written();
    writer_figure.bytes = writer.bytes_written();
  }
  sets.clear();

  // The exact encoded events LogWriter produced, for the two write-only runs.
  const std::vector<drivers::LogEvent> events = drivers::ReadAllEvents(base + "_writer.lcmlog", nullptr);

  // 2. LogWriter::WriteRaw of the encoded events: the writer's own overhead (flush, rename).
  Figure raw_figure{"LogWriter.WriteRaw (write)"};
  {
    const auto start = std::chrono::steady_clock::now();
    drivers::LogWriter writer(base + "_raw.lcmlog");
    std::uint64_t i = 0;
    for (const auto& event : events) {
      writer.WriteRaw(event.channel, event.timestamp_us * 1000, event.data.data(), event.data.size());
      if (++i % static_cast<std::uint64_t>(options.rigs) == 0) progress.Update(++done, "WriteRaw");
    }
    writer.Close();
    raw_figure.seconds = Seconds(start);
    raw_figure.events = writer.events_written();
    raw_figure.bytes = writer.bytes_written();
  }

  // 3. Baseline: bare lcm::LogFile, no flush per event, no rename.
  Figure bare_figure{"bare lcm::LogFile (baseline)"};
  {
    const auto start = std::chrono::steady_clock::now();
    {
      lcm::LogFile log(base + "_bare.lcmlog", "w");
      if (!log.good()) Fail(base + "_bare.lcmlog: cannot create");
      std::uint64_t i = 0;
      for (const auto& event : events) {
        lcm::LogEvent e;
        e.eventnum = static_cast<std::int64_t>(i);
        e.timestamp = event.timestamp_us;
        e.channel = event.channel;
        e.datalen = static_cast<std::int32_t>(event.data.size());
        e.data = const_cast<std::uint8_t*>(event.data.data());
        if (log.writeEvent(&e) != 0) Fail(base + "_bare.lcmlog: write failed");
        bare_figure.bytes += 28 + event.channel.size() + event.data.size();
        if (++i % static_cast<std::uint64_t>(options.rigs) == 0) progress.Update(++done, "bare");
      }
    }  // closing is part of the cost
    bare_figure.seconds = Seconds(start);
    bare_figure.events = events.size();
  }
  progress.Finish();
  for (const char* suffix : {"_writer.lcmlog", "_raw.lcmlog", "_bare.lcmlog"}) {
    std::remove((base + suffix).c_str());
  }

  const Figure figures[] = {writer_figure, raw_figure, bare_figure};
  if (options.json) {
    std::printf("{\"frames\":%d,\"rigs\":%d,\"encoding\":\"%s\",\"results\":[", options.frames,
                options.rigs, options.png ? "png" : "raw");
    for (std::size_t i = 0; i < 3; ++i) {
      const Figure& f = figures[i];
      std::printf("%s{\"name\":\"%s\",\"seconds\":%.6f,\"events\":%llu,\"bytes\":%llu,"
                  "\"mb_per_s\":%.3f,\"events_per_s\":%.3f,\"ratio_vs_bare\":%.4f}",
                  i ? "," : "", f.name.c_str(), f.seconds, static_cast<unsigned long long>(f.events),
                  static_cast<unsigned long long>(f.bytes), f.mb_per_s(), f.events_per_s(),
                  f.mb_per_s() / bare_figure.mb_per_s());
    }
    std::printf("]}\n");
    return;
  }
  std::printf("recording %d frame sets x %d rigs (782x582 mono16, %s) in %s\n", options.frames,
              options.rigs, options.png ? "png" : "raw", options.dir.c_str());
  std::printf("%-32s %10s %10s %12s %14s\n", "writer", "MB", "MB/s", "events/s", "vs baseline");
  for (const Figure& f : figures) {
    std::printf("%-32s %10.1f %10.1f %12.1f %13.3fx\n", f.name.c_str(), f.bytes / 1e6, f.mb_per_s(),
                f.events_per_s(), f.mb_per_s() / bare_figure.mb_per_s());
  }
}

void Register(CLI::App& root) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App& bench = CommandGroup(root, "bench", "Benchmarks (ratios against a baseline in the same run)");
  auto* command = bench.add_subcommand(
      "record", "Recording throughput: LogWriter vs bare lcm::LogFile on the same encoded events");
  command->add_option("--frames", options->frames, "Frame sets to record (default 50)");
  command->add_option("--rigs", options->rigs, "Stereo rigs per frame set (default 6)");
  command->add_flag("--png", options->png, "Encode images as PNG (LogWriter.Write only)");
  command->add_option("--dir", options->dir, "Folder for the scratch logs (default /tmp)");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] { Bench(*options); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
