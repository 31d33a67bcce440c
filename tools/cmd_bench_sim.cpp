// `romo bench sim`: ray-casting throughput of the simulator. Baseline: the same frames rendered
// by one thread in the same run; reports rays per second per core and seconds per 12-camera
// frame with 1 and N threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>
#include <vector>

#include "cli/command_registry.hpp"
#include "romo/core/check.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::tools {
namespace {

struct Options {
  double scale = 1.0;
  int frames = 3;
  int threads = 2;
  int aa = 2;
  std::uint64_t seed = 1;
};

struct Timing {
  double median_s = 0.0;
  double cpu_s = 0.0;  // process CPU seconds per frame (all threads)
};

double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

Timing TimeFrames(const sim::Renderer& renderer, const sim::ParkingScene& scene,
                  const std::vector<double>& times, std::uint64_t seed) {
  std::vector<double> wall;
  const double cpu0 = CpuSeconds();
  for (std::size_t i = 0; i < times.size(); ++i) {
    const sim::SceneSnapshot snap = scene.At(times[i]);
    const auto t0 = std::chrono::steady_clock::now();
    const auto frames = renderer.Render(snap, seed, i, nullptr);
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    ROMO_DEMAND(!frames.empty());
  }
  Timing t;
  std::sort(wall.begin(), wall.end());
  t.median_s = wall[wall.size() / 2];
  t.cpu_s = (CpuSeconds() - cpu0) / static_cast<double>(times.size());
  return t;
}

void Run(const Options& o) {
  if (o.frames < 1) Fail("romo bench sim: --frames = " + std::to_string(o.frames) + " must be >= 1");
  sim::SimParams params;
  params.scale = o.scale;
  params.seed = o.seed;
  params.render.samples_per_axis = o.aa;
  params.render.threads = o.threads;
  params.Validate();
  const drivers::Calibration calibration = sim::SimCalibration(params);
  const sim::ParkingScene scene(sim::ParkingSceneParams{o.seed});
  // Frames spread over the maneuver (approach, turn, entry).
  std::vector<double> times;
  for (int i = 0; i < o.frames; ++i) {
    times.push_back(scene.maneuver_duration_s() * (i + 0.5) / o.frames);
  }
  sim::RenderParams one = params.render;
  one.threads = 1;
  const sim::Renderer r1(calibration, one);
  const sim::Renderer rn(calibration, params.render);
  const double rays = static_cast<double>(r1.RaysPerFrame(false));
  const int cameras = static_cast<int>(calibration.rigs.size()) * 2;
  std::printf("romo bench sim: %d cameras %dx%d, %dx%d rays per pixel, %d frames, seed %llu\n",
              cameras, calibration.rigs.front().width_px, calibration.rigs.front().height_px, o.aa,
              o.aa, o.frames, static_cast<unsigned long long>(o.seed));
  const Timing t1 = TimeFrames(r1, scene, times, o.seed);
  const Timing tn = TimeFrames(rn, scene, times, o.seed);
  std::printf("rays per frame: %.0f\n", rays);
  // Per core: rays over the CPU time the process spent, which stays meaningful on a loaded
  // machine where wall time does not.
  std::printf("1 thread (baseline): %.3f s per %d-camera frame (wall, median), %.3f CPU s, "
              "%.2f Mrays/s per core\n",
              t1.median_s, cameras, t1.cpu_s, rays / t1.cpu_s / 1e6);
  std::printf("%d threads: %.3f s per %d-camera frame (wall, median), %.3f CPU s, %.2f Mrays/s "
              "per core, wall speed-up %.2fx vs 1 thread\n",
              o.threads, tn.median_s, cameras, tn.cpu_s, rays / tn.cpu_s / 1e6,
              t1.median_s / tn.median_s);
}

void Register(CLI::App& root) {
  CLI::App& bench =
      CommandGroup(root, "bench", "Benchmarks (ratios against a named baseline in the same run)");
  auto o = std::make_shared<Options>();
  auto* cmd = bench.add_subcommand(
      "sim", "Simulator ray casting: rays per second per core and seconds per 12-camera frame "
             "with 1 and N threads (baseline: 1 thread)");
  cmd->add_option("--scale", o->scale, "Image scale (default 1 = 782x582)");
  cmd->add_option("--frames", o->frames, "Frames per configuration (default 3; median reported)");
  cmd->add_option("--threads", o->threads, "Threads of the parallel run (default 2)")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--aa", o->aa, "Anti-aliasing rays per pixel axis (default 2)")->check(CLI::Range(1, 4));
  cmd->add_option("--seed", o->seed, "Scene seed");
  cmd->callback([o] { Run(*o); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
