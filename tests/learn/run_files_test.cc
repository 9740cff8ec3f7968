// Tests for a run's files on resume: the training log and progress.csv cut back to a
// checkpoint, with what was cut kept aside and torn last lines repaired.
#include "learn/run_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "learn/intrinsic/reward.h"
#include "learn/learner.h"
#include "learn/registry.h"
#include "test_tasks.h"

namespace cradle::learn {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("cradle_run_files_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

TEST(RunFiles, TrainingLogCutToCheckpointEpisodesKeepsRestAside) {
  const fs::path dir = fresh_dir("log");
  const fs::path log = dir / "training.jsonl";
  write_text(log, "{\"steps\":0}\n{\"steps\":100}\n{\"steps\":100}\n{\"steps\":7}\n{\"ste");
  EXPECT_EQ(cut_training_log(log, 2), 2);
  EXPECT_EQ(read_text(log), "{\"steps\":0}\n{\"steps\":100}\n");
  EXPECT_EQ(read_text(dir / "training.after-checkpoint.jsonl"),
            "{\"steps\":100}\n{\"steps\":7}\n{\"ste\n");
  // Nothing past the checkpoint: unchanged; a log shorter than the checkpoint says: all kept.
  EXPECT_EQ(cut_training_log(log, 2), 2);
  EXPECT_EQ(cut_training_log(log, 5), 2);
  EXPECT_EQ(read_text(log), "{\"steps\":0}\n{\"steps\":100}\n");
  EXPECT_EQ(cut_training_log(log, 0), 0);
  EXPECT_EQ(read_text(log), "");
}

TEST(RunFiles, ProgressCutToCheckpointStepRepairsTornLine) {
  const fs::path dir = fresh_dir("csv");
  const fs::path csv = dir / "progress.csv";
  const std::string header = "global_step,time,x";
  write_text(csv, header + "\n128,1,\n256,2,0.5\n384,3,1\n512,4");
  ProgressCut cut = cut_progress(csv, header, 256);
  EXPECT_TRUE(cut.append);
  EXPECT_EQ(read_text(csv), header + "\n128,1,\n256,2,0.5\n");
  ASSERT_EQ(cut.rows.size(), 2u);
  EXPECT_EQ(cut.rows[1][0], 256);
  EXPECT_EQ(cut.rows[1][2], 0.5);
  EXPECT_TRUE(std::isnan(cut.rows[0][2]));
  EXPECT_EQ(read_text(dir / "progress.after-checkpoint.csv"), header + "\n384,3,1\n512,4\n");
  // A second cut appends to the aside file without a second header.
  write_text(csv, header + "\n128,1,\n256,2,0.5\n640,5,1\n");
  cut = cut_progress(csv, header, 256);
  EXPECT_EQ(read_text(dir / "progress.after-checkpoint.csv"),
            header + "\n384,3,1\n512,4\n640,5,1\n");
  // Other columns: the whole file is kept aside, a new one starts.
  cut = cut_progress(csv, "global_step,other", 256);
  EXPECT_FALSE(cut.append);
  EXPECT_FALSE(fs::exists(csv));
  EXPECT_TRUE(fs::exists(dir / "progress.before-resume.csv"));
  // No file: a new one.
  EXPECT_FALSE(cut_progress(csv, header, 256).append);
}

// A reward whose whole state is one number, saved as one file.
class CounterReward final : public intrinsic::IntrinsicReward {
 public:
  CounterReward() : IntrinsicReward(1.0) {}
  std::string_view name() const override { return "counter"; }
  void compute(const VecEnv&, std::span<const double>, std::span<double>) override {}
  void save(const fs::path& dir) const override {
    std::ofstream(dir / "intrinsic_counter.txt") << count;
  }
  void load(const fs::path& dir) override {
    std::ifstream in(dir / "intrinsic_counter.txt");
    if (!(in >> count)) throw UserError("intrinsic_counter.txt missing");
  }
  long count = 0;
};

// The intrinsic state round-trips through the checkpoint, staged outside the checkpoint folder,
// and a staging folder an older build left beside the checkpoint (killed mid-save) is swept away.
TEST(RunFiles, IntrinsicStateRoundTripsAndLeavesNoStagingFolder) {
  const fs::path dir = fresh_dir("staging");
  const fs::path file = dir / "latest.ckpt";
  fs::create_directories(dir / "latest.ckpt.intrinsic.4242");
  write_text(dir / "latest.ckpt.intrinsic.4242" / "intrinsic_counter.txt", "7");
  auto env = testing::make_cartpoles(1, 30);
  auto learner = make_learner("ppo", *env, {});
  CounterReward saved;
  saved.count = 123456789;
  save_run_checkpoint(file, *learner, &saved,
                      {.steps = 64, .episodes = 2, .intrinsic = "counter:1"});
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  EXPECT_EQ(names, std::vector<std::string>{"latest.ckpt"});
  CounterReward loaded;
  const RunState state = load_run_state(file, &loaded);
  EXPECT_EQ(loaded.count, 123456789);
  EXPECT_EQ(state.steps, 64);
  EXPECT_EQ(state.episodes, 2);
  EXPECT_EQ(state.intrinsic, std::optional<std::string>("counter:1"));
  names.clear();
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  EXPECT_EQ(names, std::vector<std::string>{"latest.ckpt"});
}

TEST(RunFiles, NonFiniteLossIsOneLineErrorNamingTheUpdate) {
  TrainStats stats{.steps = 384};
  stats.losses = {{"policy_loss", 0.5}, {"explained_variance", std::nan("")}};
  EXPECT_NO_THROW(check_finite_losses(stats, "/nonexistent/latest.ckpt"));
  stats.losses["value_loss"] = std::nan("");
  try {
    check_finite_losses(stats, "/nonexistent/latest.ckpt");
    FAIL() << "a NaN loss passed";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("step 384"), std::string::npos) << message;
    EXPECT_NE(message.find("value_loss"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// Every learner refuses out-of-range and non-finite hyperparameters with one line.
TEST(HyperparameterRanges, EveryLearnerRefusesBadValues) {
  auto env = testing::make_cartpoles(1, 30);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"learning_rate", "-1"}, {"learning_rate", "nan"}, {"learning_rate", "inf"},
      {"learning_rate", "0"},  {"gamma", "2"},           {"gamma", "-0.1"},
      {"batch_size", "0"},     {"pi_layers", "64,0"},    {"log_std_init", "1e9"}};
  for (const char* algo : {"ppo", "a2c", "sac", "td3", "ddpg"}) {
    for (const auto& [name, value] : bad) {
      if (std::string(algo) == "a2c" && name == "batch_size") continue;  // A2C has none
      try {
        make_learner(algo, *env, {.hyperparameters = {{name, value}}});
        ADD_FAILURE() << algo << " accepted " << name << "=" << value;
      } catch (const UserError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      }
    }
  }
  for (const auto& [name, value] :
       std::vector<std::pair<std::string, std::string>>{{"clip_range", "-1"},
                                                        {"max_grad_norm", "-1"},
                                                        {"vf_coef", "-1e9"},
                                                        {"ent_coef", "inf"},
                                                        {"gae_lambda", "1.5"},
                                                        {"n_epochs", "0"},
                                                        {"batch_size", "4096"}}) {
    EXPECT_THROW(make_learner("ppo", *env, {.hyperparameters = {{name, value}}}), UserError)
        << name << "=" << value;
  }
  try {
    make_learner("ppo", *env, {.hyperparameters = {{"gamma", "2"}}});
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), "hyperparameter 'gamma' = 2: expected 0 <= gamma <= 1");
  }
}

}  // namespace
}  // namespace cradle::learn
