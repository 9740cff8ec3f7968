// `cradle random --config FILE --train_for N [--seed S]`: the reference's random baselines
// (random_selftouch / random_handregard): a random policy for N steps in training mode, writing
// scene.xml and the training log; prints the resulting training-log score.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "core/config.h"
#include "core/jsonl.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "eval/scores.h"

namespace cradle::apps {

void register_random(CLI::App& app) {
  struct Options {
    std::string config;
    std::string save_dir;
    long train_for = 10000;
    std::uint64_t seed = 0;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd =
      app.add_subcommand("random", "Random-policy baseline in training mode (writes the log)");
  cmd->add_option("--config", opts->config, "BabyBench YAML config")->required();
  cmd->add_option("--out,--save-dir", opts->save_dir,
                  "Output folder (default: the config's save_dir)");
  cmd->add_option("--train_for,--train-for", opts->train_for, "Env steps to run")
      ->check(CLI::Range(1L, 1000000000L));
  cmd->add_option("--seed", opts->seed, "Seed of the env and the random policy")->check(kSeed);
  cmd->callback([opts] {
    Config config = load_config(opts->config);
    if (!opts->save_dir.empty()) config.save_dir = opts->save_dir;
    auto env = envs::make_env(config, /*training=*/true, opts->seed);
    // The reference examples reset twice before training; one reset is enough here (the log
    // then starts with one 0-step entry).
    env->reset(opts->seed);
    const Box& space = env->action_space();
    std::vector<double> action(space.size());
    Rng rng(opts->seed + 1);
    for (long t = 0; t < opts->train_for; ++t) {
      space.sample(rng, action);
      const envs::StepResult r = env->step(action);
      if (r.terminated || r.truncated) env->reset();
    }
    env->close();
    const std::filesystem::path log =
        std::filesystem::path(config.save_dir) / "logs" / "training.jsonl";
    const auto entries = read_jsonl(log);
    std::printf("random policy: %ld steps, %zu log entries in %s\n", opts->train_for,
                entries.size(), log.c_str());
    if (const auto score = eval::training_score(config.behavior, entries)) {
      std::printf("training score (%s): %.4f\n",
                  std::string(behavior_name(config.behavior)).c_str(), *score);
    }
    if (config.behavior == Behavior::kHandRegard) {
      if (const auto hr = eval::hand_regard_score(entries)) {
        std::printf("hand regard, either hand in view of each eye: %.4f\n", hr->either);
      }
    }
  });
}

}  // namespace cradle::apps
