// Shared machinery of the learned rewards (rnd, icm, disagreement): features and their running
// normalisation, the per-env previous state, a buffer of recent samples, minibatch training and
// checkpointing. Each reward supplies its networks, its per-sample reward and its loss.
//
// Per step, for the vector's N envs:
//   s'_i = RunningNorm(features of observation(i))   (the statistics first take the step's rows in)
//   valid_i = the step is a transition of env i (not an autoreset, and s_i is known)
//   raw_i = score(s_i, a_i, s'_i)                     (reward-specific, no gradient)
//   reward_i = raw_i / std(raw)                       (running std of every raw reward so far)
// and (s_i, a_i, s'_i) joins the sample buffer, a ring of the most recent `buffer` samples.
// Transition rewards (icm, disagreement) give an invalid env 0 and store nothing for it; state
// rewards (rnd) need no s_i, so every env's s'_i is scored and stored.
// update() then runs min(max_steps, ceil(epochs x samples / batch)) Adam steps on minibatches
// drawn uniformly (with replacement, from a generator seeded by `seed`) from the buffer, and
// empties it: every update trains on what compute() saw since the last one.
//
// Networks run on the CPU in float32. Weights are drawn from a generator seeded by `seed`
// (uniform in +-1/sqrt(fan_in), like torch's default Linear init), so runs repeat. Checkpoints
// hold the networks, the optimisers and the running statistics, not the sample buffer or the
// minibatch generator (save after update(), when the buffer is empty anyway).
//
// Cost: the MLPs are compute-bound even at a few envs (OpenBLAS matrix products); Debian's
// OpenBLAS starts its own threads, which contend with the env workers: OPENBLAS_NUM_THREADS=1
// made these rewards about 30% cheaper on 2 cores.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <random>
#include <span>
#include <vector>

#include "learn/intrinsic/features.h"
#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

struct LearnedOptions {
  Features::Options features;   // what the state vector holds
  int hidden = 128;             // units in each of the two hidden layers of every MLP
  double learning_rate = 1e-3;  // Adam
  int batch = 256;              // minibatch size
  double epochs = 2;            // passes over the buffer per update (in expectation)
  int max_steps = 256;          // cap on Adam steps per update
  int buffer = 16384;           // samples kept between updates (most recent)
  double clip = 5;              // normalised features clipped to +-clip
  std::uint64_t seed = 1;       // weight init and minibatch draws
};

// A two-hidden-layer ReLU MLP: in -> hidden -> hidden -> out, weights from `gen`.
torch::nn::Sequential make_mlp(int in, int hidden, int out, at::Generator& gen);

class LearnedReward : public IntrinsicReward {
 public:
  LearnedReward(double scale, LearnedOptions options);

  void bind(const VecEnv& env) override;
  void reset(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;
  void update() override;
  void save(const std::filesystem::path& dir) const override;
  void load(const std::filesystem::path& dir) override;

  int feature_size() const { return features_.size(); }
  // Raw (unnormalised) rewards of each env's last compute(), by env id.
  std::span<const double> last_raw() const { return last_raw_; }
  // Samples waiting for the next update().
  int buffered() const { return filled_; }
  // Mean loss of the last update() (0 before any).
  double last_loss() const { return last_loss_; }

 protected:
  // Whether a sample is a transition (s, a, s') or a state s' alone.
  virtual bool transitions() const = 0;
  // Builds networks and optimisers for `features` inputs and `actions` action values.
  virtual void build(int features, int actions, at::Generator& gen) = 0;
  // Per-row raw reward [rows] (called under NoGradGuard).
  virtual torch::Tensor score(const torch::Tensor& s, const torch::Tensor& a,
                              const torch::Tensor& next) = 0;
  // One optimiser step; draw() returns a fresh minibatch of the buffer (ensembles draw one per
  // member). Returns the loss.
  struct Batch {
    torch::Tensor s, a, next;  // [batch x features], [batch x actions], [batch x features]
  };
  virtual double train_step(const std::function<Batch()>& draw) = 0;
  // Checkpoint the networks and optimisers.
  virtual void save_models(torch::serialize::OutputArchive& archive) const = 0;
  virtual void load_models(torch::serialize::InputArchive& archive) = 0;

  const LearnedOptions& options() const { return options_; }

 private:
  void observe(const VecEnv& env, std::vector<float>& rows);
  std::filesystem::path file(const std::filesystem::path& dir, const char* ext) const;

  LearnedOptions options_;
  Features features_;
  RunningNorm norm_;
  RunningStd reward_std_;
  int action_size_ = 0;
  bool bound_ = false;
  at::Generator gen_;
  std::mt19937_64 draw_;
  // Per env id: the previous normalised features (num_envs x features) and episode starts;
  // next_: this call's features, per slot.
  std::vector<float> prev_, next_;
  detail::EpisodeStarts starts_;
  std::vector<double> last_raw_;
  // Sample ring, row-major: states, actions, next states (`buffer` rows each) and its fill.
  std::vector<float> buf_s_, buf_a_, buf_next_;
  int filled_ = 0, head_ = 0;
  double last_loss_ = 0;
};

}  // namespace cradle::learn::intrinsic
