#include "sami/envs/registry.h"

#include <array>
#include <span>

#include "sami/envs/env_def.h"

namespace cradle::sami {

const EnvDef& env_def(EnvId id) {
  // Pointers to the env files' definitions, made on first use (each is its file's function-local
  // static, so no file's static initialisation order matters).
  static const std::array<const EnvDef*, kEnvCount> table = {
#define CRADLE_SAMI_ENV_ENTRY(id, file) &envs::file(),
      CRADLE_SAMI_ENVS(CRADLE_SAMI_ENV_ENTRY)
#undef CRADLE_SAMI_ENV_ENTRY
  };
  return *table[static_cast<int>(id)];
}

std::span<const EnvId> all_envs() {
  static constexpr std::array<EnvId, kEnvCount> all = {
#define CRADLE_SAMI_ENV_ID(id, file) EnvId::id,
      CRADLE_SAMI_ENVS(CRADLE_SAMI_ENV_ID)
#undef CRADLE_SAMI_ENV_ID
  };
  return all;
}

}  // namespace cradle::sami
