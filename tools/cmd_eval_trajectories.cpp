// `romo eval trajectories`: RLS path prediction vs the constant-velocity baseline on an ETH/UCY
// trajectory file (ADE/FDE over every window of obs + pred steps).
#include <cstdio>
#include <string>

#include "cli/command_registry.hpp"
#include "romo/core/json.hpp"
#include "romo/core/check.hpp"
#include "romo/objects/trajectory_eval.hpp"

namespace romo::tools {
namespace {

struct Options {
  std::string file;
  std::string format = "ethucy";
  int obs = 8;
  int pred = 12;
  double frame_step = 0.0;
  double step_s = 0.4;
  double forgetting = objects::PredictorParams{}.forgetting;
  bool strict = false;
  bool json = false;
};

void Run(const Options& o) {
  if (o.format != "ethucy") Fail("--format: unknown trajectory format '" + o.format + "' (ethucy)");
  const objects::TrajectorySet set = objects::ReadEthUcy(o.file, o.strict);
  objects::WindowParams window;
  window.obs = o.obs;
  window.pred = o.pred;
  window.frame_step = o.frame_step;
  window.step_s = o.step_s;
  objects::PredictorParams rls;
  rls.forgetting = o.forgetting;
  const objects::TrajectoryEvalResult r = objects::EvaluateTrajectories(set, window, rls);
  // Skipped rows are reported on stderr so --json output stays exactly the documented object.
  if (set.skipped_total() > 0 || set.pedestrians_seen_once > 0) {
    std::fprintf(stderr,
                 "romo: %s: skipped %lld rows (malformed %lld, non-finite %lld, duplicate %lld); "
                 "%lld pedestrians seen once\n",
                 o.file.c_str(), static_cast<long long>(set.skipped_total()),
                 static_cast<long long>(set.skipped_malformed),
                 static_cast<long long>(set.skipped_nonfinite),
                 static_cast<long long>(set.skipped_duplicate),
                 static_cast<long long>(set.pedestrians_seen_once));
    for (const auto& note : set.notes) std::fprintf(stderr, "  %s\n", note.c_str());
  }
  if (o.json) {
    std::printf("{\"file\": %s, \"windows\": %lld, \"romo\": {\"ade\": %.4f, \"fde\": %.4f}, "
                "\"cv\": {\"ade\": %.4f, \"fde\": %.4f}}\n",
                JsonString(o.file).c_str(), static_cast<long long>(r.windows), r.romo.ade_m,
                r.romo.fde_m, r.cv.ade_m, r.cv.fde_m);
    return;
  }
  std::printf("file      %s\n", o.file.c_str());
  std::printf("windows   %lld (obs %d, pred %d, frame step %g, %.3g s per step)\n",
              static_cast<long long>(r.windows), o.obs, o.pred, r.frame_step, o.step_s);
  std::printf("rows      %lld used, %lld skipped, %lld pedestrians seen once\n",
              static_cast<long long>(set.rows_used), static_cast<long long>(set.skipped_total()),
              static_cast<long long>(set.pedestrians_seen_once));
  std::printf("romo RLS  ADE %.3f m  FDE %.3f m  (forgetting %.3g)\n", r.romo.ade_m, r.romo.fde_m,
              o.forgetting);
  std::printf("CV        ADE %.3f m  FDE %.3f m\n", r.cv.ade_m, r.cv.fde_m);
}

void Register(CLI::App& root) {
  CLI::App& eval = CommandGroup(root, "eval", "Score romo's outputs against ground truth");
  auto options = std::make_shared<Options>();
  CLI::App* cmd = eval.add_subcommand(
      "trajectories", "RLS path prediction vs constant velocity (ADE/FDE) on a trajectory file");
  cmd->add_option("--file", options->file, "Trajectory file (ETH/UCY: frame ped_id x y)")
      ->required();
  cmd->add_option("--format", options->format, "File format (ethucy)")->capture_default_str();
  cmd->add_option("--obs", options->obs, "Observed steps per window")->capture_default_str();
  cmd->add_option("--pred", options->pred, "Predicted steps per window")->capture_default_str();
  cmd->add_option("--frame-step", options->frame_step,
                  "Frame-number difference of one step (0: most common in the file)")
      ->capture_default_str();
  cmd->add_option("--step-s", options->step_s, "Seconds per step")->capture_default_str();
  cmd->add_option("--forgetting", options->forgetting, "RLS forgetting factor (0, 1]")
      ->capture_default_str();
  cmd->add_flag("--strict", options->strict, "Fail on the first bad row instead of skipping it");
  cmd->add_flag("--json", options->json, "Print one JSON object");
  cmd->callback([options] { Run(*options); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
