// `romo eval scene --log OUT.lcmlog [--log ...] [--json]`: a run's outputs against the simulator's
// truth; several runs (seeds) pooled into one score.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "romo/pipeline/scene_eval.hpp"

namespace romo::tools {
namespace {
struct EvalSceneOptions {
  std::vector<std::string> logs;
  bool json = false;
  bool misses = false;
  double range_m = 15.0;
};
}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<EvalSceneOptions>();
  CLI::App& eval = CommandGroup(root, "eval", "Score romo against references and ground truth");
  CLI::App* cmd = eval.add_subcommand("scene", "Score a run's outputs log against the simulator's ground truth");
  cmd->add_option("--log", opts->logs,
                  "outputs.lcmlog of `romo run` / `romo replay` of a simulated scene; several (one --log each, or "
                  "a list) are pooled: counts summed, medians over all")
      ->required()
      ->expected(1, -1);
  cmd->add_flag("--json", opts->json, "print one JSON object");
  cmd->add_flag("--misses", opts->misses, "also list each visible car or pedestrian missed, and what was nearest");
  cmd->add_option("--range", opts->range_m, "score objects within this range of the ego, m")->capture_default_str();
  cmd->callback([opts] {
    pipeline::SceneEvalParams p;
    p.range_m = opts->range_m;
    const pipeline::SceneEval e = pipeline::EvaluateSceneLogs(opts->logs, p);
    std::printf("%s\n", opts->json ? e.ToJson().c_str() : e.ToText().c_str());
    if (opts->misses) std::printf("%s", e.MissesText().c_str());
  });
});

}  // namespace romo::tools
