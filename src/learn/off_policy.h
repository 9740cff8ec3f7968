// What SAC, TD3 and DDPG share (SB3's OffPolicyAlgorithm): the settings of the replay loop,
// the networks' sizes, the Q critics, Polyak averaging, and the learner skeleton that collects
// transitions, trains every train_freq vector steps, reports, acts and checkpoints. Each
// algorithm's file holds its actor and its update, the part the papers are about.
//
// The loop (SB3 semantics, counted in env steps = vector steps x num_envs):
//   while steps < total_steps:
//     a = uniform in [-1, 1] while steps < learning_starts, else the algorithm's exploration
//     step the envs with a rescaled to the Box; store the real transitions
//     every train_freq vector steps, once the buffer holds more than learning_starts
//     transitions: gradient_steps updates on minibatches of batch_size
//   reporting every report_every vector steps.
// With overlap_collection the two halves run at once, in cycles of train_freq vector steps:
//   handoff (both idle): merge the collector's staged transitions into the buffer, count them,
//     refresh the collector's actor copy (every actor_refresh updates), report and checkpoint;
//   then, concurrently: the collector thread steps the envs train_freq vector steps with the
//     copy (its own generator) into a staging buffer, while the learner does the gradient
//     steps the merged ones call for (gradient_steps per train_freq vector steps, as above).
// Everything shared (envs, normaliser, staging, copy, counters) changes hands only at the
// handoff, under a mutex: no data race. The collector acts with an actor one cycle older than
// the synchronous loop's (gradient_steps updates; distributed SAC's stale actors); the cycle's
// length is max(collect, update) instead of their sum.
// Training waits on the buffer's size rather than the step counter so that a resumed run,
// whose buffer starts empty (it is not saved), refills it before training again; it acts
// with its loaded policy meanwhile. A fresh run trains from the same step as SB3's.
#pragma once

#include <torch/torch.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "learn/grad_tensors.h"
#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/networks.h"
#include "learn/preprocess.h"
#include "learn/replay_buffer.h"

namespace cradle::learn {

// The replay loop's settings; each algorithm sets its SB3 defaults before binding.
struct OffPolicyConfig {
  double learning_rate = 3e-4;   // Adam step size of every network (and SAC's temperature)
  long buffer_size = 1'000'000;  // replay capacity in transitions
  long learning_starts = 100;    // transitions collected (random actions) before training
  int batch_size = 256;          // minibatch size
  double tau = 0.005;            // Polyak coefficient of the target networks
  double gamma = 0.99;           // discount factor
  int train_freq = 1;            // vector steps between trainings (SB3 train_freq, "step")
  int gradient_steps = 1;        // updates per training
  // > 0: train only when an episode ends, ceil(its length / episode_train_freq) updates
  // (SpinningUp's SAC, TeachMyAgent's student: 10); train_freq and gradient_steps are then unused.
  int episode_train_freq = 0;
  int report_every = 1000;  // vector steps between progress reports (not SB3)
  // Collection on its own thread while the learner updates (see OffPolicyLearner): the
  // collector acts with a copy of the actor refreshed every actor_refresh gradient steps (at the
  // first handoff after them). Same number of gradient steps per env step as without; off by
  // default: runs with it are not bitwise the runs without it.
  bool overlap_collection = false;
  int actor_refresh = 1;
  void bind(Hyperparameters& table);
  void check(std::string_view algorithm) const;  // UserError for a bad value
};

// Network sizes (SB3's off-policy defaults: net_arch [256, 256], ReLU, no orthogonal init).
struct OffPolicyNetworkConfig {
  std::vector<int> pi_layers{256, 256};  // actor MLP hidden sizes (SB3 net_arch pi)
  std::vector<int> qf_layers{256, 256};  // each critic's MLP hidden sizes (SB3 net_arch qf)
  std::string activation = "relu";       // "relu" or "tanh" (SB3 activation_fn, nn.ReLU)
  int cnn_features = 256;                // NatureCNN output size per image (SB3 features_dim)
  void bind(Hyperparameters& table);
  void check(std::string_view algorithm) const;  // UserError for an empty layer list
};

// n Q(s, a) networks on one encoder of their own (SB3 ContinuousCritic with
// share_features_extractor=False): Q_i = MLP_i([encoder(s), a]) -> 1. The n MLPs are fused:
// layer l of every Q is one weight [n, in, out] and one bias [n, 1, out] (Q_i's Linear has
// weight[i]^T and bias[i]), so each layer of all the critics is one batched matmul (baddbmm)
// instead of n, forwards and backwards. Same maths as n separate MLPs; same initial values
// too (drawn in the order separate Linear layers draw them).
class CriticImpl : public torch::nn::Module {
 public:
  CriticImpl(const ObsShape& shape, int action_size, int critics,
             const OffPolicyNetworkConfig& config, at::Generator& generator);
  // [critics, B]: every Q of (observation, actions).
  torch::Tensor forward(const ObsBatch& observation, const torch::Tensor& actions);
  // [B]: the first Q only (TD3's actor loss).
  torch::Tensor q1(const ObsBatch& observation, const torch::Tensor& actions);
  int critics() const { return critics_; }
  // Layer l of every Q: weight [critics, in, out] and bias [critics, 1, out].
  const torch::Tensor& weight(size_t layer) const { return weights_[layer]; }
  const torch::Tensor& bias(size_t layer) const { return biases_[layer]; }
  size_t layers() const { return weights_.size(); }

 private:
  torch::Tensor activate(const torch::Tensor& x) const;

  MultiInputEncoder encoder_{nullptr};
  std::vector<torch::Tensor> weights_, biases_;
  int critics_ = 0;
  bool relu_ = true;
};
TORCH_MODULE(Critic);

// Refuses (UserError naming both formats) a checkpoint whose critic `key` holds the separate
// critic MLPs of builds before the fused critics (children q1, q2, ...).
void check_critic_format(torch::serialize::InputArchive& archive, const std::string& key);

// A network's parameters packed (PackedParameters) with a target copy of the same layout.
// target <- tau * online + (1 - tau) * target is then one operation on two tensors.
void polyak_update(torch::Tensor& target, const torch::Tensor& online, double tau);

// Every setting of an off-policy learner: the algorithm's own (`Own`, with a bind(table)), the
// loop's, the networks' and the observation's, parsed strictly from LearnerOptions.
template <typename Own>
struct OffPolicySettings {
  Own own;
  OffPolicyConfig loop;
  OffPolicyNetworkConfig networks;
  ObservationConfig observation;
  std::string text;  // every value, "name = value" lines
};

// Binds every setting (defaults: `own` and `loop` as given), applies the overrides and checks
// the loop's values. Throws UserError for an unknown name or a bad value.
template <typename Own>
OffPolicySettings<Own> parse_off_policy_settings(std::string_view algorithm,
                                                 const LearnerOptions& options, Own own,
                                                 OffPolicyConfig loop) {
  apply_torch_options(options);
  OffPolicySettings<Own> settings{.own = std::move(own), .loop = loop};
  Hyperparameters table;
  settings.own.bind(table);
  settings.loop.bind(table);
  settings.networks.bind(table);
  settings.observation.bind(table);
  table.apply(options.hyperparameters);
  settings.loop.check(algorithm);
  settings.networks.check(algorithm);
  settings.text = table.to_text();
  return settings;
}

// Turns off the gradients of a module's parameters for its lifetime: the critics scoring the
// actor's actions pass gradients to the actions only, which spares computing (and then
// discarding) their weights' gradients.
class FrozenParameters {
 public:
  explicit FrozenParameters(torch::nn::Module& module);
  ~FrozenParameters();
  FrozenParameters(const FrozenParameters&) = delete;
  FrozenParameters& operator=(const FrozenParameters&) = delete;

 private:
  std::vector<torch::Tensor> parameters_;
};

// The learner skeleton. An algorithm builds its networks and optimisers in its constructor,
// registers what its checkpoint holds, and implements the two methods below.
class OffPolicyLearner : public Learner {
 public:
  std::string_view algorithm() const override { return algorithm_; }
  long steps() const override { return steps_; }
  std::string config_text() const override { return text_; }
  void learn(long total_steps, const ProgressFn& on_progress) override;
  void save(const std::filesystem::path& file) const override;
  void load(const std::filesystem::path& file) override;
  void act(const envs::ObservationBuffers& observation, std::span<double> action,
           bool deterministic) override;
  std::uint64_t parameter_hash() const override;
  // `count` gradient steps on minibatches of the buffer as it stands, exactly as the loop takes
  // them (for benchmarks). UserError while the buffer is empty.
  void update(int count);
  // Floats of the preprocessed observation vector the networks read (pooled touch included).
  int observation_size() const { return pipeline_.shape().vector_size; }
  double value(const envs::ObservationBuffers& observation) override;

 protected:
  // Throws UserError for an action space without finite bounds or a replay buffer too large
  // for the machine.
  OffPolicyLearner(std::string algorithm, VecEnv& env, const LearnerOptions& options,
                   const OffPolicyConfig& loop, const ObservationConfig& observation,
                   std::string text);

  // Actions in [-1, 1] for the current observations: the behaviour policy (deterministic:
  // the policy's best guess, for evaluation). [rows, action_size].
  virtual torch::Tensor policy_action(const ObsBatch& observation, bool deterministic) = 0;
  // The value of each observation [rows] (Learner::value); undefined: the algorithm has none.
  virtual torch::Tensor state_value(const ObsBatch& /*observation*/) { return {}; }
  // One gradient step on a minibatch (observations already normalised). `update` counts the
  // updates since the start of training, this one included (TD3's delay).
  virtual void train(const ReplayBuffer::Sample& batch, long update) = 0;
  // overlap_collection: a copy of the acting network for the collector thread (`source`, the
  // learner's, and `copy` of the same layout, whose parameters the loop refreshes from it), and
  // the copy's exploration policy, policy_action(observation, false) drawing from `generator`.
  struct ActorCopy {
    torch::nn::Module* source = nullptr;
    std::shared_ptr<torch::nn::Module> copy;
    std::function<torch::Tensor(const ObsBatch& observation, at::Generator& generator)> explore;
  };
  // The default refuses (UserError naming the algorithm).
  virtual ActorCopy copy_actor();
  // A loss or diagnostic of an update; each report gives the mean of each name's values.
  void record(const std::string& name, double value);

  // What the checkpoint holds besides the normaliser, generator and counters.
  void checkpoint_module(std::string key, torch::nn::Module& module);
  void checkpoint_optimizer(std::string key, torch::optim::Optimizer& optimizer);
  void checkpoint_tensor(std::string key, torch::Tensor& tensor);

  const ObsShape& shape() const { return pipeline_.shape(); }
  int action_size() const { return env_.action_space().size(); }
  at::Generator& generator() { return generator_; }
  // The data-parallel ranks (null: alone); an algorithm averages every gradient over them.
  GradSync* sync() const { return sync_.get(); }

 private:
  // Whether to train at this step: the buffer holds more than learning_starts transitions (in a
  // data-parallel run, every rank's buffer, so that all start together).
  bool ready_to_train();
  // `count` gradient steps, minibatches normalised with `statistics`.
  void run_updates(int count, const RunningMeanStd& statistics);
  // learn() with overlap_collection.
  void learn_overlapped(long total_steps, const ProgressFn& on_progress);
  // The progress report of the steps since `start` (steps since `start_steps`).
  TrainStats report(std::chrono::steady_clock::time_point start, long start_steps,
                    double& collect_seconds, double& update_seconds);

  const std::string algorithm_;
  VecEnv& env_;
  const OffPolicyConfig config_;
  const ObservationConfig observation_;
  const std::string text_;  // every value, "name = value" lines
  at::Generator generator_;
  ObservationPipeline pipeline_;
  ReplayBuffer buffer_;
  TransitionCollector collector_;
  ObsBatch scratch_;  // one row, for act()
  const int update_threads_;
  const std::shared_ptr<GradSync> sync_;
  bool ready_ = false;  // data-parallel: every rank's buffer passed learning_starts
  long steps_ = 0, vector_steps_ = 0, updates_ = 0;
  std::map<std::string, std::pair<double, long>> records_;  // sum and count since the report
  std::vector<std::pair<std::string, torch::nn::Module*>> modules_;
  std::vector<std::pair<std::string, torch::optim::Optimizer*>> optimizers_;
  std::vector<std::pair<std::string, torch::Tensor*>> tensors_;
};

}  // namespace cradle::learn
