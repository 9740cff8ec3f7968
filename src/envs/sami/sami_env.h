// Adapter from the SaMI family (src/sami/) to the envs::Env interface, so the learners, the
// vector env and the Python Env wrapper can drive SaMI envs. Kept thin on purpose.
#pragma once

#include <memory>
#include <string_view>

#include "envs/env.h"
#include "sami/env.h"

namespace cradle::envs {

class SamiEnvAdapter final : public Env {
 public:
  explicit SamiEnvAdapter(std::unique_ptr<sami::SamiEnv> env);
  const DictSpace& observation_space() const override { return space_; }
  const Box& action_space() const override { return action_space_; }
  void reset(std::optional<std::uint64_t> seed = std::nullopt) override;
  StepResult step(std::span<const double> action) override;
  const ObservationBuffers& observation() const override { return buffers_; }
  const Info& info() const override { return info_; }
  sami::SamiEnv& sami() { return *env_; }

 private:
  void copy_observation();
  std::unique_ptr<sami::SamiEnv> env_;
  DictSpace space_;
  Box action_space_;
  ObservationBuffers buffers_;
  Info info_;
  int success_slot_ = -1;  // info "is_success"
};

// A SaMI env by name and split (or task-set YAML file) behind the Env interface.
std::unique_ptr<Env> make_sami_env(std::string_view name, std::string_view split,
                                   std::uint64_t seed);

}  // namespace cradle::envs
