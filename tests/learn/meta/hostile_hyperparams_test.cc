// SaMI hyperparameters that used to end in std::bad_alloc or a LibTorch trace: a replay, an
// encoder or a network beyond the machine's memory, layer lists out of range. Each is a one-line
// UserError before anything large is allocated.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "core/error.h"
#include "learn/meta/context_sac.h"
#include "learn/meta/trajectory_replay.h"

namespace cradle::learn::meta {
namespace {

// The UserError message of building a SaMI learner with these overrides, or "".
std::string learner_error(const std::map<std::string, std::string>& hp) {
  try {
    SamiConfig config;
    apply_sami_hyperparameters(config, hp);
    ContextSac learner("SaCCM", /*obs_size=*/20, /*action_size=*/4, config, 1);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

TEST(SamiHostileHyperparameters, SizesBeyondMemoryOrRangeAreOneLineErrors) {
  const std::vector<std::pair<std::map<std::string, std::string>, std::string>> cases = {
      {{{"lstm_hidden", "65536"}}, "half the machine's memory"},
      {{{"net_arch", "100000000"}}, "net_arch: expected every layer size in 1..65536"},
      {{{"net_arch", "65536,65536"}}, "half the machine's memory"},
      {{{"net_arch", ""}}, "net_arch: expected at least one layer"},
      {{{"net_arch", "256,"}}, "cannot parse"},
      {{{"net_arch", "0"}}, "net_arch: expected every layer size in 1..65536"},
      {{{"batch_size", "0"}}, "batch_size"},
      {{{"batch_size", "1000000"}}, "batch_size: expected 1 <= batch_size <= 100000"},
      {{{"buffer_size", "10000000000"}}, "cannot parse"}};
  for (const auto& [hp, expected] : cases) {
    const std::string message = learner_error(hp);
    EXPECT_NE(message.find(expected), std::string::npos)
        << hp.begin()->first << "=" << hp.begin()->second << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_EQ(learner_error({{"net_arch", "64,64"}, {"lstm_hidden", "32"}}), "");
}

TEST(SamiHostileHyperparameters, ReplayBeyondMemoryIsRefusedBeforeAllocating) {
  try {
    TrajectoryReplay replay(/*envs=*/4, /*capacity=*/1000000000, /*max_len=*/50, 20, 4);
    FAIL() << "a replay of 4e9 trajectories was allocated";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("buffer_size = 1000000000"), std::string::npos) << message;
    EXPECT_NE(message.find("half the machine's memory"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_NO_THROW(TrajectoryReplay(2, 10, 50, 20, 4));
}

}  // namespace
}  // namespace cradle::learn::meta
