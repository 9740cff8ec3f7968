// GoalGAN: a least-squares GAN whose discriminator learns which goals are of intermediate
// difficulty (success rate in [goid_lb, goid_ub] over n_rollouts tries) and whose generator then
// proposes such goals; successful goals are kept and replayed with probability p_old.
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/gmm.h"
#include "teach/teacher.h"
#include "teach/torch_util.h"

namespace cradle::teach {
namespace {

class GoalGanTeacher final : public Teacher {
 public:
  GoalGanTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                 GoalGanParams p)
      : Teacher(std::move(mins), std::move(maxs), seed), p_(std::move(p)), net_rng_(seed + 1) {
    // Check the parameters before anything depends on them.
    if (!(p_.state_noise_level >= 0)) throw UserError("goal_gan: state_noise_level must be >= 0");
    if (!(p_.success_distance_threshold >= 0))
      throw UserError("goal_gan: success_distance_threshold must be >= 0");
    if (p_.update_size < 1) throw UserError("goal_gan: update_size must be >= 1");
    if (p_.n_rollouts < 1) throw UserError("goal_gan: n_rollouts must be >= 1");
    if (!(p_.goid_lb >= 0 && p_.goid_lb <= p_.goid_ub && p_.goid_ub <= 1))
      throw UserError("goal_gan: expected 0 <= goid_lb <= goid_ub <= 1");
    if (!(p_.p_old >= 0 && p_.p_old <= 1)) throw UserError("goal_gan: p_old must lie in [0, 1]");
    if (p_.pretrain_samples < 1 || p_.pretrain_iterations < 0 || p_.train_iterations < 1 ||
        p_.batch_size < 1 || !(p_.lr > 0))
      throw UserError(
          "goal_gan: pretrain_samples, train_iterations and batch_size must be >= 1, "
          "pretrain_iterations >= 0 and lr > 0");
    if (p_.initial_dist) check_dist(*p_.initial_dist, "goal_gan: initial_dist");
    // Networks work on (task - centre) / range, the box mapped to [-0.5, 0.5].
    const int d = dims();
    for (int i = 0; i < d; ++i) {
      centre_.push_back(0.5f * (mins_[i] + maxs_[i]));
      range_.push_back(maxs_[i] - mins_[i] + 2e-6f);
    }
    // Generator: noise (d) -> 256 -> 256 (ReLU) -> d (tanh); discriminator: d -> 128 -> 128
    // (leaky ReLU 0.1) -> 1; Xavier initialisation; RMSProp for both.
    generator_ = torch::nn::Sequential(torch::nn::Linear(d, 256), torch::nn::ReLU(),
                                       torch::nn::Linear(256, 256), torch::nn::ReLU(),
                                       torch::nn::Linear(256, d), torch::nn::Tanh());
    const auto leaky = torch::nn::LeakyReLUOptions().negative_slope(0.1);
    discriminator_ = torch::nn::Sequential(torch::nn::Linear(d, 128), torch::nn::LeakyReLU(leaky),
                                           torch::nn::Linear(128, 128), torch::nn::LeakyReLU(leaky),
                                           torch::nn::Linear(128, 1));
    xavier_init(*generator_, net_rng_);
    xavier_init(*discriminator_, net_rng_);
    const auto opt = torch::optim::RMSpropOptions(p_.lr).alpha(0.9).eps(1e-10);  // TF's RMSProp
    g_opt_ = std::make_unique<torch::optim::RMSprop>(generator_->parameters(), opt);
    d_opt_ = std::make_unique<torch::optim::RMSprop>(discriminator_->parameters(), opt);
    // Pretraining: goals from the env's easy region (else a random sub-region), all labelled good.
    if (p_.use_pretrained_samples) {
      const DiagGaussian dist = p_.initial_dist ? *p_.initial_dist : dist_from_bounds(true);
      std::vector<Task> goals;
      for (int n = 0; n < p_.pretrain_samples; ++n) goals.push_back(gaussian_task(dist));
      train(goals, std::vector<bool>(goals.size(), true), p_.pretrain_iterations);
    }
  }

  Task sample_task() override {
    // Replays of the last generated goal first.
    if (!repeats_.empty()) {
      Task t = repeats_.front();
      repeats_.pop_front();
      return t;
    }
    // A successful goal again (p_old), else a fresh generated goal played n_rollouts times.
    if (!successes_.empty() && rng_.uniform() < p_.p_old) {
      const auto i = std::min(successes_.size() - 1,
                              static_cast<std::size_t>(rng_.uniform() * successes_.size()));
      return noisy(successes_[i]);
    }
    Task goal = noisy(generate());
    pending_[goal];
    for (int n = 1; n < p_.n_rollouts; ++n) repeats_.push_back(goal);
    return goal;
  }

  Task non_exploratory_task_sampling() override {
    Task goal = generate();
    clip(goal);
    return goal;
  }

  void episodic_update(const Task& task, double ret, bool success) override {
    check_episode(task, ret);
    // Only generated goals are labelled, once all their rollouts are in.
    auto it = pending_.find(task);
    if (it == pending_.end()) return;
    it->second.push_back(success);
    if (static_cast<int>(it->second.size()) < p_.n_rollouts) return;
    double rate = 0;
    for (bool s : it->second) rate += s;
    rate /= p_.n_rollouts;
    pending_.erase(it);
    const bool label = rate >= p_.goid_lb && rate <= p_.goid_ub;
    goals_.push_back(task);
    labels_.push_back(label);
    labelled_.push_back({{"goal", task}, {"success_rate", rate}, {"label", label}});
    // Too easy goals join the success buffer when no stored goal is that close.
    if (rate > p_.goid_ub) add_success(task);
    // Every update_size labels: train when at least one goal was of intermediate difficulty.
    if (static_cast<int>(goals_.size()) >= p_.update_size) {
      if (std::find(labels_.begin(), labels_.end(), true) != labels_.end())
        train(goals_, labels_, p_.train_iterations);
      goals_.clear();
      labels_.clear();
    }
  }

  nlohmann::json dump() const override {
    nlohmann::json j = Teacher::dump();
    j["labelled_goals"] = labelled_;  // goal, success rate, label
    j["success_buffer"] = successes_.size();
    j["trainings"] = losses_;  // per training: iterations, last discriminator and generator loss
    return j;
  }
  const char* name() const override { return "goal_gan"; }

 private:
  // One goal from the generator, in task units (not clipped).
  Task generate() {
    torch::NoGradGuard no_grad;
    const torch::Tensor out = generator_->forward(normal_tensor(net_rng_, 1, dims()));
    Task goal(dims());
    for (int i = 0; i < dims(); ++i) goal[i] = centre_[i] + out[0][i].item<float>() * range_[i];
    return goal;
  }
  // Gaussian noise of noise_level * range per dimension, clipped to the box.
  Task noisy(Task goal) {
    for (int i = 0; i < dims(); ++i)
      goal[i] +=
          static_cast<float>(p_.state_noise_level * (maxs_[i] - mins_[i]) * standard_normal(rng_));
    clip(goal);
    return goal;
  }
  void add_success(const Task& goal) {
    double diag = 0;
    for (int i = 0; i < dims(); ++i) diag += (maxs_[i] - mins_[i]) * (maxs_[i] - mins_[i]);
    const double limit = p_.success_distance_threshold * std::sqrt(diag);
    for (const Task& s : successes_) {
      double dist = 0;
      for (int i = 0; i < dims(); ++i) dist += (s[i] - goal[i]) * (s[i] - goal[i]);
      if (std::sqrt(dist) <= limit) return;
    }
    successes_.push_back(goal);
  }
  // LSGAN outer iterations: one discriminator step on batch_size labelled goals plus as many
  // generated ones (label 0), then one generator step.
  void train(const std::vector<Task>& goals, const std::vector<bool>& labels, int iterations) {
    std::vector<Task> norm;
    for (const Task& g : goals) {
      Task n(dims());
      for (int i = 0; i < dims(); ++i) n[i] = (g[i] - centre_[i]) / range_[i];
      norm.push_back(std::move(n));
    }
    const torch::Tensor x = rows_tensor(norm);
    torch::Tensor y = torch::empty({static_cast<std::int64_t>(labels.size()), 1});
    for (std::size_t i = 0; i < labels.size(); ++i) y[i][0] = labels[i] ? 1.f : 0.f;
    const int b = p_.batch_size;
    double d_loss = 0, g_loss = 0;
    for (int it = 0; it < iterations; ++it) {
      // Discriminator: labelled goals toward 2y - 1, generated goals toward -1.
      std::vector<std::int64_t> idx(b);
      for (auto& i : idx)
        i = std::min<std::int64_t>(x.size(0) - 1,
                                   static_cast<std::int64_t>(net_rng_.uniform() * x.size(0)));
      const torch::Tensor index = torch::tensor(idx);
      torch::Tensor fake;
      {
        torch::NoGradGuard no_grad;
        fake = generator_->forward(normal_tensor(net_rng_, b, dims()));
      }
      const torch::Tensor real_target = 2 * y.index_select(0, index) - 1;
      const torch::Tensor d_real = discriminator_->forward(x.index_select(0, index));
      const torch::Tensor d_fake = discriminator_->forward(fake);
      const torch::Tensor dl = torch::cat({d_real - real_target, d_fake + 1}).pow(2).mean();
      d_opt_->zero_grad();
      dl.backward();
      d_opt_->step();
      // Generator: its goals toward the discriminator's "good" (1).
      const torch::Tensor gen = generator_->forward(normal_tensor(net_rng_, b, dims()));
      const torch::Tensor gl = (discriminator_->forward(gen) - 1).pow(2).mean();
      g_opt_->zero_grad();
      gl.backward();
      g_opt_->step();
      d_loss = dl.item<double>();
      g_loss = gl.item<double>();
    }
    losses_.push_back({{"iterations", iterations},
                       {"goals", goals.size()},
                       {"discriminator_loss", d_loss},
                       {"generator_loss", g_loss}});
  }

  GoalGanParams p_;
  Rng net_rng_;
  std::vector<float> centre_, range_;
  torch::nn::Sequential generator_{nullptr}, discriminator_{nullptr};
  std::unique_ptr<torch::optim::RMSprop> g_opt_, d_opt_;
  std::deque<Task> repeats_;
  std::map<Task, std::vector<bool>> pending_;
  std::vector<Task> goals_, successes_;
  std::vector<bool> labels_;
  nlohmann::json labelled_ = nlohmann::json::array(), losses_ = nlohmann::json::array();
};

}  // namespace

std::unique_ptr<Teacher> make_goal_gan_teacher(std::vector<float> mins, std::vector<float> maxs,
                                               std::uint64_t seed, GoalGanParams params) {
  return std::make_unique<GoalGanTeacher>(std::move(mins), std::move(maxs), seed,
                                          std::move(params));
}

}  // namespace cradle::teach
