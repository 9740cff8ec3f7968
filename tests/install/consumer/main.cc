// Steps a TeachMyAgent Parkour env through the installed library and headers.
#include <cstdio>
#include <vector>

#include "tma/tma_env.h"

int main() {
  cradle::tma::TmaEnv env(cradle::tma::TmaOptions{.env = cradle::tma::EnvId::kParkour});
  env.reset(0);
  const std::vector<double> action(env.action_size(), 0.0);
  for (int i = 0; i < 5; ++i) env.step(action);
  std::printf("cradle %s: 5 Parkour steps\n", CRADLE_VERSION);
}
