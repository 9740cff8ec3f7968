// Intrinsic-motivation rewards: per-step rewards that a learner adds to (or uses instead of) the
// env's extrinsic reward. Each reward lives in its own file of this folder; this header holds the
// common interface, an adapter for callables and the weighted sum that the CLI's --intrinsic flag
// builds ("name[:weight],name[:weight]").
//
// Life cycle, for a trainer driving a VecEnv:
//   auto r = intrinsic::parse_intrinsic("touch_count:0.5,rnd");
//   r->bind(vec);                 // once, before training
//   vec.reset(seed); r->reset(vec);
//   every step: vec.step(actions); r->compute(vec, actions, rewards);   // rewards += intrinsic
//   every rollout: r->update();   // learned rewards train on what compute() saw
//   checkpoints: r->save(dir) / r->load(dir)
//
// compute() must see every step of every env, in order: stateful rewards use the episode flags of
// an env's previous step to recognise next-step autoresets (VecEnv's Gymnasium 1.x convention: an
// env whose episode ended in step t is reset by step t+1, whose observation is then no
// transition). The vector given to compute() may be part of the bound one (an async vector's
// batch, learn::BatchView): slot i is env env.env_id(i), and per-env state is indexed by that id.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "envs/env.h"
#include "learn/vec_env.h"

namespace cradle::learn::intrinsic {

// One intrinsic reward over a vector of envs. Rewards that keep state keep it per env (indexed by
// env id, sized in bind() from the whole vector) and, for counts and learned models, over the
// whole training run.
class IntrinsicReward {
 public:
  explicit IntrinsicReward(double scale) : scale_(scale) {}
  virtual ~IntrinsicReward() = default;
  IntrinsicReward(const IntrinsicReward&) = delete;
  IntrinsicReward& operator=(const IntrinsicReward&) = delete;

  // The registry name ("touch_count", "rnd", ...).
  virtual std::string_view name() const = 0;
  // The weight this reward is multiplied by before it is added.
  double scale() const { return scale_; }

  // Called once with the vector before training: sizes per-env state, builds models. Throws
  // UserError when the vector lacks what the reward reads (e.g. saliency without eyes).
  virtual void bind(const VecEnv& /*env*/) {}
  // Called after VecEnv::reset: every env starts a new episode, no transition spans the reset.
  virtual void reset(const VecEnv& /*env*/) {}
  // Called after each VecEnv::step (or an async batch) with that step's actions (num_envs x
  // action dim, row-major): adds scale() x this reward of slot i to rewards[i] (rewards has
  // num_envs entries).
  virtual void compute(const VecEnv& env, std::span<const double> actions,
                       std::span<double> rewards) = 0;
  // Learned rewards (rnd, icm, disagreement) train on the samples collected by compute() since the
  // last call. A trainer calls it once per rollout; others ignore it.
  virtual void update() {}

  // Checkpointing: writes / reads this reward's state (counts, networks, optimisers, running
  // statistics) as files named intrinsic_<name>.* in `dir` (which must exist). Stateless rewards
  // write nothing. load() throws UserError for a missing or mismatched file.
  virtual void save(const std::filesystem::path& /*dir*/) const {}
  virtual void load(const std::filesystem::path& /*dir*/) {}

 private:
  double scale_;
};

// Names make_intrinsic() accepts, in registry order.
std::vector<std::string> intrinsic_names();
// A reward by name with its default parameters, multiplied by `scale`. Throws UserError (one line
// listing the known names) for an unknown name.
std::unique_ptr<IntrinsicReward> make_intrinsic(std::string_view name, double scale = 1.0);

// Adapter for a callable (e.g. a Python function): reward of slot i =
// scale x fn(env_id(i), observation(i), action of slot i, info(i)).
class FunctionReward final : public IntrinsicReward {
 public:
  using Function = std::function<double(int env, const envs::ObservationBuffers& observation,
                                        std::span<const double> action, const envs::Info& info)>;
  FunctionReward(std::string name, Function fn, double scale = 1.0);
  std::string_view name() const override { return name_; }
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;

 private:
  std::string name_;
  Function fn_;
};

// Weighted sum of rewards (each term carries its own scale). Remembers each term's contribution
// to the last compute() for logging.
class Composite final : public IntrinsicReward {
 public:
  Composite() : IntrinsicReward(1.0) {}
  // Adds a term; throws UserError when a term of the same name is already present.
  void add(std::unique_ptr<IntrinsicReward> term);

  std::string_view name() const override { return "composite"; }
  int size() const { return static_cast<int>(terms_.size()); }
  const IntrinsicReward& term(int k) const { return *terms_[k]; }
  // Term k's scaled reward of each env in the last compute().
  std::span<const double> last(int k) const { return last_[k]; }
  // "touch_count:0.5,rnd:1" (the form parse_intrinsic reads).
  std::string describe() const;

  void bind(const VecEnv& env) override;
  void reset(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;
  void update() override;
  void save(const std::filesystem::path& dir) const override;
  void load(const std::filesystem::path& dir) override;

 private:
  std::vector<std::unique_ptr<IntrinsicReward>> terms_;
  std::vector<std::vector<double>> last_;
};

// Parses "name[:weight],name[:weight]" (spaces around items ignored, weight defaults to 1) into a
// Composite. An empty spec gives an empty Composite (no intrinsic reward). Throws UserError for an
// unknown name (listing the known ones), a malformed weight or a repeated name.
std::unique_ptr<Composite> parse_intrinsic(std::string_view spec);

// Shared helpers for the rewards of this folder.
namespace detail {
// Index of an observation key in the vector's space, or -1.
int key_index(const VecEnv& env, std::string_view key);
// Per env id: whether its observation in the current compute() starts an episode (VecEnv's
// next-step autoreset) or has no earlier observation known to the reward; either way it ends no
// transition. Starts all true; a reward that records the observations at reset(vec) clears it.
class EpisodeStarts {
 public:
  void assign(int num_envs, bool value) { starts_.assign(num_envs, value ? 1 : 0); }
  // Call at the end of compute(): the envs of this call whose episode ended in this step are
  // reset by their next one.
  void record_flags(const VecEnv& env);
  bool operator[](int id) const { return starts_[id] != 0; }
  int size() const { return static_cast<int>(starts_.size()); }

 private:
  std::vector<std::uint8_t> starts_;
};
}  // namespace detail

}  // namespace cradle::learn::intrinsic
