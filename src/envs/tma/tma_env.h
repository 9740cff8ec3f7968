// cradle::envs::Env over a TeachMyAgent environment (src/tma/): one observation entry
// "observation" (float32 as in the reference, unbounded), actions in [-1, 1]; Info::is_success
// carries `success` (return > 230) and Info::is_failure a -100 termination.
#pragma once

#include <memory>
#include <vector>

#include "envs/env.h"
#include "tma/tma_env.h"

namespace cradle::envs {

// The benchmark's task space, as reset options a teacher sets: Stump Tracks' stump_height
// [0, 3] and obstacle_spacing [0, 6] (the criteria's space); Parkour's input_vector_0..k-1 (k =
// input_cppn_dim; the benchmark's bounds for k = 3, else [-1, 1] each), water_level [0, 1],
// creepers_width 0.25, creepers_height [0, 4], creepers_spacing [0, 5] and terrain_cppn_scale 10.
std::vector<TaskParameter> tma_task_parameters(tma::EnvId env, int input_cppn_dim = 3);

class TmaEnvAdapter : public Env {
 public:
  explicit TmaEnvAdapter(const tma::TmaOptions& options,
                         std::shared_ptr<const tma::Cppn> cppn = nullptr);
  const DictSpace& observation_space() const override { return observation_space_; }
  const Box& action_space() const override { return action_space_; }
  void reset(std::optional<std::uint64_t> seed = std::nullopt) override;
  StepResult step(std::span<const double> action) override;
  // A teacher's task for the following resets, one option per dimension: scalar parameters by
  // name (stump_height), the values of a vector parameter as name_0, name_1, ... (input_vector_0,
  // as the test-set files name them). UserError for an unknown name, a missing index or a value
  // out of range.
  void set_reset_options(const ResetOptions& options) override;
  const ObservationBuffers& observation() const override { return buffers_; }
  const Info& info() const override { return info_; }
  tma::TmaEnv& env() { return env_; }

 private:
  void copy_observation();
  tma::TmaEnv env_;
  DictSpace observation_space_;
  Box action_space_;
  ObservationBuffers buffers_;
  Info info_;
  int success_slot_ = -1, failure_slot_ = -1;  // info "is_success", "is_failure"
};

}  // namespace cradle::envs
