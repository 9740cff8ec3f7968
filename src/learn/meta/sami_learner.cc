// SaMI's context-SAC methods as a learn::Learner. The loop, top to bottom, heads sami_learner.h;
// the update is ContextSac::update (context_sac.h).
#include "learn/meta/sami_learner.h"

#include <torch/torch.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "core/text.h"
#include "learn/checkpoint.h"
#include "learn/grad_tensors.h"
#include "learn/meta/context_sac.h"
#include "learn/meta/methods.h"
#include "learn/meta/samplers.h"
#include "learn/meta/trajectory_replay.h"
#include "learn/networks.h"
#include "learn/replay_buffer.h"
#include "learn/rollout.h"

namespace cradle::learn::meta {

void SamiLearnerConfig::bind(Hyperparameters& table) {
  table.add("horizon", &horizon,
            "longest trajectory stored; a longer episode goes on in a new one (SaMI: the env's "
            "horizon)");
  table.add("report_every", &report_every, "vector steps between progress reports");
}

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::array<std::string_view, 5> kNames = {"tesac", "ccm", "satesac", "saccm",
                                                    "saccm_all"};
constexpr std::array<std::string_view, 5> kMethods = {"TESAC", "CCM", "SaTESAC", "SaCCM",
                                                      "SaCCMAll"};

// SaMI's stream for random actions and replay sampling, apart from ContextSac's generator.
constexpr std::uint64_t kRngSalt = 0x5a4d49ULL;

// Rng's state in checkpoints: four words, copied as they lie.
static_assert(std::is_trivially_copyable_v<Rng> && sizeof(Rng) == 4 * sizeof(std::uint64_t));

torch::Tensor rng_state(const Rng& rng) {
  torch::Tensor out = torch::empty({4}, torch::kInt64);
  std::memcpy(out.data_ptr<std::int64_t>(), &rng, sizeof(Rng));
  return out;
}

struct Settings {
  SamiConfig sami;
  SamiLearnerConfig own;
  std::string text;  // every value, "name = value" lines
};

// Every setting, parsed strictly from the options; UserError for an unknown name or bad value.
Settings parse_settings(const std::string& algorithm, const LearnerOptions& options) {
  apply_torch_options(options);
  Settings settings;
  Hyperparameters table;
  settings.sami.bind(table);
  settings.own.bind(table);
  table.apply(options.hyperparameters);
  settings.sami.check();
  // Values SamiConfig::check leaves to the loop (the ranges of hyperparam_ranges.h hold
  // for values given by name, not for defaults).
  const auto need = [&](bool ok, const std::string& what) {
    if (!ok) throw UserError(algorithm + ": hyperparameter " + what);
  };
  need(settings.own.horizon >= 1 && settings.own.horizon <= 10'000'000,
       "horizon: expected 1 <= horizon <= 10000000");
  need(settings.own.report_every >= 1, "report_every: expected a positive number");
  need(settings.sami.train_freq >= 1 && settings.sami.gradient_steps >= 1,
       "train_freq and gradient_steps: expected positive numbers");
  need(settings.sami.learning_starts >= 0, "learning_starts: expected 0 or more");
  need(settings.sami.buffer_size >= 1, "buffer_size: expected a positive number");
  settings.text = table.to_text();
  return settings;
}

// Where each float observation key sits in the concatenated row.
struct FloatKey {
  int index = 0;  // in the DictSpace
  bool f64 = false;
  int size = 0;
};

std::vector<FloatKey> float_keys(const std::string& algorithm, const DictSpace& space) {
  std::vector<FloatKey> keys;
  for (int k = 0; k < static_cast<int>(space.entries.size()); ++k) {
    const auto& [name, box] = space.entries[k];
    if (box.dtype == DType::kUInt8) {
      throw UserError(algorithm + ": observation key '" + name +
                      "' is uint8 (an image); SaMI's learners read float observations only");
    }
    keys.push_back({k, box.dtype == DType::kFloat64, box.size()});
  }
  if (keys.empty()) throw UserError(algorithm + ": the env has no float observation key");
  return keys;
}

int total_size(const std::vector<FloatKey>& keys) {
  int size = 0;
  for (const FloatKey& key : keys) size += key.size;
  return size;
}

class SamiLearner final : public Learner {
 public:
  SamiLearner(std::string algorithm, std::string method, VecEnv& env, const LearnerOptions& options,
              Settings settings)
      : algorithm_(std::move(algorithm)),
        env_(env),
        settings_(std::move(settings)),
        config_(settings_.sami),
        keys_(float_keys(algorithm_, env.observation_space())),
        envs_(env.num_envs()),
        obs_size_(total_size(keys_)),
        action_size_(checked_actions(env)),
        sac_(std::move(method), obs_size_, action_size_, config_, options.seed),
        replay_(envs_, config_.buffer_size, settings_.own.horizon, obs_size_, action_size_),
        rng_(options.seed ^ kRngSalt),
        generator_(at::make_generator<at::CPUGeneratorImpl>(options.seed)),
        sync_(options.sync),
        stepper_(env, options.reward_hook),
        streams_(sac_.streams(envs_)),
        act_stream_(sac_.streams(1)),
        observations_(torch::zeros({envs_, obs_size_})),
        act_observation_(torch::zeros({1, obs_size_})),
        first_(static_cast<size_t>(envs_) * obs_size_),
        fresh_(envs_, 0),
        actions_(static_cast<size_t>(envs_) * action_size_),
        env_actions_(actions_.size()) {
    if (sac_.contrast() == Contrast::kEnvDiff && envs_ < 2) {
      throw UserError(algorithm_ + " contrasts training envs and needs a vector of at least 2");
    }
    const Box& box = env.action_space();
    for (int j = 0; j < action_size_; ++j) {
      low_.push_back(box.low[j]);
      high_.push_back(box.high[j]);
      scale_.push_back(0.5 * (box.high[j] - box.low[j]));
    }
    // Data-parallel: every rank starts from rank 0's networks and averages its gradients.
    sac_.set_sync(sync_.get());
    for (const torch::Tensor& p : sac_.parameters()) broadcast_tensor(sync_.get(), p.detach());
  }

  std::string_view algorithm() const override { return algorithm_; }
  long steps() const override { return steps_; }
  std::string config_text() const override { return settings_.text; }

  void learn(long total_steps, const ProgressFn& on_progress) override;

  void save(const std::filesystem::path& file) const override {
    const CheckpointInfo header{.algorithm = algorithm_, .config = settings_.text, .steps = steps_};
    write_checkpoint(file, header, [&](torch::serialize::OutputArchive& archive) {
      sac_.write(archive);
      replay_.write(archive, "replay");
      archive.write("rng", rng_state(rng_));
      write_generator(archive, "env_generator", generator_);
      archive.write("vector_steps", torch::tensor({vector_steps_}, torch::kInt64));
    });
  }

  void load(const std::filesystem::path& file) override {
    const CheckpointInfo info = read_checkpoint(
        file, algorithm_, [&](const CheckpointInfo&, torch::serialize::InputArchive& archive) {
          // Every part is read and checked before any changes.
          const std::function<void()> copy_sac = sac_.read(archive);
          const std::function<void()> copy_replay = replay_.stage(archive, "replay");
          torch::Tensor rng, env_generator, vector_steps;
          archive.read("rng", rng);
          archive.read("env_generator", env_generator);
          archive.read("vector_steps", vector_steps);
          if (rng.scalar_type() != torch::kInt64 || rng.numel() != 4 || vector_steps.numel() != 1) {
            throw UserError("not the generator state and counters of a SaMI learner");
          }
          copy_sac();
          copy_replay();
          std::memcpy(static_cast<void*>(&rng_), rng.contiguous().data_ptr<std::int64_t>(),
                      sizeof(Rng));
          generator_.set_state(env_generator);
          vector_steps_ = vector_steps.item<long>();
        });
    steps_ = info.steps;
    // Data-parallel: every rank loaded rank 0's generators; ranks above 0 go on with streams of
    // their own, so that they explore and sample differently.
    if (distributed(sync_.get()) && sync_->rank() > 0) {
      offset_generator(sync_.get(), generator_);
      offset_generator(sync_.get(), sac_.generator());
      rng_ = Rng(rng_.next() ^ (0x9e3779b97f4a7c15ULL * static_cast<unsigned>(sync_->rank())));
    }
    new_episode();
  }

  void act(const envs::ObservationBuffers& observation, std::span<double> action,
           bool deterministic) override {
    if (act_steps_ == settings_.own.horizon) new_episode();
    gather(observation, act_observation_.data_ptr<float>());
    auto [a, context] = sac_.act(act_observation_, act_stream_, deterministic);
    act_context_ = context.contiguous();
    ++act_steps_;
    rescale(a.contiguous().data_ptr<float>(), action);
  }

  std::span<const float> context() const {
    if (!act_context_.defined()) return {};
    return {act_context_.data_ptr<float>(), static_cast<size_t>(act_context_.numel())};
  }

  void new_episode() override {
    act_stream_.reset(0);
    act_steps_ = 0;
  }

  std::uint64_t parameter_hash() const override { return tensor_hash(sac_.parameters()); }

 private:
  int checked_actions(const VecEnv& env) const {
    check_bounded_actions(algorithm_, env.action_space());
    return env.action_space().size();
  }

  // One env's float keys, concatenated into `row` (obs_size_ floats).
  void gather(const envs::ObservationBuffers& observation, float* row) const {
    for (const FloatKey& key : keys_) {
      if (key.f64) {
        const std::span<const double> values = observation.f64(key.index);
        row = std::copy(values.begin(), values.end(), row);
      } else {
        const std::span<const float> values = observation.f32(key.index);
        row = std::copy(values.begin(), values.end(), row);
      }
    }
  }

  // Actions in [-1, 1] to the Box, as SaMI's low + (a + 1) (high - low) / 2, then clipped
  // to the bounds (a no-op on [-1, 1], whose values stay SaMI's exactly).
  template <typename T>
  void rescale(const T* actions, std::span<double> out) const {
    for (size_t k = 0; k < out.size(); ++k) {
      const size_t j = k % action_size_;
      out[k] = std::clamp(low_[j] + (static_cast<double>(actions[k]) + 1.0) * scale_[j], low_[j],
                          high_[j]);
    }
  }

  std::span<const float> row(int env) const {
    return {observations_.data_ptr<float>() + static_cast<size_t>(env) * obs_size_,
            static_cast<size_t>(obs_size_)};
  }

  // Slot `env`'s next trajectory starts at its current observation; the ring takes it at its
  // first step.
  void start_trajectory(int env) {
    const std::span<const float> o = row(env);
    std::copy(o.begin(), o.end(), first_.begin() + static_cast<long>(env) * obs_size_);
    fresh_[env] = 1;
  }

  void record(const std::string& name, double value) {
    if (std::isnan(value)) return;  // sance_loss of an update without a contrastive step
    auto& [sum, count] = records_[name];
    sum += value;
    ++count;
  }

  // gradient_steps updates, their losses recorded.
  void train();
  TrainStats report(Clock::time_point start, long start_steps);

  const std::string algorithm_;
  VecEnv& env_;
  const Settings settings_;
  const SamiConfig& config_;
  const std::vector<FloatKey> keys_;
  const int envs_, obs_size_, action_size_;
  ContextSac sac_;
  TrajectoryReplay replay_;
  Rng rng_;                         // random actions, replay samples
  at::Generator generator_;         // env seeds
  std::shared_ptr<GradSync> sync_;  // data-parallel ranks (null: alone)
  EnvStepper stepper_;
  ContextSac::Streams streams_, act_stream_;
  torch::Tensor observations_;       // [envs, obs] float32: the current observations
  torch::Tensor act_observation_;    // [1, obs]
  torch::Tensor act_context_;        // [1, context]: the last act() call's c_t
  std::vector<float> first_;         // [envs, obs]: each slot's next trajectory's first observation
  std::vector<std::uint8_t> fresh_;  // 1: the slot's trajectory is not in its ring yet
  std::vector<double> actions_;      // [envs, action] in [-1, 1]
  std::vector<double> env_actions_;  // the same in the Box
  std::vector<double> low_, high_, scale_;  // per action: bounds, (high - low) / 2
  long steps_ = 0, vector_steps_ = 0;
  int act_steps_ = 0;                                       // act() calls in the current stream
  long window_updates_ = 0;                                 // gradient steps since the last report
  double update_seconds_ = 0;                               // their time
  std::map<std::string, std::pair<double, long>> records_;  // sum and count since the report
};

void SamiLearner::learn(long total_steps, const ProgressFn& on_progress) {
  if (steps_ >= total_steps) return;
  const Clock::time_point start = Clock::now();
  const long start_steps = steps_;
  // learning_starts counts this rank's env steps; steps_ every rank's (as SAC's).
  const long random_steps = config_.learning_starts * envs_;
  const long ranks = world_size(sync_.get());
  const int horizon = settings_.own.horizon;
  records_.clear();
  new_episode();

  // Fresh episodes: the reset cuts any open trajectory (truncated: its last observation
  // bootstraps), and every slot starts anew.
  stepper_.start(draw_env_seed(generator_));
  for (int i = 0; i < envs_; ++i) {
    if (replay_.open_length(i) > 0) replay_.finish(i, /*terminated=*/false);
    gather(env_.observation(i), observations_.data_ptr<float>() + static_cast<long>(i) * obs_size_);
    start_trajectory(i);
    streams_.reset(i);
  }

  while (steps_ < total_steps) {
    // Act: the policy advances every stream (random steps too, as SaMI's loop); until
    // learning_starts the actions taken are uniform and replace the streams' previous actions.
    const torch::Tensor policy = sac_.act(observations_, streams_, /*deterministic=*/false).first;
    float* taken = streams_.prev_actions.data_ptr<float>();
    if (vector_steps_ * envs_ < random_steps) {
      for (size_t k = 0; k < actions_.size(); ++k) {
        actions_[k] = rng_.uniform(-1.0, 1.0);
        taken[k] = static_cast<float>(actions_[k]);
      }
    } else {
      const float* p = policy.contiguous().data_ptr<float>();
      std::copy(p, p + actions_.size(), actions_.begin());
    }
    rescale(actions_.data(), env_actions_);
    stepper_.step(env_actions_);
    ++vector_steps_;
    steps_ += envs_ * ranks;

    // Store: a slot reset by this step starts a trajectory; the others extend theirs.
    const std::span<const std::uint8_t> real = stepper_.real();
    const std::span<const double> rewards = stepper_.rewards();
    const std::span<const std::uint8_t> terminated = env_.terminated();
    const std::span<const std::uint8_t> truncated = env_.truncated();
    for (int i = 0; i < envs_; ++i) {
      gather(env_.observation(i),
             observations_.data_ptr<float>() + static_cast<long>(i) * obs_size_);
      if (!real[i]) {
        streams_.reset(i);
        start_trajectory(i);
        continue;
      }
      if (fresh_[i]) {
        replay_.begin(i, std::span<const float>(first_).subspan(static_cast<size_t>(i) * obs_size_,
                                                                obs_size_));
        fresh_[i] = 0;
      }
      replay_.add(
          i, std::span<const float>(taken + static_cast<size_t>(i) * action_size_, action_size_),
          rewards[i], row(i));
      if (terminated[i] || truncated[i]) {
        replay_.finish(i, terminated[i]);  // the next starts at the autoreset
      } else if (replay_.open_length(i) == horizon) {
        // As long as a trajectory may be: the episode goes on in a new one, with a new context.
        replay_.finish(i, /*terminated=*/false);
        streams_.reset(i);
        start_trajectory(i);
      }
    }

    // Train every train_freq vector steps once past learning_starts with a whole trajectory in
    // every slot; data-parallel, on every rank when every rank has them (so updates pair up).
    if (vector_steps_ * envs_ >= random_steps && vector_steps_ % config_.train_freq == 0) {
      bool ready = true;
      for (int i = 0; i < envs_ && ready; ++i) ready = replay_.stored(i) > 0;
      if (agree_max(sync_.get(), ready ? 0.0 : 1.0) == 0.0) train();
    }

    if (vector_steps_ % settings_.own.report_every != 0 && steps_ < total_steps) continue;
    const TrainStats stats = report(start, start_steps);
    if (on_progress && !on_progress(stats)) break;
  }
}

void SamiLearner::train() {
  const Clock::time_point start = Clock::now();
  for (int g = 0; g < config_.gradient_steps; ++g) {
    const ContextSac::Losses l = sac_.update(replay_, rng_);
    if (!std::isfinite(l.critic) || !std::isfinite(l.actor)) {
      char text[64];
      std::snprintf(text, sizeof text, "%g", l.critic);
      throw UserError(algorithm_ + ": the update diverged at step " + std::to_string(steps_) +
                      " (qf_loss " + text + ")");
    }
    record("qf_loss", l.critic);
    record("actor_loss", l.actor);
    record("alpha", l.alpha);
    record("alpha_loss", l.alpha_loss);
    record("entropy", l.entropy);
    record("sance_loss", l.sance);
    record("sance_weight", l.weight);
  }
  window_updates_ += config_.gradient_steps;
  update_seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
}

TrainStats SamiLearner::report(Clock::time_point start, long start_steps) {
  TrainStats stats{.steps = steps_};
  for (const auto& [name, record] : records_) stats.losses[name] = record.first / record.second;
  records_.clear();
  stats.losses["updates"] = static_cast<double>(sac_.updates());  // gradient steps so far
  // This report's gradient steps and the seconds they took (as the off-policy learners' columns).
  stats.losses["gradient_steps"] = static_cast<double>(std::exchange(window_updates_, 0));
  stats.losses["update_seconds"] = std::exchange(update_seconds_, 0.0);
  long trajectories = 0;
  for (int i = 0; i < envs_; ++i) trajectories += replay_.stored(i);
  stats.losses["buffer_trajectories"] = static_cast<double>(trajectories);
  stepper_.episodes().report_into(stats);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  stats.sps = static_cast<double>(steps_ - start_steps) / std::max(seconds, 1e-9);
  return stats;
}

}  // namespace

std::span<const std::string_view> sami_learner_names() { return kNames; }

std::string sami_learner_list() { return listed(kNames); }

std::string_view sami_method(std::string_view algorithm) {
  for (size_t k = 0; k < kNames.size(); ++k) {
    if (kNames[k] == algorithm) return kMethods[k];
  }
  return {};
}

std::string sami_learner_name(std::string_view method) {
  for (size_t k = 0; k < kNames.size(); ++k) {
    if (kMethods[k] == method) return std::string(kNames[k]);
  }
  method_contrast(method);  // the one-line error naming the methods
  throw UserError("unknown SaMI method '" + std::string(method) + "'");
}

std::span<const float> last_context(const Learner& learner) {
  const auto* sami = dynamic_cast<const SamiLearner*>(&learner);
  if (sami == nullptr) {
    throw UserError(std::string(learner.algorithm()) +
                    " infers no context (expected one of SaMI's learners: " + sami_learner_list() +
                    ")");
  }
  return sami->context();
}

std::unique_ptr<Learner> make_sami_learner(std::string_view algorithm, VecEnv& env,
                                           const LearnerOptions& options) {
  const std::string_view method = sami_method(algorithm);
  if (method.empty()) {
    throw UserError("unknown SaMI learner '" + std::string(algorithm) + "' (expected " +
                    sami_learner_list() + ")");
  }
  const std::string name(algorithm);
  return std::make_unique<SamiLearner>(name, std::string(method), env, options,
                                       parse_settings(name, options));
}

}  // namespace cradle::learn::meta
