// What the vector tests compare: uniform random actions for every env of a vector, and everything
// one vector call produces as bytes, so that two vectors (threads against threads, processes
// against threads) are compared bitwise with one EXPECT_EQ.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/rng.h"
#include "core/spaces.h"
#include "learn/vec_env.h"

namespace cradle::learn::test {

// Uniform random actions for every env (rows of the space's size), from `rng`.
inline void random_actions(const Box& space, Rng& rng, std::vector<double>& actions) {
  space.sample(rng, actions);
}

// Rewards, flags, and for every env its observations, score and every info value (unpublished
// ones included).
inline std::vector<std::byte> snapshot(const VecEnv& vec) {
  std::vector<std::byte> out;
  auto append = [&](const auto& values) {
    const auto bytes = std::as_bytes(std::span(values));
    out.insert(out.end(), bytes.begin(), bytes.end());
  };
  append(vec.rewards());
  append(vec.terminated());
  append(vec.truncated());
  for (int i = 0; i < vec.num_envs(); ++i) {
    for (int k = 0; k < vec.observation(i).count(); ++k) append(vec.observation(i).bytes(k));
    const double score = vec.env(i).score();
    append(std::span(&score, 1));
    const envs::Info& info = vec.info(i);
    append(std::span(&info.steps, 1));
    for (int k = 0; k < info.size(); ++k) {
      if (info.type(k) == envs::InfoType::kIntList) {
        append(info.list(k));
        const int end = -1;  // lists of different splits differ
        append(std::span(&end, 1));
      } else {
        const double number = info.number(k);
        append(std::span(&number, 1));
      }
    }
  }
  return out;
}

}  // namespace cradle::learn::test
