// Adapter from the SaMI family (src/sami/) to the envs::Env interface, so the learners, the
// vector env and the Python Env wrapper can drive SaMI envs. Kept thin on purpose.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "envs/env.h"
#include "sami/env.h"

namespace cradle::envs {

class SamiEnvAdapter final : public Env {
 public:
  // The hidden parameters a teacher may set, as reset options: mass and damping factors
  // (locomotion envs that vary them) and Panda's table_friction and cube_mass (kg). Inside the
  // ranges task-set files may use (sami/task.h: damping beyond x3 blows the humanoids up).
  static constexpr double kFactorRange[2] = {0.05, 3};
  static constexpr double kCellRange[2] = {0.01, 50};

  explicit SamiEnvAdapter(std::unique_ptr<sami::SamiEnv> env);
  const DictSpace& observation_space() const override { return space_; }
  const Box& action_space() const override { return action_space_; }
  void reset(std::optional<std::uint64_t> seed = std::nullopt) override;
  StepResult step(std::span<const double> action) override;
  const ObservationBuffers& observation() const override { return buffers_; }
  const Info& info() const override { return info_; }
  // Fixes the named hidden parameters in every task set for the following resets (the rest are
  // still drawn from the sets); UserError for a name the env does not vary or a value out of
  // range, before anything changes.
  void set_reset_options(const ResetOptions& options) override;
  // Panda push's success so far (1 or 0: the cube within 5 cm of the goal); NaN for locomotion,
  // which has no success rule.
  double score() const override;
  sami::SamiEnv& sami() { return *env_; }

 private:
  void copy_observation();
  std::unique_ptr<sami::SamiEnv> env_;
  DictSpace space_;
  Box action_space_;
  ObservationBuffers buffers_;
  Info info_;
  int success_slot_ = -1;                 // info "is_success"
  std::vector<sami::TaskSet> base_sets_;  // the sets the env was made with
};

// The task sets of a vector of SaMI envs, one per env: the split's (or YAML file's) sets through
// sami::one_set_per_env.
std::vector<sami::TaskSet> sami_vector_sets(sami::EnvId id, std::string_view split_or_file);

// A SaMI env by name and split (or task-set YAML file) behind the Env interface.
std::unique_ptr<Env> make_sami_env(std::string_view name, std::string_view split,
                                   std::uint64_t seed);

}  // namespace cradle::envs
