// The `cradle` subcommands: each file under apps/ registers one with the CLI.
#pragma once

#include <CLI/CLI.hpp>

namespace cradle::apps {

void register_build_scene(CLI::App& app);
void register_model_info(CLI::App& app);
void register_bench(CLI::App& app);
void register_random(CLI::App& app);
void register_evaluate(CLI::App& app);
void register_test_installation(CLI::App& app);
void register_train(CLI::App& app);
void register_illustrate(CLI::App& app);
void register_tma(CLI::App& app);
void register_tma_campaign(CLI::App& tma);  // under `tma`: campaign, analyze
void register_campaign(CLI::App& app);      // campaigns of every kind of run
void register_sami(CLI::App& app);
void register_launch(CLI::App& app);
void register_soak(CLI::App& app);
void register_envs(CLI::App& app);

}  // namespace cradle::apps
