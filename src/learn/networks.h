// Networks for Dict observations, in the shape of SB3's MultiInputPolicy:
// - MultiInputEncoder (SB3 CombinedExtractor): the preprocessed observation vector passes
//   through as is; each eye image goes through its own NatureCNN; the results are concatenated.
// - make_mlp: fully connected hidden layers with an activation after each.
// - GaussianActorCritic (SB3 ActorCriticPolicy for Box actions): a shared encoder, an optional
//   shared trunk, separate policy and value MLPs (64-64 tanh), a linear action mean, a linear
//   value and a state-independent log standard deviation.
// Off-policy learners can build deterministic actors and Q(obs, action) networks from the same
// parts: an encoder, make_mlp over [features, action], and init_layers.
//
// Every weight is initialised from the caller's generator (LibTorch's own initialisers draw from
// the process-wide generator), so a seed fixes the network.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <string>
#include <vector>

#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/preprocess.h"

namespace cradle::learn {

struct PolicyConfig {
  // Hidden layers shared by policy and value before their own (SB3 net_arch's shared part,
  // Baselines' ppo2 "mlp" trunk); empty: separate networks.
  std::vector<int> shared_layers;
  std::vector<int> pi_layers{64, 64};  // policy MLP hidden sizes (SB3 net_arch pi)
  std::vector<int> vf_layers{64, 64};  // value MLP hidden sizes (SB3 net_arch vf)
  std::string activation = "tanh";     // "tanh" or "relu" (SB3 activation_fn, nn.Tanh)
  int cnn_features = 256;              // NatureCNN output size per image (SB3 features_dim)
  bool ortho_init = true;              // orthogonal init with SB3's gains (SB3 ortho_init)
  double log_std_init = 0.0;           // initial log standard deviation (SB3 log_std_init)
  void bind(Hyperparameters& table);
};

// Applies LearnerOptions::device (only "cpu"; UserError otherwise) and torch_threads.
void apply_torch_options(const LearnerOptions& options);

// LibTorch's intra-op thread count set to `threads` for a scope (a gradient update), then set
// back; 0 or less changes nothing. Cheap enough to open around every gradient step: no thread is
// created or destroyed. OpenBLAS keeps its one thread: two OpenBLAS threads under two LibTorch
// threads made the hand-regard update 70 % slower.
class ScopedTorchThreads {
 public:
  explicit ScopedTorchThreads(int threads);
  ~ScopedTorchThreads();
  ScopedTorchThreads(const ScopedTorchThreads&) = delete;
  ScopedTorchThreads& operator=(const ScopedTorchThreads&) = delete;

 private:
  int previous_ = 0;  // 0: nothing to restore
};

// Threads for the gradient updates of a policy: LearnerOptions::update_threads when set; else
// every core when the observation has images, whose convolutions scale, and 0 (unchanged: one
// thread) for vector policies, whose small matrices gain nothing from a second thread.
int update_threads(const LearnerOptions& options, const ObsShape& shape);

// A seed for a learner's envs, drawn from its generator: the generator is saved in checkpoints,
// so a resumed run resets its envs exactly as the saved one would have.
std::uint64_t draw_env_seed(at::Generator& generator);

// Fills a weight (2-D, or a conv kernel flattened to [out, rest]) with a random orthogonal
// matrix times gain (Saxe et al. 2014; the sign-corrected QR of a Gaussian matrix).
void orthogonal_(torch::Tensor weight, double gain, at::Generator& generator);
// Initialises every Linear and Conv2d inside `module`: orthogonal weights times gain and zero
// biases, or (orthogonal = false) LibTorch's default, uniform in +-1/sqrt(fan_in).
void init_layers(torch::nn::Module& module, double gain, bool orthogonal, at::Generator& generator);

// A module's parameters packed into one contiguous tensor and their gradients into another, so
// the optimiser and gradient clipping run a few large ops instead of several per layer (for
// these small networks that makes each minibatch update about a quarter cheaper). The module's
// parameter tensors become views into the packed one: forward passes, saving and loading work
// unchanged as long as they copy into the tensors (read_module does; Module::load replaces
// them and breaks the packing). Optimise {tensor()} and zero gradients with zero_grad(), not
// the optimiser's, which would drop the packed gradient.
class PackedParameters {
 public:
  explicit PackedParameters(torch::nn::Module& module);
  torch::Tensor& tensor() { return packed_; }
  const torch::Tensor& tensor() const { return packed_; }
  void zero_grad() { grad_.zero_(); }

 private:
  torch::Tensor packed_, grad_;
};

// Throws UserError when a network of `parameters` weights, with its gradients and two Adam
// moments (16 bytes a weight), would need more than half the machine's memory (the replay
// buffer's rule): an absurd layer size is a one-line error, not std::bad_alloc.
void check_network_memory(const std::string& what, double parameters);
// Memory limit of check_network_memory, in bytes: half the physical memory.
double network_memory_limit();

// Hidden layers Linear -> activation for each size; output size layers.back() (or `input` when
// there are none).
torch::nn::Sequential make_mlp(int input, const std::vector<int>& layers,
                               const std::string& activation);

// The Nature DQN encoder (Mnih et al. 2015) as in SB3: conv 8x8/4 (32), 4x4/2 (64), 3x3/1 (64),
// ReLU after each, then Linear to `features` + ReLU. A 64x64 eye gives a 4x4x64 map (1,024
// values). Input uint8 [B, height, width, channels], scaled to [0, 1].
class NatureCnnImpl : public torch::nn::Module {
 public:
  NatureCnnImpl(int height, int width, int channels, int features);
  torch::Tensor forward(const torch::Tensor& images);

 private:
  torch::nn::Sequential convs_{nullptr};
  torch::nn::Linear linear_{nullptr};
};
TORCH_MODULE(NatureCnn);

class MultiInputEncoderImpl : public torch::nn::Module {
 public:
  MultiInputEncoderImpl(const ObsShape& shape, int cnn_features);
  int output_size() const { return output_size_; }
  torch::Tensor forward(const ObsBatch& observation);

 private:
  std::vector<NatureCnn> cnns_;
  int output_size_ = 0;
};
TORCH_MODULE(MultiInputEncoder);

class GaussianActorCriticImpl : public torch::nn::Module {
 public:
  GaussianActorCriticImpl(const ObsShape& shape, int action_size, const PolicyConfig& config,
                          at::Generator& generator);
  struct Output {
    torch::Tensor mean;   // [B, action_size]
    torch::Tensor value;  // [B]
  };
  Output forward(const ObsBatch& observation);
  torch::Tensor value(const ObsBatch& observation);
  const torch::Tensor& log_std() const { return log_std_; }
  // log N(actions; mean, exp(log_std)), summed over action dimensions: [B].
  torch::Tensor log_prob(const torch::Tensor& mean, const torch::Tensor& actions) const;
  // Entropy of the Gaussian (a scalar: the same for every state).
  torch::Tensor entropy() const;

 private:
  // The encoder's features through the shared trunk (when there is one).
  torch::Tensor features(const ObsBatch& observation);

  MultiInputEncoder encoder_{nullptr};
  torch::nn::Sequential shared_net_{nullptr}, pi_net_{nullptr}, vf_net_{nullptr};
  torch::nn::Linear action_mean_{nullptr}, value_head_{nullptr};
  torch::Tensor log_std_;
};
TORCH_MODULE(GaussianActorCritic);

// V(s) of one observation as the policy sees it (normalised by `pipeline`, whose statistics do
// not change), through `scratch`, a one-row batch (PPO's and A2C's Learner::value).
double state_value(ObservationPipeline& pipeline, GaussianActorCritic& policy,
                   const envs::ObservationBuffers& observation, ObsBatch& scratch);

}  // namespace cradle::learn
