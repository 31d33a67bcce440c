// `romo soak LOG --duration S --out DIR`: the vehicle pipeline over a recording played in a loop
// for a fixed wall time, sampling resident memory (VmRSS), the heap in use (mallinfo2) and
// per-frame latency (wall and CPU) to show they stay flat: slopes per minute go to soak.json,
// samples to soak.csv and a plot to soak.png.
#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/core/json.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/pipeline/outputs.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/pipeline/run_loop.hpp"

namespace romo::tools {
namespace {

struct SoakOptions {
  std::string log;
  std::string out_dir;
  double duration_s = 120.0;
  double warmup_s = 20.0;
  int threads = 2;
  double leak_kb_per_frame = 0.0;  // kept and never freed: shows the memory fit catches a leak
};

struct Sample {
  double t_s = 0.0;
  double rss_mb = 0.0;
  double heap_mb = 0.0;     // bytes malloc has handed out and not had back (all arenas, mmapped chunks)
  double latency_ms = 0.0;  // the pipeline's own end-to-end time for the frame (wall)
  double cpu_ms = 0.0;      // process CPU time spent on the frame (all threads)
  double tracks = 0.0;      // tracks the pipeline holds after the frame (live and coasting)
  std::int64_t loop = 0;    // times the recording had started over when the frame came out
};

// Mean tracks held per frame over the first and the last loops wholly inside the measured window:
// every loop replays the same frames, so state that is never pruned shows as a difference that no
// host load can cause (unlike the time slopes).
struct TracksPerLoop {
  double first = 0.0, last = 0.0;  // of the first and last whole loop
  // Of the first and last loops_averaged whole loops: one loop's mean moves by a track or two
  // with what the loop before left coasting and remembered.
  double first_mean = 0.0, last_mean = 0.0;
  std::int64_t loops_compared = 0, loops_averaged = 0;
};

TracksPerLoop CompareLoops(const std::vector<Sample>& measured) {
  TracksPerLoop result;
  if (measured.empty()) return result;
  // The first and last loops seen may be cut by the warm-up and the end of the run.
  const std::int64_t first = measured.front().loop + 1, last = measured.back().loop - 1;
  if (last < first) return result;
  // Mean tracks per frame of each whole loop, in one pass over the samples.
  std::map<std::int64_t, std::pair<double, int>> sum_and_count;
  for (const auto& s : measured) {
    if (s.loop < first || s.loop > last) continue;
    auto& [sum, n] = sum_and_count[s.loop];
    sum += s.tracks;
    ++n;
  }
  auto mean_of = [&](std::int64_t loop) {
    const auto it = sum_and_count.find(loop);
    return it != sum_and_count.end() ? it->second.first / it->second.second : 0.0;
  };
  result.first = mean_of(first);
  result.last = mean_of(last);
  result.loops_compared = last - first + 1;
  constexpr std::int64_t kLoopsAveraged = 5;
  result.loops_averaged = std::min(kLoopsAveraged, (result.loops_compared + 1) / 2);
  for (std::int64_t k = 0; k < result.loops_averaged; ++k) {
    result.first_mean += mean_of(first + k) / static_cast<double>(result.loops_averaged);
    result.last_mean += mean_of(last - k) / static_cast<double>(result.loops_averaged);
  }
  return result;
}

// Memory at the same point of every whole loop: the lowest and the highest sample of each. Within
// a loop RSS jumps between levels ~15 MB apart as the allocator maps and unmaps large buffers, so a
// fit over the raw samples moves with the phase the window ends at (+3.1 MB/min once with first
// and last samples 0.3 MB apart), and a fit over the peaks with whether the upper level was
// reached early or late in the run (+4.6 MB/min once, with the last sample 5.6 MB below the
// first). What a leak keeps is held between frames too: it lifts every loop's floor.
struct LoopExtremes {
  std::vector<Sample> floors, peaks;  // one per whole loop, at the loop's mean time
};

LoopExtremes PerLoop(const std::vector<Sample>& measured, double Sample::*field) {
  LoopExtremes result;
  if (measured.empty()) return result;
  const std::int64_t first = measured.front().loop + 1, last = measured.back().loop - 1;
  std::map<std::int64_t, std::vector<const Sample*>> by_loop;
  for (const auto& s : measured) {
    if (s.loop >= first && s.loop <= last) by_loop[s.loop].push_back(&s);
  }
  for (const auto& [loop, samples] : by_loop) {
    Sample floor, peak;
    floor.*field = 1e300, peak.*field = -1e300;
    for (const Sample* s : samples) {
      floor.t_s += s->t_s / static_cast<double>(samples.size());
      floor.*field = std::min(floor.*field, s->*field);
      peak.*field = std::max(peak.*field, s->*field);
    }
    peak.t_s = floor.t_s;
    floor.loop = peak.loop = loop;
    result.floors.push_back(floor);
    result.peaks.push_back(peak);
  }
  return result;
}

// Resident set size from /proc/self/status ("VmRSS:   123456 kB"), in MB (1e6 bytes).
double ResidentMb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) * 1024.0 / 1e6;
  }
  Fail("soak: /proc/self/status has no VmRSS line");
}

// What the program holds from malloc, free of the allocator's own keeping: RSS also moves by
// ~3 MB steps as freed memory is kept or given back (glibc's heaps and trimming), which a slope
// over 100 s cannot tell from a leak; the heap in use moves only with what is allocated.
double HeapInUseMb() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd) / 1e6;
}

double ProcessCpuMs() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return 1e3 * (usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-3 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

struct Fit {
  double slope = 0.0;      // per minute
  double intercept = 0.0;  // at t = 0
  double mean = 0.0;
};

// Ordinary least squares of y over t (seconds); slope reported per minute.
Fit LeastSquares(const std::vector<Sample>& samples, double Sample::*field) {
  Fit fit;
  const double n = static_cast<double>(samples.size());
  if (samples.empty()) return fit;
  double st = 0, sy = 0;
  for (const auto& s : samples) {
    st += s.t_s;
    sy += s.*field;
  }
  const double mt = st / n, my = sy / n;
  double stt = 0, sty = 0;
  for (const auto& s : samples) {
    stt += (s.t_s - mt) * (s.t_s - mt);
    sty += (s.t_s - mt) * (s.*field - my);
  }
  const double per_s = stt > 0 ? sty / stt : 0.0;
  fit.slope = 60.0 * per_s;
  fit.intercept = my - per_s * mt;
  fit.mean = my;
  return fit;
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

// One panel: samples as dots, the fit over the measured window as a line, axes in minutes.
void DrawPanel(cv::Mat* image, cv::Rect area, const std::vector<Sample>& all, double Sample::*field,
               const Fit& fit, double warmup_s, const std::string& title) {
  const cv::Scalar black(0, 0, 0), grey(180, 180, 180), blue(200, 80, 0), red(0, 0, 220);
  cv::rectangle(*image, area, grey);
  double t_max = 1e-9, y_min = 1e300, y_max = -1e300;
  for (const auto& s : all) {
    t_max = std::max(t_max, s.t_s);
    y_min = std::min(y_min, s.*field);
    y_max = std::max(y_max, s.*field);
  }
  if (all.empty()) y_min = 0, y_max = 1;
  const double pad = std::max(0.05 * (y_max - y_min), 1e-3 * std::max(1.0, std::abs(y_max)));
  y_min = std::max(0.0, y_min - pad);
  y_max += pad;
  auto to_px = [&](double t, double y) {
    return cv::Point(area.x + static_cast<int>((t / t_max) * (area.width - 1)),
                     area.y + area.height - 1 - static_cast<int>((y - y_min) / (y_max - y_min) * (area.height - 1)));
  };
  for (const auto& s : all) cv::circle(*image, to_px(s.t_s, s.*field), 1, s.t_s < warmup_s ? grey : blue, -1);
  const double per_s = fit.slope / 60.0;
  cv::line(*image, to_px(warmup_s, fit.intercept + per_s * warmup_s), to_px(t_max, fit.intercept + per_s * t_max), red, 2);
  char text[256];
  std::snprintf(text, sizeof text, "%s   slope %+.3f per min   mean %.2f   (%.1f..%.1f, t 0..%.1f min)",
                title.c_str(), fit.slope, fit.mean, y_min, y_max, t_max / 60.0);
  cv::putText(*image, text, cv::Point(area.x + 8, area.y + 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, black, 1, cv::LINE_AA);
}

void Soak(const SoakOptions& o) {
  namespace fs = std::filesystem;
  if (!(o.duration_s > 0.0)) Fail("soak: --duration " + std::to_string(o.duration_s) + " must be > 0 s");
  if (!(o.warmup_s >= 0.0 && o.warmup_s < o.duration_s)) {
    Fail("soak: --warmup " + std::to_string(o.warmup_s) + " s must be in [0, --duration)");
  }
  if (!(o.leak_kb_per_frame >= 0.0 && o.leak_kb_per_frame <= 1e5)) {
    Fail("soak: --leak-kb-per-frame " + std::to_string(o.leak_kb_per_frame) + " must be in [0, 100000]");
  }
  drivers::LogReader reader(o.log);
  if (reader.calibration() == nullptr) Fail("soak: recording " + o.log + " has no calibration (ROMO_CALIBRATION)");
  const drivers::Calibration calibration = *reader.calibration();
  pipeline::Pipeline pipe(calibration, pipeline::PipelineParams::ForCalibration(calibration, o.threads));
  // Outputs are built and summarised as in a run (so their memory counts) but not written: 30
  // minutes of frames would only fill the disk.
  pipeline::OutputSink sink(calibration, pipeline::OutputOptions{"", "", false, false});
  pipeline::LoopedLog looped(reader);
  fs::create_directories(o.out_dir);

  std::vector<std::vector<char>> leaked;  // filled with non-zero bytes so its pages are resident
  std::vector<Sample> samples;
  Progress progress("soak", 0);
  const auto start = std::chrono::steady_clock::now();
  double cpu_before = ProcessCpuMs();
  pipeline::RunOptions run;
  run.duration_s = o.duration_s;
  const auto stats = pipeline::RunFrames(
      looped, pipe, sink, run, nullptr, [&](std::int64_t done, const pipeline::FrameResult& r) {
        if (o.leak_kb_per_frame > 0.0) leaked.emplace_back(static_cast<std::size_t>(1e3 * o.leak_kb_per_frame), '\1');
        Sample s;
        s.t_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        s.rss_mb = ResidentMb();
        s.heap_mb = HeapInUseMb();
        s.latency_ms = r.status.total_latency_ms;
        const double cpu_now = ProcessCpuMs();
        s.cpu_ms = cpu_now - cpu_before;
        cpu_before = cpu_now;
        s.tracks = static_cast<double>(r.tracks.size());
        s.loop = looped.loops();
        samples.push_back(s);
        char text[96];
        std::snprintf(text, sizeof text, "%.0f s, RSS %.1f MB, %.0f ms", s.t_s, s.rss_mb, s.latency_ms);
        progress.Update(static_cast<std::uint64_t>(done), text);
      });
  progress.Finish();
  sink.Finish();
  std::vector<Sample> measured;
  for (const auto& s : samples) {
    if (s.t_s >= o.warmup_s) measured.push_back(s);
  }
  if (measured.size() < 10) {
    Fail("soak: only " + std::to_string(measured.size()) + " frames after the " + std::to_string(o.warmup_s) +
         " s warm-up: run longer (--duration) or warm up shorter (--warmup)");
  }
  const LoopExtremes rss_loops = PerLoop(measured, &Sample::rss_mb);
  const LoopExtremes heap_loops = PerLoop(measured, &Sample::heap_mb);
  // Fewer than 3 whole loops (a long recording or a slow host) leave only the raw samples.
  const bool loops_fit = rss_loops.peaks.size() >= 3;
  const Fit rss_samples = LeastSquares(measured, &Sample::rss_mb);
  // Through the loops' floors (or peaks), or the fit over the samples with too few loops.
  const auto loop_fit = [&](const std::vector<Sample>& per_loop, double Sample::*field, const Fit& samples) {
    return loops_fit ? LeastSquares(per_loop, field) : samples;
  };
  const Fit rss_floor = loop_fit(rss_loops.floors, &Sample::rss_mb, rss_samples);
  const Fit rss_peak = loop_fit(rss_loops.peaks, &Sample::rss_mb, rss_samples);
  const Fit heap_samples = LeastSquares(measured, &Sample::heap_mb);
  const Fit heap_floor = loop_fit(heap_loops.floors, &Sample::heap_mb, heap_samples);
  const Fit latency = LeastSquares(measured, &Sample::latency_ms);
  const Fit cpu = LeastSquares(measured, &Sample::cpu_ms);
  const TracksPerLoop tracks = CompareLoops(measured);
  std::vector<double> latencies, rss_values;
  for (const auto& s : measured) {
    latencies.push_back(s.latency_ms);
    rss_values.push_back(s.rss_mb);
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  {
    std::ofstream csv(o.out_dir + "/soak.csv");
    csv << "t_s,rss_mb,heap_mb,latency_ms,cpu_ms,tracks,loop\n";
    for (const auto& s : samples) {
      csv << s.t_s << ',' << s.rss_mb << ',' << s.heap_mb << ',' << s.latency_ms << ',' << s.cpu_ms << ',' << s.tracks << ',' << s.loop
          << '\n';
    }
  }
  {
    std::ofstream json(o.out_dir + "/soak.json");
    char text[2048];
    std::snprintf(text, sizeof text,
                  "{\n  \"log\": \"%s\",\n  \"duration_s\": %.1f,\n  \"warmup_s\": %.1f,\n  \"frames\": %lld,\n"
                  "  \"frames_measured\": %zu,\n  \"loops\": %lld,\n  \"skipped_out_of_order\": %lld,\n"
                  "  \"rss_mb\": {\"first\": %.2f, \"last\": %.2f, \"max\": %.2f, \"mean\": %.2f, \"slope_mb_per_min\": %.4f, "
                  "\"floor_slope_mb_per_min\": %.4f, \"peak_slope_mb_per_min\": %.4f, \"sample_slope_mb_per_min\": %.4f, "
                  "\"loops_fitted\": %zu},\n"
                  "  \"heap_mb\": {\"first\": %.2f, \"last\": %.2f, \"mean\": %.2f, \"floor_slope_mb_per_min\": %.4f, "
                  "\"sample_slope_mb_per_min\": %.4f},\n"
                  "  \"latency_ms\": {\"mean\": %.2f, \"p50\": %.2f, \"p95\": %.2f, \"slope_ms_per_min\": %.4f},\n"
                  "  \"cpu_ms_per_frame\": {\"mean\": %.2f, \"slope_ms_per_min\": %.4f},\n"
                  "  \"tracks_per_frame\": {\"first_loop\": %.3f, \"last_loop\": %.3f, \"loops_compared\": %lld, "
                  "\"first_loops_mean\": %.3f, \"last_loops_mean\": %.3f, \"loops_averaged\": %lld}\n}\n",
                  JsonEscape(o.log).c_str(), wall_s, o.warmup_s, static_cast<long long>(stats.frames), measured.size(),
                  static_cast<long long>(looped.loops()), static_cast<long long>(stats.skipped_out_of_order),
                  measured.front().rss_mb, measured.back().rss_mb,
                  *std::max_element(rss_values.begin(), rss_values.end()), rss_samples.mean, rss_floor.slope, rss_floor.slope,
                  rss_peak.slope, rss_samples.slope, loops_fit ? rss_loops.peaks.size() : std::size_t{0},
                  measured.front().heap_mb, measured.back().heap_mb, heap_samples.mean, heap_floor.slope,
                  heap_samples.slope, latency.mean,
                  Percentile(latencies, 0.5), Percentile(latencies, 0.95), latency.slope, cpu.mean, cpu.slope, tracks.first, tracks.last,
                  static_cast<long long>(tracks.loops_compared), tracks.first_mean, tracks.last_mean,
                  static_cast<long long>(tracks.loops_averaged));
    json << text;
  }
  cv::Mat plot(4 * 260 + 20, 1000, CV_8UC3, cv::Scalar(255, 255, 255));
  DrawPanel(&plot, cv::Rect(10, 10, 980, 250), samples, &Sample::rss_mb, rss_floor, o.warmup_s,
            loops_fit ? "resident memory (MB), fit of loop floors" : "resident memory (MB)");
  DrawPanel(&plot, cv::Rect(10, 270, 980, 250), samples, &Sample::heap_mb, heap_floor, o.warmup_s,
            loops_fit ? "heap in use (MB), fit of loop floors" : "heap in use (MB)");
  DrawPanel(&plot, cv::Rect(10, 530, 980, 250), samples, &Sample::latency_ms, latency, o.warmup_s, "frame latency (ms, wall)");
  DrawPanel(&plot, cv::Rect(10, 790, 980, 250), samples, &Sample::cpu_ms, cpu, o.warmup_s, "CPU per frame (ms)");
  cv::imwrite(o.out_dir + "/soak.png", plot);
  std::printf("soak: %lld frames (%lld loops of %s) in %.1f s; after %.0f s warm-up: RSS %.1f MB, loop floor slope %+.3f MB/min, heap %+.3f MB/min, "
              "latency mean %.1f ms slope %+.3f ms/min, CPU %.1f ms/frame slope %+.3f ms/min; %s/soak.{json,csv,png}\n",
              static_cast<long long>(stats.frames), static_cast<long long>(looped.loops()), o.log.c_str(), wall_s,
              o.warmup_s, rss_samples.mean, rss_floor.slope, heap_floor.slope, latency.mean, latency.slope, cpu.mean, cpu.slope,
              o.out_dir.c_str());
}

}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<SoakOptions>();
  CLI::App* cmd = root.add_subcommand(
      "soak", "Replay a recording in a loop for a fixed time; report resident-memory and latency drift (slopes)");
  cmd->add_option("log", opts->log, "recording (.lcmlog) with a calibration, e.g. from romo sim")->required();
  cmd->add_option("--out", opts->out_dir, "folder for soak.json, soak.csv and soak.png")->required();
  cmd->add_option("--duration", opts->duration_s, "wall time to run, seconds")->capture_default_str();
  cmd->add_option("--warmup", opts->warmup_s, "seconds left out of the fits (caches and pools filling)")
      ->capture_default_str();
  cmd->add_option("--threads", opts->threads, "stereo threads (rigs in parallel)")->capture_default_str();
  cmd->add_option("--leak-kb-per-frame", opts->leak_kb_per_frame,
                  "self-check: keep this much memory per frame, never freed, to see the memory slope catch it")
      ->capture_default_str();
  cmd->callback([opts] { Soak(*opts); });
});

}  // namespace romo::tools
