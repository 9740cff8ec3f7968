// SAC, TD3 and DDPG: the replay buffer's bookkeeping under next-step autoreset, its memory
// check, strict hyperparameters, checkpoints, and learning on the inline Pendulum swing-up.
#include "learn/off_policy.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "learn/checkpoint.h"
#include "learn/registry.h"
#include "learn/replay_buffer.h"
#include "test_tasks.h"

namespace cradle::learn {
namespace {

// ---------------------------------------------------------------------------------------------
// A scripted env: observation [length, episode, t], reward 100 episode + t after step t,
// episodes of `length` steps that end terminated when the episode number is even, truncated
// when odd.
class ScriptedEnv final : public envs::Env {
 public:
  ScriptedEnv(int length, double bound)
      : space_(make_space()),
        action_space_(Box::uniform({1}, DType::kFloat32, -bound, bound)),
        obs_(space_),
        length_(length) {}
  const DictSpace& observation_space() const override { return space_; }
  const Box& action_space() const override { return action_space_; }
  const envs::ObservationBuffers& observation() const override { return obs_; }
  const envs::Info& info() const override { return info_; }
  void reset(std::optional<std::uint64_t>) override {
    ++episode_;
    t_ = 0;
    info_.steps = 0;
    observe();
  }
  envs::StepResult step(std::span<const double> action) override {
    if (--steps_to_failure_ == 0) throw std::runtime_error("scripted env failure");
    last_action_ = action[0];
    ++t_;
    info_.steps = t_;
    observe();
    const bool ended = t_ == length_;
    return {.reward = 100.0 * episode_ + t_,
            .terminated = ended && episode_ % 2 == 0,
            .truncated = ended && episode_ % 2 == 1};
  }
  double last_action() const { return last_action_; }
  void fail_at_step(long step) { steps_to_failure_ = step; }

 private:
  static DictSpace make_space() {
    DictSpace space;
    space.entries.push_back({"observation", Box::unbounded({3}, DType::kFloat64)});
    return space;
  }
  void observe() {
    obs_.f64(0)[0] = length_;
    obs_.f64(0)[1] = episode_;
    obs_.f64(0)[2] = t_;
  }
  DictSpace space_;
  Box action_space_;
  envs::ObservationBuffers obs_;
  envs::Info info_;
  int length_, episode_ = -1, t_ = 0;
  double last_action_ = 0;
  long steps_to_failure_ = -1;  // step() throws when this reaches 0
};

std::unique_ptr<ThreadedVecEnv> make_scripted(std::vector<int> lengths, double bound = 2.0) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int length : lengths) list.push_back(std::make_unique<ScriptedEnv>(length, bound));
  return std::make_unique<ThreadedVecEnv>(std::move(list), /*threads=*/1);
}

TEST(ReplayBuffer, StoresRealTransitionsAndSkipsAutoresets) {
  auto env = make_scripted({3, 4});
  ObservationPipeline pipeline(env->observation_space(), {.normalize_observations = false},
                               nullptr);
  ReplayBuffer buffer(1000, pipeline.shape(), 1);
  TransitionCollector collector(*env, pipeline, {});
  collector.start(1);
  const int steps = 20;
  for (int t = 0; t < steps; ++t) {
    // Action 0.5 in [-1, 1] reaches the env as 1.0 in [-2, 2].
    collector.step(torch::full({2, 1}, 0.5f), buffer);
    EXPECT_DOUBLE_EQ(dynamic_cast<const ScriptedEnv&>(env->env(0)).last_action(), 1.0);
  }
  // Env 0: episodes of 3 steps + 1 autoreset step -> 20 / 4 * 3 = 15 transitions. Env 1:
  // 5 steps per cycle -> 4 cycles x 4 = 16.
  ASSERT_EQ(buffer.size(), 31);
  const ReplayBuffer::Sample all = buffer.gather(torch::arange(buffer.size()));
  int terminated = 0, truncated = 0;
  for (long i = 0; i < buffer.size(); ++i) {
    const auto row = all.observations.vector[i];
    const auto next = all.next_observations.vector[i];
    const float length = row[0].item<float>(), episode = row[1].item<float>();
    const float t = row[2].item<float>(), next_t = next[2].item<float>();
    // (s, a, r, s') of one episode: s' is the step after s, never another episode's start.
    EXPECT_EQ(next[0].item<float>(), length);
    EXPECT_EQ(next[1].item<float>(), episode);
    EXPECT_EQ(next_t, t + 1);
    EXPECT_LT(t, length);  // no transition starts from a final observation
    EXPECT_FLOAT_EQ(all.rewards[i].item<float>(), 100.0f * episode + next_t);
    EXPECT_FLOAT_EQ(all.actions[i][0].item<float>(), 0.5f);
    // Terminated only on the last step of an even episode; a truncated last step (odd
    // episode) is stored as an ordinary transition whose s' is the final observation.
    const bool last = next_t == length;
    const bool even = static_cast<int>(episode) % 2 == 0;
    EXPECT_EQ(all.terminated[i].item<float>(), last && even ? 1.0f : 0.0f);
    terminated += last && even;
    truncated += last && !even;
  }
  // Env 0 ended episodes 0..4 (0, 2, 4 terminated), env 1 episodes 0..3 (0, 2 terminated).
  EXPECT_EQ(terminated, 5);
  EXPECT_EQ(truncated, 4);
}

TEST(ReplayBuffer, OverwritesTheOldestWhenFull) {
  auto env = make_scripted({100});
  ObservationPipeline pipeline(env->observation_space(), {.normalize_observations = false},
                               nullptr);
  ReplayBuffer buffer(5, pipeline.shape(), 1);
  TransitionCollector collector(*env, pipeline, {});
  collector.start(1);
  for (int t = 0; t < 12; ++t) collector.step(torch::zeros({1, 1}), buffer);
  ASSERT_EQ(buffer.size(), 5);
  // Transitions 0..11 written in a ring of 5: slots hold t = 10, 11, 7, 8, 9.
  const ReplayBuffer::Sample all = buffer.gather(torch::arange(5));
  const std::vector<float> expected = {10, 11, 7, 8, 9};
  for (int i = 0; i < 5; ++i) EXPECT_EQ(all.observations.vector[i][2].item<float>(), expected[i]);
}

TEST(ReplayBuffer, MemoryRuleNamesBufferSizeAndBytes) {
  // Two 64x64x3 eyes and 100 floats: (2 x 2 x 12,288) + 800 + 80 + 5 bytes a transition.
  const ObsShape eyes{.vector_size = 100, .images = {{64, 64, 3}, {64, 64, 3}}};
  EXPECT_DOUBLE_EQ(replay_bytes(1, eyes, 20), 49152 + 800 + 80 + 5);
  EXPECT_NEAR(replay_bytes(1'000'000, eyes, 20), 50.0e9, 0.1e9);
  try {
    check_replay_memory("sac", 1'000'000, eyes, 20, /*limit_bytes=*/8e9);
    FAIL() << "expected a UserError";
  } catch (const UserError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("buffer_size = 1000000"), std::string::npos) << message;
    EXPECT_NE(message.find("50.0 GB"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(check_replay_memory("sac", 100'000, eyes, 20, 8e9));
  EXPECT_THROW(check_replay_memory("sac", 0, eyes, 20, 8e9), UserError);
  // Through the learners, against this machine's memory: a buffer no machine holds.
  auto env = testing::make_cartpoles(1, 30, /*with_image=*/true);
  for (const char* algorithm : {"sac", "td3", "ddpg"}) {
    EXPECT_THROW(make_learner(algorithm, *env, {.hyperparameters = {{"buffer_size", "100000000"}}}),
                 UserError)
        << algorithm;
  }
}

TEST(OffPolicy, RejectsBadSettingsAndUnboundedActions) {
  auto env = testing::make_cartpoles(1, 30);
  const std::vector<std::pair<std::string, std::map<std::string, std::string>>> bad = {
      {"sac", {{"ent_coef", "autox"}}},
      {"sac", {{"ent_coef", "-1"}}},
      {"sac", {{"ent_coef", "auto_abc"}}},
      {"sac", {{"target_entropy", "high"}}},
      {"sac", {{"batch_size", "0"}}},
      {"sac", {{"tau", "2"}}},
      {"sac", {{"n_critics", "0"}}},
      {"sac", {{"buffer_size", "0"}}},
      {"sac", {{"n_stepz", "1"}}},
      {"td3", {{"policy_delay", "0"}}},
      {"td3", {{"exploration_noise", "-1"}}},
      {"td3", {{"learning_rate", "fast"}}},
      {"ddpg", {{"policy_delay", "2"}}},
      {"ddpg", {{"n_critics", "2"}}},
  };
  for (const auto& [algorithm, hyperparameters] : bad) {
    EXPECT_THROW(make_learner(algorithm, *env, {.hyperparameters = hyperparameters}), UserError)
        << algorithm << " " << hyperparameters.begin()->first;
  }
  auto unbounded = make_scripted({5}, std::numeric_limits<double>::infinity());
  EXPECT_THROW(make_learner("sac", *unbounded, {}), UserError);
}

// ---------------------------------------------------------------------------------------------
// Fused critics

// The fused critics start from the values n separate Linear MLPs draw from the same generator,
// and compute what those MLPs compute (forward, q1 and gradients), for relu and tanh.
TEST(FusedCritic, MatchesSeparateMlpsWithCopiedWeights) {
  for (const std::string activation : {"relu", "tanh"}) {
    SCOPED_TRACE(activation);
    const ObsShape shape{.vector_size = 7};
    const OffPolicyNetworkConfig config{.qf_layers = {16, 8}, .activation = activation};
    at::Generator fused_generator = at::make_generator<at::CPUGeneratorImpl>(11);
    Critic fused(shape, 3, 2, config, fused_generator);
    at::Generator separate_generator = at::make_generator<at::CPUGeneratorImpl>(11);
    std::vector<torch::nn::Sequential> separate;
    for (int i = 0; i < 2; ++i) {
      torch::nn::Sequential q = make_mlp(10, config.qf_layers, activation);
      q->push_back(torch::nn::Linear(8, 1));
      init_layers(*q, 1.0, /*orthogonal=*/false, separate_generator);
      separate.push_back(q);
    }
    // Same initial values, bit for bit.
    for (int i = 0; i < 2; ++i) {
      size_t l = 0;
      for (const auto& child : separate[i]->children()) {
        auto* linear = child->as<torch::nn::Linear>();
        if (linear == nullptr) continue;
        EXPECT_TRUE(torch::equal(fused->weight(l)[i], linear->weight.t()));
        EXPECT_TRUE(torch::equal(fused->bias(l)[i][0], linear->bias));
        ++l;
      }
      EXPECT_EQ(l, fused->layers());
    }
    // Same values and gradients on a batch.
    ObsBatch obs = ObsBatch::zeros(shape, 5);
    obs.vector.copy_(torch::randn({5, 7}, fused_generator));
    const torch::Tensor actions = torch::rand({5, 3}, fused_generator) * 2 - 1;
    const torch::Tensor q = fused->forward(obs, actions);
    ASSERT_EQ(q.sizes(), (std::vector<int64_t>{2, 5}));
    const torch::Tensor input = torch::cat({obs.vector, actions}, 1);
    std::vector<torch::Tensor> expected;
    for (auto& mlp : separate) expected.push_back(mlp->forward(input).squeeze(1));
    EXPECT_TRUE(torch::allclose(q, torch::stack(expected), 1e-5, 1e-6));
    EXPECT_TRUE(torch::allclose(fused->q1(obs, actions), expected[0], 1e-5, 1e-6));
    q.square().sum().backward();
    (expected[0].square().sum() + expected[1].square().sum()).backward();
    for (int i = 0; i < 2; ++i) {
      const auto* first = separate[i]->children()[0]->as<torch::nn::Linear>();
      EXPECT_TRUE(
          torch::allclose(fused->weight(0).grad()[i], first->weight.grad().t(), 1e-4, 1e-5));
      EXPECT_TRUE(torch::allclose(fused->bias(0).grad()[i][0], first->bias.grad(), 1e-4, 1e-5));
    }
    // The actions' gradient (the actor's loss), through both Qs and through Q1 alone.
    const torch::Tensor fused_actions = actions.clone().requires_grad_(true);
    const torch::Tensor separate_input = input.clone().requires_grad_(true);
    fused->forward(obs, fused_actions).sum().backward();
    (separate[0]->forward(separate_input).sum() + separate[1]->forward(separate_input).sum())
        .backward();
    EXPECT_TRUE(
        torch::allclose(fused_actions.grad(), separate_input.grad().narrow(1, 7, 3), 1e-4, 1e-5));
    const torch::Tensor q1_actions = actions.clone().requires_grad_(true);
    const torch::Tensor q1_input = input.clone().requires_grad_(true);
    fused->q1(obs, q1_actions).sum().backward();
    separate[0]->forward(q1_input).sum().backward();
    EXPECT_TRUE(torch::allclose(q1_actions.grad(), q1_input.grad().narrow(1, 7, 3), 1e-4, 1e-5));
  }
}

// A critic saved as separate MLPs (q1, q2: checkpoints from before the fused critics) is
// refused with one line naming both formats; a fused one passes.
TEST(FusedCritic, RefusesTheSeparateMlpFormat) {
  auto archive_of = [](const std::string& child) {
    torch::serialize::OutputArchive out, critic, q;
    q.write("weight", torch::zeros({1, 2}));
    critic.write(child, q);
    out.write("critic", critic);
    std::ostringstream bytes;
    out.save_to(bytes);
    auto in = std::make_unique<torch::serialize::InputArchive>();
    std::istringstream stream(bytes.str());
    in->load_from(stream);
    return in;
  };
  try {
    check_critic_format(*archive_of("q1"), "critic");
    ADD_FAILURE() << "the separate-MLP format was accepted";
  } catch (const UserError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("separate critic MLPs"), std::string::npos) << message;
    EXPECT_NE(message.find("fused critics"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_NO_THROW(check_critic_format(*archive_of("encoder"), "critic"));
}

// ---------------------------------------------------------------------------------------------
// Checkpoints

// Small networks and buffer, so the tests stay quick.
std::map<std::string, std::string> small(std::map<std::string, std::string> extra = {}) {
  std::map<std::string, std::string> hp = {{"pi_layers", "32,32"},    {"qf_layers", "32,32"},
                                           {"batch_size", "32"},      {"buffer_size", "2000"},
                                           {"learning_starts", "50"}, {"report_every", "64"}};
  for (const auto& [name, value] : extra) hp[name] = value;
  return hp;
}

std::vector<double> actions_of(Learner& learner, bool with_image, bool deterministic) {
  auto env = testing::make_cartpoles(1, 200, with_image);
  env->reset(123);
  std::vector<double> actions;
  const std::vector<double> push = {1.5};
  for (int i = 0; i < 5; ++i) {
    double a = 0;
    learner.act(env->observation(0), {&a, 1}, deterministic);
    actions.push_back(a);
    env->step(push);
  }
  return actions;
}

std::vector<double> train_losses(Learner& learner, long steps) {
  std::vector<double> losses;
  learner.learn(steps, [&](const TrainStats& stats) {
    for (const auto& [name, value] : stats.losses) {
      if (!name.ends_with("_seconds")) losses.push_back(value);  // timings vary
    }
    return true;
  });
  return losses;
}

void check_checkpoint(const std::string& algorithm, bool with_image) {
  SCOPED_TRACE(algorithm);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("cradle_" + algorithm + "_offpolicy.pt");
  auto env_a = testing::make_cartpoles(2, 30, with_image);
  auto env_b = testing::make_cartpoles(2, 30, with_image);
  auto a = make_learner(algorithm, *env_a, {.seed = 3, .hyperparameters = small()});
  auto b = make_learner(algorithm, *env_b, {.seed = 99, .hyperparameters = small()});
  // Images make every update a few CNN passes: fewer steps then.
  const long steps = with_image ? 100 : 200, more = with_image ? 64 : 256;
  EXPECT_FALSE(train_losses(*a, steps).empty());
  EXPECT_NE(actions_of(*a, with_image, true), actions_of(*b, with_image, true));
  a->save(file);
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".tmp"));
  b->load(file);
  EXPECT_EQ(b->steps(), a->steps());
  const CheckpointInfo info = read_checkpoint_info(file);
  EXPECT_EQ(info.algorithm, algorithm);
  EXPECT_EQ(info.config, a->config_text());

  // Deterministic actions, then sampled ones (same generator state), agree.
  const std::vector<double> deterministic = actions_of(*a, with_image, true);
  EXPECT_EQ(deterministic, actions_of(*b, with_image, true));
  EXPECT_EQ(actions_of(*a, with_image, false), actions_of(*b, with_image, false));
  for (double action : deterministic) EXPECT_LE(std::fabs(action), 3.0);

  // The loaded learner continues: its empty buffer refills (learning_starts transitions)
  // before it trains again.
  long buffer = 0;
  b->learn(b->steps() + more, [&](const TrainStats& stats) {
    buffer = static_cast<long>(stats.losses.at("buffer_transitions"));
    return true;
  });
  EXPECT_GE(b->steps(), a->steps() + more);
  EXPECT_GT(buffer, more / 2);  // what this learn() call collected, autoreset steps aside
  EXPECT_LE(buffer, more);

  // Another algorithm's or another shape's learner refuses the file.
  auto env_c = testing::make_cartpoles(1, 30, with_image);
  auto other =
      make_learner(algorithm == "sac" ? "td3" : "sac", *env_c, {.hyperparameters = small()});
  EXPECT_THROW(other->load(file), UserError);
  // Critics of another shape: refused before anything changes (the actor, read first, fits).
  auto wide = make_learner(algorithm, *env_c, {.hyperparameters = small({{"qf_layers", "16"}})});
  const std::vector<double> before = actions_of(*wide, with_image, true);
  EXPECT_THROW(wide->load(file), UserError);
  EXPECT_EQ(actions_of(*wide, with_image, true), before);
  EXPECT_EQ(wide->steps(), 0);
  std::filesystem::remove(file);
}

TEST(OffPolicyCheckpoint, SacWithImagesRestoresActions) { check_checkpoint("sac", true); }
TEST(OffPolicyCheckpoint, Td3RestoresActions) { check_checkpoint("td3", false); }
TEST(OffPolicyCheckpoint, DdpgRestoresActions) { check_checkpoint("ddpg", false); }

// SpinningUp's schedule: ceil(length / 10) updates when each episode ends, none in between.
TEST(Sac, TrainsAtEpisodeEndsWithEpisodeTrainFreq) {
  auto env = testing::make_pendulums(2, 25);
  auto sac = make_learner("sac", *env,
                          {.seed = 1,
                           .hyperparameters = {{"episode_train_freq", "10"},
                                               {"learning_starts", "0"},
                                               {"batch_size", "8"},
                                               {"pi_layers", "8"},
                                               {"qf_layers", "8"},
                                               {"report_every", "1"}}});
  std::vector<double> updates;
  sac->learn(200, [&](const TrainStats& s) {
    updates.push_back(s.losses.at("updates"));
    return true;
  });
  // 100 vector steps of two envs: 26 per episode (25 steps and the autoreset), 3 episodes each.
  ASSERT_EQ(updates.size(), 100u);
  EXPECT_EQ(updates[23], 0);  // nothing before the first episode ends (step 25)
  EXPECT_EQ(updates[24], 6);  // two episodes of 25 steps: 2 x ceil(25 / 10)
  EXPECT_EQ(updates[49], 6);
  EXPECT_EQ(updates.back(), 18);
  EXPECT_THROW(make_learner("sac", *env, {.hyperparameters = {{"episode_train_freq", "-1"}}}),
               UserError);
}

TEST(Sac, ValueIsTheCriticAtTheDeterministicActionAndRises) {
  // CartPole pays 1 per step: min_i Q_i(s, tanh(mean(s))) of a start state grows with training.
  auto env = testing::make_cartpoles(1, 100);
  auto sac = make_learner("sac", *env,
                          {.seed = 2,
                           .hyperparameters = {{"learning_starts", "100"},
                                               {"batch_size", "32"},
                                               {"pi_layers", "32"},
                                               {"qf_layers", "32"}}});
  env->reset(5);
  const envs::ObservationBuffers start = env->observation(0);
  const double before = sac->value(start);
  EXPECT_LT(std::fabs(before), 2.0);
  EXPECT_EQ(sac->value(start), before);
  sac->learn(1500, [](const TrainStats&) { return true; });
  EXPECT_GT(sac->value(start), before + 3.0);
}

TEST(Td3, ValueIsTheMinimumCriticAtTheActorsAction) {
  // TD3 and DDPG (SPDL's value estimate): min_i Q_i(s, mu(s)), as SAC's. The critic is read
  // back from a checkpoint into a network of the same shape and evaluated at the action the
  // learner takes deterministically; a few updates first move the critics off their targets.
  const std::map<std::string, std::string> hp = {{"learning_starts", "20"},
                                                 {"batch_size", "8"},
                                                 {"pi_layers", "8"},
                                                 {"qf_layers", "8"},
                                                 {"normalize_observations", "false"}};
  for (const std::string algorithm : {"td3", "ddpg"}) {
    SCOPED_TRACE(algorithm);
    auto env = make_scripted({7}, /*bound=*/1.0);
    auto learner = make_learner(algorithm, *env, {.seed = 5, .hyperparameters = hp});
    learner->learn(120, [](const TrainStats&) { return true; });
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / ("cradle_" + algorithm + "_value.ckpt");
    learner->save(file);
    ObservationPipeline pipeline(env->observation_space(), {.normalize_observations = false},
                                 nullptr);
    at::Generator unused = at::make_generator<at::CPUGeneratorImpl>(0);
    const int critics = algorithm == "td3" ? 2 : 1;
    OffPolicyNetworkConfig networks;
    networks.pi_layers = {8};
    networks.qf_layers = {8};
    Critic critic(pipeline.shape(), 1, critics, networks, unused);
    read_checkpoint(file, algorithm,
                    [&](const CheckpointInfo&, torch::serialize::InputArchive& archive) {
                      read_module(archive, "critic", *critic);
                    });
    std::filesystem::remove(file);

    env->reset(3);
    int differ = 0;
    for (int t = 0; t < 5; ++t) {
      const envs::ObservationBuffers& observation = env->observation(0);
      std::vector<double> action(1);
      learner->act(observation, action, /*deterministic=*/true);
      ObsBatch batch = ObsBatch::zeros(pipeline.shape(), 1);
      pipeline.process(observation, batch);
      torch::NoGradGuard no_grad;
      const torch::Tensor q =
          critic->forward(batch, torch::tensor({{static_cast<float>(action[0])}}));
      ASSERT_EQ(q.size(0), critics);
      const double expected = q.min().item<double>();
      EXPECT_NEAR(learner->value(observation), expected, 1e-5 * (1 + std::fabs(expected)));
      if (critics == 2) differ += q[0].item<double>() != q[1].item<double>();
      env->step(action);
    }
    if (critics == 2) {
      EXPECT_GT(differ, 0);  // the minimum is not a formality
    }
  }
}

TEST(Sac, DeterministicGivenTheSeed) {
  auto env_a = testing::make_cartpoles(2, 30);
  auto env_b = testing::make_cartpoles(2, 30);
  auto a = make_learner("sac", *env_a, {.seed = 7, .hyperparameters = small()});
  auto b = make_learner("sac", *env_b, {.seed = 7, .hyperparameters = small()});
  const std::vector<double> losses = train_losses(*a, 300);
  EXPECT_FALSE(losses.empty());
  EXPECT_EQ(losses, train_losses(*b, 300));
}

// ---------------------------------------------------------------------------------------------
// Overlapped collection

// The collector thread changes which actions are taken, never how much is learned: the same
// env steps, buffer sizes and gradient steps at every report as the synchronous loop, for every
// off-policy algorithm and for train_freq > 1.
TEST(OverlapCollection, KeepsTheUpdateToDataRatio) {
  for (const std::string algorithm : {"sac", "td3", "ddpg"}) {
    for (const std::string train_freq : {"1", "3"}) {
      SCOPED_TRACE(algorithm + " train_freq " + train_freq);
      auto counts = [&](const std::string& overlap) {
        // Episodes of fixed lengths: the stored transitions do not depend on the actions.
        auto env = make_scripted({10, 7});
        auto learner = make_learner(algorithm, *env,
                                    {.seed = 5,
                                     .hyperparameters = small({{"overlap_collection", overlap},
                                                               {"train_freq", train_freq},
                                                               {"gradient_steps", "2"},
                                                               {"report_every", "12"}})});
        std::vector<double> seen;
        learner->learn(200, [&](const TrainStats& stats) {
          seen.push_back(static_cast<double>(stats.steps));
          seen.push_back(stats.losses.at("updates"));
          seen.push_back(stats.losses.at("buffer_transitions"));
          for (const auto& [name, value] : stats.losses) EXPECT_TRUE(std::isfinite(value)) << name;
          return true;
        });
        EXPECT_EQ(learner->steps(), 200);
        return seen;
      };
      const std::vector<double> sync = counts("false");
      EXPECT_GT(sync.size(), 6u);
      EXPECT_EQ(counts("true"), sync);
    }
  }
}

// Stopped by the progress callback: learn() returns at that report with the collector joined;
// a checkpoint written there loads into a learner that acts the same.
TEST(OverlapCollection, StopsAtAReportWithAConsistentCheckpoint) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "cradle_overlap_stop.pt";
  auto env_a = testing::make_cartpoles(2, 30);
  auto env_b = testing::make_cartpoles(2, 30);
  const auto hp = small({{"overlap_collection", "true"}, {"report_every", "40"}});
  auto a = make_learner("sac", *env_a, {.seed = 3, .hyperparameters = hp});
  auto b = make_learner("sac", *env_b, {.seed = 4, .hyperparameters = hp});
  int reports = 0;
  a->learn(1'000'000, [&](const TrainStats& stats) {
    EXPECT_EQ(stats.steps, 80L * (reports + 1));
    a->save(file);
    return ++reports < 3;
  });
  EXPECT_EQ(reports, 3);
  EXPECT_EQ(a->steps(), 240);
  b->load(file);
  EXPECT_EQ(b->steps(), 240);
  EXPECT_EQ(actions_of(*a, false, true), actions_of(*b, false, true));
  // And it runs on from there.
  a->learn(320, {});
  EXPECT_EQ(a->steps(), 320);
  std::filesystem::remove(file);
}

// An env failing on the collector thread fails learn() on the caller's thread, with the
// collector joined (no hang, no terminate), as a sync run would fail.
TEST(OverlapCollection, RethrowsTheCollectorsFailure) {
  std::vector<std::unique_ptr<envs::Env>> list;
  auto scripted = std::make_unique<ScriptedEnv>(10, 2.0);
  scripted->fail_at_step(150);
  list.push_back(std::move(scripted));
  ThreadedVecEnv env(std::move(list), /*threads=*/1);
  auto learner =
      make_learner("sac", env, {.hyperparameters = small({{"overlap_collection", "true"}})});
  EXPECT_THROW(learner->learn(1000, {}), std::runtime_error);
  // The 150th step call is vector step 164 (14 autoresets before it): nothing after it counts.
  EXPECT_GT(learner->steps(), 100);
  EXPECT_LT(learner->steps(), 165);
}

// Settings it cannot honour are refused, each with its one-line reason.
TEST(OverlapCollection, RefusesWhatItCannotRun) {
  auto env = testing::make_cartpoles(1, 30);
  EXPECT_THROW(make_learner("sac", *env, {.hyperparameters = {{"actor_refresh", "0"}}}), UserError);
  auto episodic = make_learner(
      "sac", *env,
      {.hyperparameters = small({{"overlap_collection", "true"}, {"episode_train_freq", "10"}})});
  EXPECT_THROW(episodic->learn(100, {}), UserError);
  auto images = testing::make_cartpoles(1, 30, /*with_image=*/true);
  auto seeing =
      make_learner("sac", *images, {.hyperparameters = small({{"overlap_collection", "true"}})});
  EXPECT_THROW(seeing->learn(100, {}), UserError);
}

// ---------------------------------------------------------------------------------------------
// Learning: Pendulum swing-up (episodes of 200 steps). A random policy scores about -1,200;
// swinging up and balancing scores above -400 (about -150 from most starts).

constexpr int kPendulumSteps = 200;

double random_pendulum_return(int episodes) {
  testing::Pendulum env(testing::pendulum_model(), kPendulumSteps);
  Rng rng(5);
  double total = 0;
  env.reset(1);
  for (int e = 0; e < episodes; ++e) {
    if (e > 0) env.reset(std::nullopt);
    for (int t = 0; t < kPendulumSteps; ++t) {
      const double action = rng.uniform(-2, 2);
      total += env.step({&action, 1}).reward;
    }
  }
  return total / episodes;
}

// Mean return of `episodes` deterministic episodes of the learner's policy.
double policy_pendulum_return(Learner& learner, int episodes) {
  testing::Pendulum env(testing::pendulum_model(), kPendulumSteps);
  double total = 0;
  env.reset(77);
  for (int e = 0; e < episodes; ++e) {
    if (e > 0) env.reset(std::nullopt);
    for (int t = 0; t < kPendulumSteps; ++t) {
      double action = 0;
      learner.act(env.observation(), {&action, 1}, /*deterministic=*/true);
      total += env.step({&action, 1}).reward;
    }
  }
  return total / episodes;
}

struct PendulumRun {
  double random, learned, seconds;
};

PendulumRun learn_pendulum(const std::string& algorithm, long steps,
                           std::map<std::string, std::string> hp) {
  const auto start = std::chrono::steady_clock::now();
  auto env = testing::make_pendulums(1, kPendulumSteps);
  auto learner = make_learner(algorithm, *env, {.seed = 1, .hyperparameters = hp});
  std::vector<double> returns;
  learner->learn(steps, [&](const TrainStats& stats) {
    if (!std::isnan(stats.episodic_return)) returns.push_back(stats.episodic_return);
    return true;
  });
  PendulumRun run{.random = random_pendulum_return(20),
                  .learned = policy_pendulum_return(*learner, 10)};
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "%s pendulum, %ld steps: random %.0f -> deterministic policy %.0f (%.1f s); "
      "training returns:",
      algorithm.c_str(), steps, run.random, run.learned, run.seconds);
  for (double r : returns) std::printf(" %.0f", r);
  std::printf("\n");
  return run;
}

const std::map<std::string, std::string> kPendulumHp = {{"pi_layers", "64,64"},
                                                        {"qf_layers", "64,64"},
                                                        {"batch_size", "128"},
                                                        {"learning_rate", "1e-3"},
                                                        {"report_every", "1000"}};

TEST(Sac, LearnsPendulumSwingUp) {
  const PendulumRun run = learn_pendulum("sac", 6000, kPendulumHp);
  EXPECT_LT(run.random, -900);
  EXPECT_GT(run.learned, -400);
}

// With the collector on its own thread (acting with an actor one update old) SAC still swings
// the pendulum up. The run depends on its seed only, not on thread timing
// (OverlappedCollectionIsRepeatableWhateverTheTiming), so a loaded machine gets the same result.
TEST(Sac, LearnsPendulumSwingUpWithOverlappedCollection) {
  std::map<std::string, std::string> hp = kPendulumHp;
  hp["overlap_collection"] = "true";
  const PendulumRun run = learn_pendulum("sac", 6000, hp);
  EXPECT_GT(run.learned, -400);
}

// What an overlapped run leaves: every report's return and losses (not its timings), and the
// trained policy's deterministic return.
struct OverlappedTrace {
  std::vector<double> values;
  bool operator==(const OverlappedTrace&) const = default;
};

// An overlapped SAC run on the pendulum whose collector (through the reward hook, which runs on
// the collector thread and leaves the rewards alone) or learner (through the progress callback,
// called at handoffs on the learner thread) sleeps at irregular steps.
OverlappedTrace overlapped_run(bool slow_collector, bool slow_learner) {
  auto env = testing::make_pendulums(1, kPendulumSteps);
  std::map<std::string, std::string> hp = kPendulumHp;
  hp["overlap_collection"] = "true";
  hp["learning_starts"] = "200";
  hp["report_every"] = "50";
  LearnerOptions options{.seed = 3, .hyperparameters = hp};
  long calls = 0;
  auto pause = [](long call) {
    std::this_thread::sleep_for(std::chrono::microseconds((call * 7919) % 5 * 400));
  };
  options.reward_hook = [&](const VecEnv&, std::span<const double>, std::span<double>) {
    if (slow_collector) pause(calls++);
  };
  auto learner = make_learner("sac", *env, options);
  OverlappedTrace trace;
  long reports = 0;
  learner->learn(1000, [&](const TrainStats& stats) {
    if (slow_learner) pause(reports++);
    trace.values.push_back(static_cast<double>(stats.steps));
    trace.values.push_back(stats.episodic_return);
    for (const auto& [name, value] : stats.losses)
      if (!name.ends_with("_seconds")) trace.values.push_back(value);  // wall time is not the run
    return true;
  });
  trace.values.push_back(policy_pendulum_return(*learner, 2));
  return trace;
}

// The handoff fixes the interleaving: whichever thread is slower, the collector stages exactly
// train_freq vector steps with the actor copy of the last handoff and the learner makes exactly
// the gradient steps of the merged ones, so the run is bitwise the same. (NaN returns of reports
// with no finished episode compare unequal; they are replaced so that they compare by position.)
TEST(Sac, OverlappedCollectionIsRepeatableWhateverTheTiming) {
  auto plain = [](OverlappedTrace t) {
    for (double& v : t.values)
      if (std::isnan(v)) v = -12345.0;
    return t;
  };
  const OverlappedTrace reference = plain(overlapped_run(false, false));
  ASSERT_GT(reference.values.size(), 40u);  // 20 reports with losses, and the policy's return
  EXPECT_TRUE(plain(overlapped_run(true, false)) == reference) << "slow collector";
  EXPECT_TRUE(plain(overlapped_run(false, true)) == reference) << "slow learner";
}

TEST(Td3, ImprovesOnPendulum) {
  const PendulumRun run = learn_pendulum("td3", 6000, kPendulumHp);
  EXPECT_GT(run.learned, run.random + 400);
}

TEST(Ddpg, ImprovesOnPendulum) {
  const PendulumRun run = learn_pendulum("ddpg", 6000, kPendulumHp);
  EXPECT_GT(run.learned, run.random + 400);
}

}  // namespace
}  // namespace cradle::learn
