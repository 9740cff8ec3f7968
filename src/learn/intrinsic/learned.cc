#include "learn/intrinsic/learned.h"

#include <ATen/CPUGeneratorImpl.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"
#include "learn/checkpoint.h"

namespace cradle::learn::intrinsic {

torch::nn::Sequential make_mlp(int in, int hidden, int out, at::Generator& gen) {
  torch::nn::Sequential net(torch::nn::Linear(in, hidden), torch::nn::ReLU(),
                            torch::nn::Linear(hidden, hidden), torch::nn::ReLU(),
                            torch::nn::Linear(hidden, out));
  torch::NoGradGuard no_grad;
  for (auto& layer : net->children()) {
    if (auto* linear = layer->as<torch::nn::Linear>()) {
      const double bound = 1.0 / std::sqrt(static_cast<double>(linear->weight.size(1)));
      linear->weight.uniform_(-bound, bound, gen);
      linear->bias.uniform_(-bound, bound, gen);
    }
  }
  return net;
}

LearnedReward::LearnedReward(double scale, LearnedOptions options)
    : IntrinsicReward(scale),
      options_(options),
      gen_(at::detail::createCPUGenerator(options.seed)),
      draw_(options.seed) {
  if (options_.batch < 1 || options_.buffer < 1 || options_.hidden < 1) {
    throw UserError("learned intrinsic reward: batch, buffer and hidden must be positive");
  }
}

void LearnedReward::bind(const VecEnv& env) {
  features_ = Features(env, options_.features);
  const int d = features_.size();
  if (d == 0) throw UserError(std::string(name()) + ": the observation has no usable features");
  action_size_ = env.action_space().size();
  norm_ = RunningNorm(d, options_.clip);
  const int n = env.num_envs();
  prev_.assign(static_cast<size_t>(n) * d, 0);
  next_.assign(prev_.size(), 0);
  starts_.assign(n, true);
  last_raw_.assign(n, 0);
  const size_t cap = options_.buffer;
  buf_next_.assign(cap * d, 0);
  if (transitions()) {
    buf_s_.assign(cap * d, 0);
    buf_a_.assign(cap * action_size_, 0);
  }
  filled_ = head_ = 0;
  if (!bound_) build(d, action_size_, gen_);
  bound_ = true;
}

void LearnedReward::observe(const VecEnv& env, std::vector<float>& rows) {
  const int d = features_.size();
  const std::span<float> used =
      std::span<float>(rows).first(static_cast<size_t>(env.num_envs()) * d);
  for (int i = 0; i < env.num_envs(); ++i) {
    features_.extract(env, i, used.subspan(static_cast<size_t>(i) * d, d));
  }
  norm_.update(used);
  norm_.apply(used);
}

void LearnedReward::reset(const VecEnv& env) {
  if (!bound_) bind(env);
  observe(env, next_);
  const size_t d = features_.size();
  for (int i = 0; i < env.num_envs(); ++i) {
    std::copy_n(&next_[i * d], d, &prev_[env.env_id(i) * d]);
  }
  starts_.assign(starts_.size(), false);
}

void LearnedReward::compute(const VecEnv& env, std::span<const double> actions,
                            std::span<double> rewards) {
  if (!bound_) bind(env);
  const int n = env.num_envs(), d = features_.size(), na = action_size_;
  observe(env, next_);

  // Rows that are samples: every env for state rewards, transitions only for the others.
  std::vector<int> rows;
  for (int i = 0; i < n; ++i) {
    if (!transitions() || !starts_[env.env_id(i)]) rows.push_back(i);
    last_raw_[env.env_id(i)] = 0;
  }
  if (!rows.empty()) {
    const long v = static_cast<long>(rows.size());
    torch::Tensor next = torch::empty({v, d}), s, a;
    if (transitions()) {
      s = torch::empty({v, d});
      a = torch::empty({v, na});
    }
    for (long r = 0; r < v; ++r) {
      const size_t i = rows[r];
      std::copy_n(&next_[i * d], d, next.data_ptr<float>() + r * d);
      if (transitions()) {
        std::copy_n(&prev_[env.env_id(i) * d], d, s.data_ptr<float>() + r * d);
        float* ap = a.data_ptr<float>() + r * na;
        for (int k = 0; k < na; ++k) ap[k] = static_cast<float>(actions[i * na + k]);
      }
    }
    torch::Tensor raw;
    {
      torch::NoGradGuard no_grad;
      raw = score(s, a, next).to(torch::kFloat64).contiguous();
    }
    const double* rp = raw.data_ptr<double>();
    for (long r = 0; r < v; ++r) reward_std_.update(rp[r]);
    for (long r = 0; r < v; ++r) {
      last_raw_[env.env_id(rows[r])] = rp[r];
      rewards[rows[r]] += scale() * reward_std_.scale(rp[r]);
    }
    // The samples join the ring.
    for (long r = 0; r < v; ++r) {
      const size_t i = rows[r], slot = head_;
      std::copy_n(&next_[i * d], d, &buf_next_[slot * d]);
      if (transitions()) {
        std::copy_n(&prev_[env.env_id(i) * d], d, &buf_s_[slot * d]);
        for (int k = 0; k < na; ++k)
          buf_a_[slot * na + k] = static_cast<float>(actions[i * na + k]);
      }
      head_ = (head_ + 1) % options_.buffer;
      filled_ = std::min(filled_ + 1, options_.buffer);
    }
  }
  // This step's features are each env's previous ones at its next step.
  for (int i = 0; i < n; ++i) {
    std::copy_n(&next_[static_cast<size_t>(i) * d], d,
                &prev_[static_cast<size_t>(env.env_id(i)) * d]);
  }
  starts_.record_flags(env);
}

void LearnedReward::update() {
  if (filled_ == 0) return;
  const int d = features_.size(), na = action_size_;
  const int batch = std::min(options_.batch, filled_);
  std::uniform_int_distribution<int> pick(0, filled_ - 1);
  auto draw = [&]() {
    Batch b{torch::empty({batch, d}), torch::Tensor(), torch::empty({batch, d})};
    if (transitions()) {
      b.s = torch::empty({batch, d});
      b.a = torch::empty({batch, na});
    }
    for (int r = 0; r < batch; ++r) {
      const size_t slot = pick(draw_);
      std::copy_n(&buf_next_[slot * d], d, b.next.data_ptr<float>() + static_cast<size_t>(r) * d);
      if (transitions()) {
        std::copy_n(&buf_s_[slot * d], d, b.s.data_ptr<float>() + static_cast<size_t>(r) * d);
        std::copy_n(&buf_a_[slot * na], na, b.a.data_ptr<float>() + static_cast<size_t>(r) * na);
      }
    }
    return b;
  };
  const int steps = std::clamp(
      static_cast<int>(std::ceil(options_.epochs * filled_ / static_cast<double>(batch))), 1,
      options_.max_steps);
  double loss = 0;
  for (int k = 0; k < steps; ++k) loss += train_step(draw);
  last_loss_ = loss / steps;
  filled_ = head_ = 0;
}

std::filesystem::path LearnedReward::file(const std::filesystem::path& dir, const char* ext) const {
  return dir / ("intrinsic_" + std::string(name()) + ext);
}

void LearnedReward::save(const std::filesystem::path& dir) const {
  if (!bound_) throw UserError(std::string(name()) + ": save before bind");
  torch::serialize::OutputArchive archive;
  save_models(archive);
  // The generator of the models' own draws (e.g. bootstrap masks), so a resumed run continues it.
  write_generator(archive, "generator", gen_);
  archive.save_to(file(dir, ".pt").string());
  // The minibatch generator's position too, so a resumed run draws the same minibatches.
  std::ostringstream draw;
  draw << draw_;
  const nlohmann::json state = {{"features", features_.size()},
                                {"norm", norm_.to_json()},
                                {"reward_std", reward_std_.to_json()},
                                {"draw", draw.str()}};
  std::ofstream out(file(dir, ".json"));
  out << state.dump() << "\n";
  if (!out) throw UserError("cannot write " + file(dir, ".json").string());
}

void LearnedReward::load(const std::filesystem::path& dir) {
  if (!bound_) throw UserError(std::string(name()) + ": load before bind");
  std::ifstream in(file(dir, ".json"));
  if (!in) throw UserError("cannot read " + file(dir, ".json").string());
  try {
    const nlohmann::json state = nlohmann::json::parse(in);
    if (state.at("features").get<int>() != features_.size()) {
      throw UserError(file(dir, ".json").string() + ": saved for another observation space");
    }
    norm_.from_json(state.at("norm"));
    reward_std_.from_json(state.at("reward_std"));
    // Files of earlier builds have no generator state: their minibatches restart from the seed.
    if (state.contains("draw")) {
      std::istringstream draw(state.at("draw").get<std::string>());
      draw >> draw_;
      if (!draw) throw UserError("malformed " + file(dir, ".json").string() + ": bad 'draw' state");
    }
    torch::serialize::InputArchive archive;
    archive.load_from(file(dir, ".pt").string());
    load_models(archive);
    // Files of earlier builds have no generator state.
    torch::Tensor generator;
    if (archive.try_read("generator", generator)) gen_.set_state(generator);
  } catch (const nlohmann::json::exception& e) {
    throw UserError("malformed " + file(dir, ".json").string() + ": " + e.what());
  } catch (const c10::Error& e) {
    throw UserError("cannot load " + file(dir, ".pt").string() + ": " + e.what_without_backtrace());
  }
}

}  // namespace cradle::learn::intrinsic
