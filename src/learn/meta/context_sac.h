// SAC with contexts (tma_sami.md §6): the SaMI learner behind TESAC, CCM, SaTESAC, SaCCM and
// SaCCMAll. Policy and critics read [observation, c_t]; c_t comes from the LSTM context encoder
// over the trajectory so far. One gradient step:
//   B trajectories (B / envs from each training env); c = online encoder over each whole
//   trajectory, c' = target encoder (no gradient); transitions t < len
//   SAC (learn/sac.h formulas): alpha step; y from the target critics at (o_{t+1}, c'_{t+1});
//   critic loss back-propagated into the critics *and the encoder* (both optimisers step);
//   the actor on the detached c_t; critic targets by Polyak tau
//   the method's contrastive step (samplers.h): one encoder step on w * SaNCE
//   encoder target by Polyak encoder_tau.
// Defaults are SaMI's (MuJoCo configs); the trainer sets the Panda ones.
#pragma once

#include <torch/torch.h>

#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "learn/grad_sync.h"
#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/meta/context_encoder.h"
#include "learn/meta/samplers.h"
#include "learn/meta/trajectory_replay.h"
#include "learn/networks.h"
#include "learn/off_policy.h"

namespace cradle::learn::meta {

struct SamiConfig {
  double learning_rate = 1e-3;               // actor, critic, encoder and alpha (Adam)
  double gamma = 0.95;                       // discount
  double tau = 0.05;                         // critic target Polyak
  double encoder_tau = 0.05;                 // encoder target Polyak
  int buffer_size = 100;                     // trajectories per training env (Panda 1000)
  int batch_size = 16;                       // trajectories per RL batch (Panda 256)
  int contrast_batch_size = 16;              // trajectories per contrastive batch (Panda 256)
  int train_freq = 128;                      // vector steps between trainings
  int gradient_steps = 16;                   // gradient steps per training
  long learning_starts = 2000;               // random env steps per training env before training
  std::vector<int> net_arch{512, 512, 512};  // actor and critic MLPs
  int lstm_hidden = 128;                     // context encoder LSTM units
  int context_size = 6;                      // c_t dimensions
  double temperature = 0.1;                  // InfoNCE temperature
  double neg_ratio = 0.5;                    // share of negatives in the contrastive batch
  double adversarial_loss_coef = 0.01;       // lambda of the SaNCE weight
  bool use_weighted_info_nce = false;        // keys mapped by the 6 x 6 matrix W
  int update_threads = 0;                    // LibTorch threads in updates (0: as set)
  void bind(Hyperparameters& table);
  void check() const;  // UserError naming a bad value
};

// Parses "name=value" overrides over `config` (strictly; UserError for an unknown name or bad
// value) and returns the full "name = value" text.
std::string apply_sami_hyperparameters(SamiConfig& config,
                                       const std::map<std::string, std::string>& overrides);

class ContextActorImpl : public torch::nn::Module {
 public:
  ContextActorImpl(int input, int action_size, const std::vector<int>& layers,
                   at::Generator& generator);
  torch::Tensor mean_action(const torch::Tensor& input);
  std::pair<torch::Tensor, torch::Tensor> sample(const torch::Tensor& input,
                                                 at::Generator& generator);

 private:
  torch::nn::Sequential latent_{nullptr};
  torch::nn::Linear mean_{nullptr}, log_std_{nullptr};
};
TORCH_MODULE(ContextActor);

class ContextSac {
 public:
  // Throws UserError for a bad config.
  ContextSac(std::string method, int obs_size, int action_size, const SamiConfig& config,
             std::uint64_t seed);

  const std::string& method() const { return method_; }
  Contrast contrast() const { return contrast_; }
  const SamiConfig& config() const { return config_; }
  int obs_size() const { return obs_size_; }
  int action_size() const { return action_size_; }
  long updates() const { return updates_; }

  struct Losses {
    double critic = 0, actor = 0, alpha = 0, alpha_loss = 0, entropy = 0;
    double sance = std::numeric_limits<double>::quiet_NaN();  // NaN: no contrastive step
    double weight = 0;
  };
  // One gradient step; every env of the replay must hold a complete trajectory.
  Losses update(const TrajectoryReplay& replay, Rng& rng);

  // Acting state of N streams: the LSTM's (h, c) and the previous actions.
  struct Streams {
    std::pair<torch::Tensor, torch::Tensor> state;  // each [1, N, hidden]
    torch::Tensor prev_actions;                     // [N, action]
    void reset(int row);                            // a new episode in stream `row`
  };
  Streams streams(int count) const;
  // Actions in [-1, 1] for observations [N, obs] (float32); advances the streams and returns
  // {actions [N, action], contexts [N, context]}.
  std::pair<torch::Tensor, torch::Tensor> act(const torch::Tensor& observations, Streams& streams,
                                              bool deterministic);

  ContextEncoder& encoder() { return encoders_.online; }
  EncoderPair& encoders() { return encoders_; }
  at::Generator& generator() { return generator_; }
  // Data-parallel ranks (null: alone): every gradient is averaged over them before its optimiser
  // steps, and the contrastive step runs on every rank when it runs on any (learn/grad_sync.h's
  // contract). The caller keeps `sync` alive and shares rank 0's parameters.
  void set_sync(GradSync* sync) { sync_ = sync; }

  // Sealed checkpoint (learn/checkpoint.h) of everything; `steps` goes into the header.
  void save(const std::filesystem::path& file, long steps) const;
  // Returns the saved steps; UserError for another method or shapes.
  long load(const std::filesystem::path& file);
  // The body of those checkpoints, for a learner that stores ContextSac beside parts of its own
  // under its own header (learn/meta/sami_learner.h). read() checks every module's shape
  // (UserError; nothing changes) and returns the copy, to run on the same archive once the
  // learner's own parts have passed their checks too.
  void write(torch::serialize::OutputArchive& archive) const;
  std::function<void()> read(torch::serialize::InputArchive& archive);

  // Every trained tensor (actor, critics and their target, both encoders, W, log alpha), e.g.
  // for learn/grad_sync.h's tensor_hash.
  std::vector<torch::Tensor> parameters() const;

 private:
  std::string method_;
  Contrast contrast_;
  SamiConfig config_;
  std::string text_;
  int obs_size_, action_size_;
  at::Generator generator_;
  EncoderPair encoders_;
  ContextActor actor_;
  Critic critic_, critic_target_;
  PackedParameters actor_parameters_, critic_parameters_, target_parameters_;
  torch::optim::Adam actor_optimizer_, critic_optimizer_;
  torch::Tensor log_alpha_;
  torch::optim::Adam alpha_optimizer_;
  double target_entropy_;
  long updates_ = 0;
  GradSync* sync_ = nullptr;
};

}  // namespace cradle::learn::meta
