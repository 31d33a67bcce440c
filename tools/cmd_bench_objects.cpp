// `romo bench objects`: tracker + path prediction time per frame for 1, 10 and 100 pedestrians
// (RLS paths vs the constant-velocity baseline, same scenes, same run), the RLS update per step
// vs a batch least-squares refit of the trail, and the prediction-log cost per frame.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/core/statistics.hpp"
#include "romo/objects/atlas.hpp"
#include "romo/objects/prediction_log.hpp"
#include "romo/objects/tracker.hpp"

namespace romo::tools {
namespace {

struct Options {
  int frames = 200;
  std::string atlas;
  bool json = false;
};

using Clock = std::chrono::steady_clock;
double Us(Clock::duration d) { return std::chrono::duration<double, std::micro>(d).count(); }

// N pedestrians on a 3 m grid walking in random directions at 0.8-1.6 m/s with 5 cm jitter,
// 10 Hz. Returns the per-frame Update() times in microseconds (after 5 warm-up frames).
std::vector<double> TimeTracker(const objects::Atlas& atlas, int pedestrians, int frames,
                                objects::PredictorKind kind, std::vector<double>* log_us) {
  objects::TrackerParams params;
  params.predictor.kind = kind;
  objects::Tracker tracker(atlas, params);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> heading(-M_PI, M_PI), speed(0.8, 1.6);
  std::normal_distribution<double> jitter(0.0, 0.05);
  const int side = static_cast<int>(std::ceil(std::sqrt(pedestrians)));
  std::vector<Eigen::Vector2d> start, velocity;
  for (int i = 0; i < pedestrians; ++i) {
    start.emplace_back(3.0 * (i % side), 3.0 * (i / side));
    const double h = heading(rng), s = speed(rng);
    velocity.emplace_back(s * std::cos(h), s * std::sin(h));
  }
  const objects::Classification ped = atlas.Classify(0.6, 0.4, 1.75);
  const objects::LocalEnu enu({48.0833, 11.2833, 600.0});
  objects::PredictionFrames pose;
  std::vector<double> us;
  std::vector<objects::Detection> detections(static_cast<std::size_t>(pedestrians));
  for (int f = 0; f < frames; ++f) {
    const double t = 0.1 * f;
    // Walkers turn back every 3 s so the grid stays populated and paths are not all straight.
    const double phase = std::fmod(t, 6.0) < 3.0 ? t - 6.0 * std::floor(t / 6.0) : 6.0 - std::fmod(t, 6.0);
    for (int i = 0; i < pedestrians; ++i) {
      auto& d = detections[static_cast<std::size_t>(i)];
      d.xy_m = start[static_cast<std::size_t>(i)] + velocity[static_cast<std::size_t>(i)] * 0.25 * phase +
               Eigen::Vector2d(jitter(rng), jitter(rng));
      d.length_m = 0.6;
      d.width_m = 0.4;
      d.height_m = 1.75;
      d.classification = ped;
    }
    const auto t0 = Clock::now();
    const auto& tracks = tracker.Update(t, detections);
    const auto t1 = Clock::now();
    if (f >= 5) us.push_back(Us(t1 - t0));
    if (log_us != nullptr && f >= 5) {
      const auto l0 = Clock::now();
      const auto preds = objects::MakePedestrianPredictions(tracks, atlas, f * 100'000'000LL, 0,
                                                            pose, enu, kind);
      const auto bytes = objects::EncodePedestrianPredictions(f * 100'000'000LL, f, preds);
      log_us->push_back(Us(Clock::now() - l0));
      ROMO_DEMAND(!bytes.empty());
    }
  }
  return us;
}

// One RLS update per step over a long trail, against refitting the same forgetting-weighted line
// by batch least squares over the whole trail at every step (the non-recursive twin).
void TimeRls(int steps, double* rls_ns, double* batch_ns) {
  std::mt19937 rng(9);
  std::normal_distribution<double> jitter(0.0, 0.05);
  std::vector<Eigen::Vector2d> trail;
  for (int k = 0; k < steps; ++k) trail.emplace_back(0.13 * k + jitter(rng), 0.05 * k + jitter(rng));
  objects::PredictorParams params;
  objects::RlsPathPredictor rls(params);
  auto t0 = Clock::now();
  for (int k = 0; k < steps; ++k) rls.Update(0.1 * k, trail[static_cast<std::size_t>(k)]);
  *rls_ns = 1000.0 * Us(Clock::now() - t0) / steps;
  volatile double sink = 0.0;
  t0 = Clock::now();
  for (int k = 0; k < steps; ++k) {
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Matrix2d b = Eigen::Matrix2d::Zero();
    double w = 1.0;
    for (int i = k; i >= 0; --i, w *= params.forgetting) {
      const Eigen::Vector2d phi(1.0, 0.1 * (i - k));
      A += w * phi * phi.transpose();
      b += w * phi * trail[static_cast<std::size_t>(i)].transpose();
    }
    if (k >= 1) sink = sink + A.ldlt().solve(b)(1, 0);
  }
  *batch_ns = 1000.0 * Us(Clock::now() - t0) / steps;
}

void Run(const Options& o) {
  if (o.frames < 20) Fail("--frames " + std::to_string(o.frames) + ": need at least 20");
  const objects::Atlas atlas =
      objects::Atlas::Load(o.atlas.empty() ? objects::Atlas::DefaultPath() : o.atlas);
  struct Row {
    int n;
    double rls_us, cv_us, log_us;
  };
  std::vector<Row> rows;
  const int counts[] = {1, 10, 100};
  Progress progress("bench objects", 4);
  int done = 0;
  for (int n : counts) {
    std::vector<double> log_us;
    const double rls = Median(TimeTracker(atlas, n, o.frames, objects::PredictorKind::kRls, &log_us));
    const double cv = Median(TimeTracker(atlas, n, o.frames, objects::PredictorKind::kConstantVelocity, nullptr));
    rows.push_back({n, rls, cv, Median(log_us)});
    progress.Update(static_cast<std::uint64_t>(++done), std::to_string(n) + " pedestrians");
  }
  double rls_ns = 0, batch_ns = 0;
  TimeRls(2000, &rls_ns, &batch_ns);
  progress.Finish();
  if (o.json) {
    std::printf("{\"frames\": %d, \"tracker\": [", o.frames);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      std::printf("%s{\"pedestrians\": %d, \"rls_us_per_frame\": %.1f, \"cv_us_per_frame\": %.1f, "
                  "\"ratio_rls_vs_cv\": %.3f, \"log_us_per_frame\": %.1f}",
                  i ? ", " : "", rows[i].n, rows[i].rls_us, rows[i].cv_us, rows[i].rls_us / rows[i].cv_us,
                  rows[i].log_us);
    }
    std::printf("], \"rls_update_ns\": %.1f, \"batch_refit_ns\": %.1f, \"ratio_rls_vs_batch\": %.4f}\n",
                rls_ns, batch_ns, rls_ns / batch_ns);
    return;
  }
  std::printf("tracker + path prediction per frame (median of %d frames, 10 Hz synthetic walkers)\n",
              o.frames - 5);
  std::printf("  %-12s %14s %14s %10s %16s\n", "pedestrians", "RLS paths us", "CV paths us",
              "RLS/CV", "log+encode us");
  for (const Row& r : rows) {
    std::printf("  %-12d %14.1f %14.1f %10.2f %16.1f\n", r.n, r.rls_us, r.cv_us, r.rls_us / r.cv_us,
                r.log_us);
  }
  std::printf("RLS update per step: %.1f ns; batch weighted LS refit over the trail (2000 steps): "
              "%.1f ns per step (RLS/batch %.4f)\n",
              rls_ns, batch_ns, rls_ns / batch_ns);
}

void Register(CLI::App& root) {
  CLI::App& bench = CommandGroup(root, "bench", "Measure romo's speed against named baselines");
  auto options = std::make_shared<Options>();
  CLI::App* cmd = bench.add_subcommand(
      "objects", "Tracker + path prediction per frame (1/10/100 pedestrians), RLS update per step");
  cmd->add_option("--frames", options->frames, "Frames per scene")->capture_default_str();
  cmd->add_option("--atlas", options->atlas, "Atlas YAML (default: config/atlas.yaml)");
  cmd->add_flag("--json", options->json, "Print one JSON object");
  cmd->callback([options] { Run(*options); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
