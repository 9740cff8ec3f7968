// Setter-Solver: a setter (a conditional RealNVP flow over goals in [0, 1]^d) proposes goals of a
// desired feasibility f, and a judge learns from binary success how feasible each goal is. The
// setter is trained so the judge finds its goals as feasible as asked (feasibility), to give
// likelihood to goals that were solved (validity), and to spread out (coverage).
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/teacher.h"
#include "teach/torch_util.h"

namespace cradle::teach {
namespace {

namespace nn = torch::nn;

// in -> H (tanh) -> 3 highway blocks (sigmoid gate, tanh candidate) -> out.
struct HighwayImpl : nn::Module {
  HighwayImpl(int in, int hidden, int out) {
    input = register_module("input", nn::Linear(in, hidden));
    for (int i = 0; i < 3; ++i) {
      gates.push_back(register_module("gate" + std::to_string(i), nn::Linear(hidden, hidden)));
      cands.push_back(register_module("cand" + std::to_string(i), nn::Linear(hidden, hidden)));
    }
    output = register_module("output", nn::Linear(hidden, out));
  }
  torch::Tensor forward(torch::Tensor x) {
    torch::Tensor h = torch::tanh(input(x));
    for (int i = 0; i < 3; ++i) {
      const torch::Tensor g = torch::sigmoid(gates[i](h));
      h = g * torch::tanh(cands[i](h)) + (1 - g) * h;
    }
    return output(h);
  }
  nn::Linear input{nullptr}, output{nullptr};
  std::vector<nn::Linear> gates, cands;
};
TORCH_MODULE(Highway);

// A slowly decaying softplus: x (atan(x) / pi + 1/2) + 1/pi, with its asymptote 1 / (3 pi x^2)
// below -30 where the closed form loses precision.
torch::Tensor slow_softplus(const torch::Tensor& x) {
  const double pi = std::numbers::pi;
  const torch::Tensor c = x.clamp(-1e6, 1e6);
  const torch::Tensor far = 1.0 / (3 * pi * c.pow(2) + 1e-30);
  const torch::Tensor near = c * (torch::atan(c) / pi + 0.5) + 1 / pi;
  return torch::where(c < -30, far, near);
}

// One affine coupling: the `moved` coordinates are scaled and shifted by nets of the `kept` ones
// and the feasibility.
struct Coupling {
  torch::Tensor kept, moved;  // index tensors
  Highway scale{nullptr}, shift{nullptr};
};

class SetterSolverTeacher final : public Teacher {
 public:
  SetterSolverTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                      SetterSolverParams p)
      : Teacher(std::move(mins), std::move(maxs), seed), p_(p), net_rng_(seed + 1) {
    // Check the parameters before anything depends on them.
    if (p_.update_frequency < 1) throw UserError("setter_solver: update_frequency must be >= 1");
    if (!(p_.setter_loss_noise_ub >= 0))
      throw UserError("setter_solver: setter_loss_noise_ub must be >= 0");
    if (p_.setter_hidden_size < 1)
      throw UserError("setter_solver: setter_hidden_size must be >= 1");
    if (!(p_.lr > 0)) throw UserError("setter_solver: lr must be > 0");
    // Setter: 3 blocks of couplings left->right, right->left, interlaced (even -> odd).
    const int d = dims(), half = d / 2;
    std::vector<std::pair<std::vector<long>, std::vector<long>>> splits;
    std::vector<long> left, right, even, odd;
    for (int i = 0; i < d; ++i) {
      (i < half ? left : right).push_back(i);
      (i % 2 == 0 ? even : odd).push_back(i);
    }
    splits = {{left, right}, {right, left}, {even, odd}};
    for (int block = 0; block < 3; ++block)
      for (const auto& [kept, moved] : splits) {
        if (moved.empty()) continue;  // 1-D spaces: nothing to move
        Coupling c;
        c.kept = torch::tensor(kept, torch::kLong);
        c.moved = torch::tensor(moved, torch::kLong);
        const int in = static_cast<int>(kept.size()) + 1, out = static_cast<int>(moved.size());
        const std::string id = std::to_string(couplings_.size());
        c.scale = setter_->register_module("s" + id, Highway(in, p_.setter_hidden_size, out));
        c.shift = setter_->register_module("t" + id, Highway(in, p_.setter_hidden_size, out));
        couplings_.push_back(std::move(c));
      }
    // Judge: goal -> 64 -> 64 (ReLU) -> feasibility logit.
    judge_ = nn::Sequential(nn::Linear(d, 64), nn::ReLU(), nn::Linear(64, 64), nn::ReLU(),
                            nn::Linear(64, 1));
    xavier_init(*setter_, net_rng_);
    xavier_init(*judge_, net_rng_);
    setter_opt_ = std::make_unique<torch::optim::Adam>(setter_->parameters(),
                                                       torch::optim::AdamOptions(p_.lr));
    judge_opt_ = std::make_unique<torch::optim::Adam>(judge_->parameters(),
                                                      torch::optim::AdamOptions(p_.lr));
  }

  Task sample_task() override {
    // A fresh desired feasibility and a goal of the setter for it.
    torch::NoGradGuard no_grad;
    const torch::Tensor f = uniform_tensor(net_rng_, 1, 1, 1e-8, 1);
    const torch::Tensor g = forward(normal_tensor(net_rng_, 1, dims()), f).first;
    Task unit(dims()), task(dims());
    for (int i = 0; i < dims(); ++i) {
      unit[i] = g[0][i].item<float>();
      task[i] = mins_[i] + unit[i] * (maxs_[i] - mins_[i]);
    }
    clip(task);
    pending_[task] = {unit, f[0][0].item<float>()};
    return task;
  }

  void episodic_update(const Task& task, double ret, bool success) override {
    check_episode(task, ret);
    // The pending goal of this task joins the buffer; every update_frequency episodes, train.
    auto it = pending_.find(task);
    if (it != pending_.end()) {
      goals_.push_back(it->second.first);
      feasibilities_.push_back(it->second.second);
      successes_.push_back(success);
      pending_.erase(it);
    }
    if (++episodes_ % p_.update_frequency == 0 && !goals_.empty()) update();
  }

  nlohmann::json dump() const override {
    nlohmann::json j = Teacher::dump();
    j["episodes"] = episodes_;
    j["updates"] = updates_;  // per update: episodes, judge loss and accuracy, setter losses
    return j;
  }
  const char* name() const override { return "setter_solver"; }

 private:
  // Latents z (n x d) and feasibilities f (n x 1) -> goals in (0, 1) and their log-densities.
  std::pair<torch::Tensor, torch::Tensor> forward(torch::Tensor z, const torch::Tensor& f) {
    const double log_2pi = std::log(2 * std::numbers::pi);
    torch::Tensor log_p = -0.5 * (z.pow(2) + log_2pi).sum(1);
    for (auto& c : couplings_) {
      const torch::Tensor in = torch::cat({z.index_select(1, c.kept), f}, 1);
      const torch::Tensor scale = 0.01 + slow_softplus(c.scale->forward(in));
      const torch::Tensor moved = z.index_select(1, c.moved) * scale + c.shift->forward(in);
      z = z.index_copy(1, c.moved, moved);
      log_p = log_p - torch::log(scale).sum(1);
    }
    const torch::Tensor g = torch::sigmoid(z);
    log_p = log_p - torch::log(g * (1 - g) + 1e-12).sum(1);
    return {g, log_p};
  }
  // log p(g | f) of given goals in (0, 1), through the inverse flow.
  torch::Tensor log_prob(const torch::Tensor& g, const torch::Tensor& f) {
    const double log_2pi = std::log(2 * std::numbers::pi);
    torch::Tensor z = torch::log(g) - torch::log(1 - g);  // inverse sigmoid
    torch::Tensor log_det = torch::log(g * (1 - g)).sum(1);
    for (auto c = couplings_.rbegin(); c != couplings_.rend(); ++c) {
      const torch::Tensor in = torch::cat({z.index_select(1, c->kept), f}, 1);
      const torch::Tensor scale = 0.01 + slow_softplus(c->scale->forward(in));
      const torch::Tensor moved = (z.index_select(1, c->moved) - c->shift->forward(in)) / scale;
      z = z.index_copy(1, c->moved, moved);
      log_det = log_det + torch::log(scale).sum(1);
    }
    return -0.5 * (z.pow(2) + log_2pi).sum(1) - log_det;
  }

  // One Adam step on the judge (cross-entropy on success), then one on the setter.
  void update() {
    const auto n = static_cast<std::int64_t>(goals_.size());
    const torch::Tensor g = rows_tensor(goals_);
    torch::Tensor f = torch::empty({n, 1}), y = torch::empty({n, 1});
    for (std::int64_t i = 0; i < n; ++i) {
      f[i][0] = feasibilities_[i];
      y[i][0] = successes_[i] ? 1.f : 0.f;
    }
    // Judge.
    const torch::Tensor logits = judge_->forward(g);
    const torch::Tensor judge_loss = torch::binary_cross_entropy_with_logits(logits, y);
    const double accuracy =
        ((logits > 0).to(torch::kFloat) == y).to(torch::kFloat).mean().item<double>();
    judge_opt_->zero_grad();
    judge_loss.backward();
    judge_opt_->step();
    // Setter: feasibility and coverage on fresh goals, validity on the solved ones (jittered).
    const torch::Tensor fresh_f = uniform_tensor(net_rng_, n, 1, 1e-8, 1);
    const auto [fresh, fresh_log_p] = forward(normal_tensor(net_rng_, n, dims()), fresh_f);
    const torch::Tensor feasibility =
        (judge_->forward(fresh) - torch::log(fresh_f / (1 - fresh_f))).pow(2).mean();
    const torch::Tensor coverage = fresh_log_p.mean();
    torch::Tensor validity = torch::zeros({});
    const torch::Tensor solved = torch::nonzero(y.squeeze(1)).squeeze(1);
    if (solved.numel() > 0) {
      const torch::Tensor jitter =
          uniform_tensor(net_rng_, solved.numel(), dims(), 0, p_.setter_loss_noise_ub);
      const torch::Tensor noisy = (g.index_select(0, solved) + jitter).clamp(1e-4, 1 - 1e-4);
      validity = -log_prob(noisy, f.index_select(0, solved)).mean();
    }
    const torch::Tensor setter_loss = feasibility + validity + coverage;
    setter_opt_->zero_grad();
    setter_loss.backward();
    setter_opt_->step();
    updates_.push_back({{"episodes", episodes_},
                        {"goals", n},
                        {"judge_loss", judge_loss.item<double>()},
                        {"judge_accuracy", accuracy},
                        {"feasibility_loss", feasibility.item<double>()},
                        {"validity_loss", validity.item<double>()},
                        {"coverage_loss", coverage.item<double>()}});
    goals_.clear();
    feasibilities_.clear();
    successes_.clear();
  }

  SetterSolverParams p_;
  Rng net_rng_;
  std::shared_ptr<nn::Module> setter_ = std::make_shared<nn::Module>();
  std::vector<Coupling> couplings_;
  nn::Sequential judge_{nullptr};
  std::unique_ptr<torch::optim::Adam> setter_opt_, judge_opt_;
  std::map<Task, std::pair<std::vector<float>, float>> pending_;  // task -> unit goal, f
  std::vector<std::vector<float>> goals_;
  std::vector<float> feasibilities_;
  std::vector<bool> successes_;
  long episodes_ = 0;
  nlohmann::json updates_ = nlohmann::json::array();
};

}  // namespace

std::unique_ptr<Teacher> make_setter_solver_teacher(std::vector<float> mins,
                                                    std::vector<float> maxs, std::uint64_t seed,
                                                    SetterSolverParams params) {
  return std::make_unique<SetterSolverTeacher>(std::move(mins), std::move(maxs), seed, params);
}

}  // namespace cradle::teach
