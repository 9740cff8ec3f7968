#include "learn/networks.h"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <thread>

#include "core/error.h"

namespace cradle::learn {

void PolicyConfig::bind(Hyperparameters& table) {
  table.add("shared_layers", &shared_layers,
            "hidden sizes shared by policy and value, e.g. 400,300 (empty: none)");
  table.add("pi_layers", &pi_layers, "policy MLP hidden sizes, e.g. 64,64 (SB3 net_arch pi)");
  table.add("vf_layers", &vf_layers, "value MLP hidden sizes, e.g. 64,64 (SB3 net_arch vf)");
  table.add("activation", &activation, "hidden activation: tanh or relu (SB3 activation_fn)");
  table.add("cnn_features", &cnn_features, "NatureCNN output size per image (SB3 features_dim)");
  table.add("ortho_init", &ortho_init, "orthogonal initialisation (SB3 ortho_init)");
  table.add("log_std_init", &log_std_init, "initial log std of the Gaussian (SB3 log_std_init)");
}

namespace {

// "64,64" (the --hp form).
std::string layer_text(const std::vector<int>& layers) {
  std::string text;
  for (const int size : layers) {
    if (!text.empty()) text += ',';
    text += std::to_string(size);
  }
  return text;
}

// A `void f(int)` thread-count setter of a library LibTorch loaded, or null.
using SetThreads = void (*)(int);
SetThreads find_set_threads(const char* symbol) {
  return reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, symbol));
}

// LibTorch's intra-op thread count without at::set_num_threads, which also rebuilds the
// pthreadpool (a thread destroyed and another created per call: around every SAC gradient step
// that made a 17 ms step 51 ms). Debian's LibTorch runs its intra-op loops and oneDNN on OpenMP,
// which read the calling thread's OpenMP setting (as at::get_num_threads does).
void set_intra_op_threads(int threads) {
  static const SetThreads set_openmp_threads = find_set_threads("omp_set_num_threads");
  if (set_openmp_threads != nullptr) {
    set_openmp_threads(threads);
  } else {
    torch::set_num_threads(threads);
  }
}

}  // namespace

void apply_torch_options(const LearnerOptions& options) {
  if (options.device != "cpu") {
    throw UserError("device '" + options.device + "': this build trains on the cpu only");
  }
  if (options.update_threads < 0) {
    throw UserError("update_threads " + std::to_string(options.update_threads) +
                    ": expected 0 (every core) or more");
  }
  if (options.torch_threads <= 0) return;
  torch::set_num_threads(options.torch_threads);
  // Debian's LibTorch does its matrix products in OpenBLAS, whose own thread pool LibTorch's
  // setting does not reach: its workers would spin on the cores the envs step on.
  if (const SetThreads set_threads = find_set_threads("openblas_set_num_threads")) {
    set_threads(options.torch_threads);
  }
}

ScopedTorchThreads::ScopedTorchThreads(int threads) {
  if (threads <= 0 || threads == torch::get_num_threads()) return;
  previous_ = torch::get_num_threads();
  set_intra_op_threads(threads);
}

ScopedTorchThreads::~ScopedTorchThreads() {
  if (previous_ > 0) set_intra_op_threads(previous_);
}

int update_threads(const LearnerOptions& options, const ObsShape& shape) {
  if (options.update_threads > 0) return options.update_threads;
  if (shape.images.empty()) return 0;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

std::uint64_t draw_env_seed(at::Generator& generator) {
  return static_cast<std::uint64_t>(
      torch::randint(0, std::numeric_limits<int64_t>::max(), {1}, generator).item<int64_t>());
}

// ---------------------------------------------------------------------------------------------
// Initialisation

void orthogonal_(torch::Tensor weight, double gain, at::Generator& generator) {
  torch::NoGradGuard no_grad;
  const long rows = weight.size(0);
  const long cols = weight.numel() / rows;
  torch::Tensor matrix = torch::randn({rows, cols}, generator, torch::kFloat32);
  if (rows < cols) matrix = matrix.t();
  auto [q, r] = torch::linalg::qr(matrix, "reduced");
  q = q * torch::sign(torch::diagonal(r));  // makes the factorisation unique (uniform Haar)
  if (rows < cols) q = q.t();
  weight.copy_(q.reshape(weight.sizes()) * gain);
}

void init_layers(torch::nn::Module& module, double gain, bool orthogonal,
                 at::Generator& generator) {
  torch::NoGradGuard no_grad;
  auto init = [&](torch::Tensor& weight, torch::Tensor& bias) {
    const double fan_in = static_cast<double>(weight.numel() / weight.size(0));
    const double bound = 1.0 / std::sqrt(fan_in);
    if (orthogonal) {
      orthogonal_(weight, gain, generator);
    } else {
      weight.uniform_(-bound, bound, generator);
    }
    if (!bias.defined()) return;
    if (orthogonal) {
      bias.zero_();
    } else {
      bias.uniform_(-bound, bound, generator);
    }
  };
  for (const auto& child : module.modules(/*include_self=*/true)) {
    if (auto* linear = child->as<torch::nn::Linear>()) {
      init(linear->weight, linear->bias);
    } else if (auto* conv = child->as<torch::nn::Conv2d>()) {
      init(conv->weight, conv->bias);
    }
  }
}

PackedParameters::PackedParameters(torch::nn::Module& module) {
  long total = 0;
  for (const torch::Tensor& p : module.parameters()) total += p.numel();
  packed_ = torch::zeros({total}, torch::kFloat32);
  grad_ = torch::zeros({total}, torch::kFloat32);
  torch::NoGradGuard no_grad;
  long offset = 0;
  for (torch::Tensor& p : module.parameters()) {
    const long n = p.numel();
    torch::Tensor slot = packed_.detach().slice(0, offset, offset + n).view(p.sizes());
    slot.copy_(p.detach());
    p.set_data(slot);
    // Autograd accumulates into an existing gradient in place, i.e. into grad_.
    p.mutable_grad() = grad_.slice(0, offset, offset + n).view(p.sizes());
    offset += n;
  }
  packed_.set_requires_grad(true);
  packed_.mutable_grad() = grad_;
}

double network_memory_limit() {
  const double pages = static_cast<double>(sysconf(_SC_PHYS_PAGES));
  const double page_size = static_cast<double>(sysconf(_SC_PAGE_SIZE));
  return 0.5 * pages * page_size;
}

void check_network_memory(const std::string& what, double parameters) {
  const double bytes = 16.0 * parameters, limit = network_memory_limit();
  if (bytes <= limit) return;
  char text[320];
  std::snprintf(text, sizeof text,
                "%s: %.3g weights need %.1f GB with their gradients and Adam moments, more than "
                "the %.1f GB allowed (half the machine's memory); lower the layer sizes",
                what.c_str(), parameters, bytes / 1e9, limit / 1e9);
  throw UserError(text);
}

torch::nn::Sequential make_mlp(int input, const std::vector<int>& layers,
                               const std::string& activation) {
  if (activation != "tanh" && activation != "relu") {
    throw UserError("activation '" + activation + "': expected tanh or relu");
  }
  // Every size first: the weights are allocated only for a network that fits.
  double parameters = 0;
  int fan_in = input;
  for (const int size : layers) {
    if (size <= 0) throw UserError("hidden layer sizes must be positive");
    parameters += (static_cast<double>(fan_in) + 1) * size;
    fan_in = size;
  }
  check_network_memory("network of hidden layers " + layer_text(layers), parameters);
  torch::nn::Sequential mlp;
  for (const int size : layers) {
    if (size <= 0) throw UserError("hidden layer sizes must be positive");
    mlp->push_back(torch::nn::Linear(input, size));
    if (activation == "tanh") {
      mlp->push_back(torch::nn::Tanh());
    } else {
      mlp->push_back(torch::nn::ReLU());
    }
    input = size;
  }
  return mlp;
}

// ---------------------------------------------------------------------------------------------
// Encoders

namespace {
int conv_output(int size, int kernel, int stride) { return (size - kernel) / stride + 1; }
}  // namespace

NatureCnnImpl::NatureCnnImpl(int height, int width, int channels, int features) {
  namespace nn = torch::nn;
  int h = conv_output(conv_output(conv_output(height, 8, 4), 4, 2), 3, 1);
  int w = conv_output(conv_output(conv_output(width, 8, 4), 4, 2), 3, 1);
  if (h < 1 || w < 1) {
    throw UserError("images of " + std::to_string(height) + "x" + std::to_string(width) +
                    " are too small for the NatureCNN encoder (at least 36x36)");
  }
  convs_ = register_module(
      "convs", nn::Sequential(nn::Conv2d(nn::Conv2dOptions(channels, 32, 8).stride(4)), nn::ReLU(),
                              nn::Conv2d(nn::Conv2dOptions(32, 64, 4).stride(2)), nn::ReLU(),
                              nn::Conv2d(nn::Conv2dOptions(64, 64, 3).stride(1)), nn::ReLU(),
                              nn::Flatten()));
  linear_ = register_module("linear", nn::Linear(64 * h * w, features));
}

torch::Tensor NatureCnnImpl::forward(const torch::Tensor& images) {
  const torch::Tensor x = images.permute({0, 3, 1, 2}).to(torch::kFloat32).div_(255.0);
  return torch::relu(linear_(convs_->forward(x)));
}

MultiInputEncoderImpl::MultiInputEncoderImpl(const ObsShape& shape, int cnn_features) {
  output_size_ = shape.vector_size;
  for (size_t k = 0; k < shape.images.size(); ++k) {
    const auto& [h, w, c] = shape.images[k];
    cnns_.push_back(register_module("cnn" + std::to_string(k), NatureCnn(h, w, c, cnn_features)));
    output_size_ += cnn_features;
  }
}

torch::Tensor MultiInputEncoderImpl::forward(const ObsBatch& observation) {
  if (cnns_.empty()) return observation.vector;
  std::vector<torch::Tensor> parts{observation.vector};
  for (size_t k = 0; k < cnns_.size(); ++k)
    parts.push_back(cnns_[k]->forward(observation.images[k]));
  return torch::cat(parts, 1);
}

// ---------------------------------------------------------------------------------------------
// Actor-critic

GaussianActorCriticImpl::GaussianActorCriticImpl(const ObsShape& shape, int action_size,
                                                 const PolicyConfig& config,
                                                 at::Generator& generator) {
  encoder_ = register_module("encoder", MultiInputEncoder(shape, config.cnn_features));
  int features = encoder_->output_size();
  // The shared trunk only when asked for: without one the parameters (and a seed's draws) stay
  // those of separate networks.
  if (!config.shared_layers.empty()) {
    shared_net_ =
        register_module("shared_net", make_mlp(features, config.shared_layers, config.activation));
    features = config.shared_layers.back();
  }
  pi_net_ = register_module("pi_net", make_mlp(features, config.pi_layers, config.activation));
  vf_net_ = register_module("vf_net", make_mlp(features, config.vf_layers, config.activation));
  const int pi_out = config.pi_layers.empty() ? features : config.pi_layers.back();
  const int vf_out = config.vf_layers.empty() ? features : config.vf_layers.back();
  action_mean_ = register_module("action_mean", torch::nn::Linear(pi_out, action_size));
  value_head_ = register_module("value_head", torch::nn::Linear(vf_out, 1));
  log_std_ = register_parameter("log_std", torch::full({action_size}, config.log_std_init));

  // SB3's gains: sqrt(2) for the encoder and hidden layers, 0.01 for the action mean (a nearly
  // state-independent first policy), 1 for the value.
  const double hidden_gain = std::sqrt(2.0);
  init_layers(*encoder_, hidden_gain, config.ortho_init, generator);
  if (shared_net_) init_layers(*shared_net_, hidden_gain, config.ortho_init, generator);
  init_layers(*pi_net_, hidden_gain, config.ortho_init, generator);
  init_layers(*vf_net_, hidden_gain, config.ortho_init, generator);
  init_layers(*action_mean_, 0.01, config.ortho_init, generator);
  init_layers(*value_head_, 1.0, config.ortho_init, generator);
}

namespace {
// An MLP of make_mlp; one without layers passes its input through (a shared trunk alone).
torch::Tensor through(torch::nn::Sequential& mlp, const torch::Tensor& x) {
  return mlp->is_empty() ? x : mlp->forward(x);
}
}  // namespace

torch::Tensor GaussianActorCriticImpl::features(const ObsBatch& observation) {
  const torch::Tensor encoded = encoder_->forward(observation);
  return shared_net_ ? shared_net_->forward(encoded) : encoded;
}

GaussianActorCriticImpl::Output GaussianActorCriticImpl::forward(const ObsBatch& observation) {
  const torch::Tensor h = features(observation);
  return {action_mean_(through(pi_net_, h)), value_head_(through(vf_net_, h)).squeeze(1)};
}

torch::Tensor GaussianActorCriticImpl::value(const ObsBatch& observation) {
  return value_head_(through(vf_net_, features(observation))).squeeze(1);
}

torch::Tensor GaussianActorCriticImpl::log_prob(const torch::Tensor& mean,
                                                const torch::Tensor& actions) const {
  // log N(a; mu, sigma) = -((a - mu) / sigma)^2 / 2 - log sigma - log(2 pi) / 2, per dimension.
  const double half_log_2pi = 0.5 * std::log(2.0 * std::numbers::pi);
  const torch::Tensor z = (actions - mean) * torch::exp(-log_std_);
  return (-0.5 * z.square() - log_std_ - half_log_2pi).sum(1);
}

torch::Tensor GaussianActorCriticImpl::entropy() const {
  // H = sum over dimensions of (1 + log(2 pi)) / 2 + log sigma.
  return (0.5 + 0.5 * std::log(2.0 * std::numbers::pi) + log_std_).sum();
}

double state_value(ObservationPipeline& pipeline, GaussianActorCritic& policy,
                   const envs::ObservationBuffers& observation, ObsBatch& scratch) {
  torch::NoGradGuard no_grad;
  pipeline.process(observation, scratch);
  return policy->value(scratch)[0].item<double>();
}

}  // namespace cradle::learn
