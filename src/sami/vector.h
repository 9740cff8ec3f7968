// A vector of SaMI envs over task sets, as SaMI's DummyVecEnv: one sub-env per task set, all
// sharing one compiled model (each owns its data and parameter arrays), stepped in parallel on
// core's thread pool. Finished sub-envs reset themselves; the finished episode's last observation
// and info stay readable until the next step.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/thread_pool.h"
#include "sami/env.h"

namespace cradle::sami {

class SamiVector {
 public:
  // threads: participants of the pool including the caller (1: inline).
  SamiVector(EnvId id, std::vector<TaskSet> sets, std::uint64_t seed, int threads = 1,
             Options options = {});

  int size() const { return static_cast<int>(envs_.size()); }
  const Spec& spec() const { return envs_[0]->spec(); }
  // Resets every sub-env; a seed reseeds sub-env i with seed + i.
  void reset(std::optional<std::uint64_t> seed = std::nullopt);
  // actions: size() rows of spec().action_size (row-major). Throws UserError on a wrong size.
  void step(std::span<const double> actions);

  // size() rows of spec().obs_size: the float32 observations after the step (after auto-reset).
  std::span<const float> observations() const { return obs_; }
  std::span<const double> rewards() const { return rewards_; }
  std::span<const std::uint8_t> terminated() const { return terminated_; }
  std::span<const std::uint8_t> truncated() const { return truncated_; }
  // The last observation and info of an episode that ended at the last step.
  std::span<const float> final_observation(int i) const;
  const Info& final_info(int i) const { return final_info_[i]; }
  SamiEnv& env(int i) { return *envs_[i]; }
  const SamiEnv& env(int i) const { return *envs_[i]; }

 private:
  void copy_observation(int i);
  ThreadPool pool_;
  std::vector<std::unique_ptr<SamiEnv>> envs_;
  std::vector<float> obs_, final_obs_;
  std::vector<double> rewards_;
  std::vector<std::uint8_t> terminated_, truncated_;
  std::vector<Info> final_info_;
};

}  // namespace cradle::sami
