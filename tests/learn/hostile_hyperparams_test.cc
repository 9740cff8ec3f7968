// Hyperparameters that used to crash or exhaust memory: lists cut short, empty layer lists where
// a network needs a layer, and layer sizes whose networks cannot fit in the machine's memory.
// Each is a one-line UserError before anything large is allocated.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "learn/learner.h"
#include "learn/networks.h"
#include "learn/registry.h"
#include "test_tasks.h"

namespace cradle::learn {
namespace {

// The UserError message of make_learner with these overrides, or "" when it builds.
std::string error_of(const std::string& algorithm, std::map<std::string, std::string> hp) {
  auto env = testing::make_pendulums(1, 20);
  try {
    make_learner(algorithm, *env, {.hyperparameters = std::move(hp)});
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

TEST(HostileHyperparameters, LayerListsParseStrictly) {
  for (const char* value : {"64,", ",64", "64,,64", "64, ", "abc", "64;64", "1e3", " , "}) {
    for (const char* algorithm : {"sac", "ppo"}) {
      const std::string message = error_of(algorithm, {{"pi_layers", value}});
      EXPECT_NE(message.find("cannot parse"), std::string::npos)
          << algorithm << " pi_layers='" << value << "': " << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  // Spaces around the numbers are fine, and so is PPO's empty head on a shared trunk.
  EXPECT_EQ(error_of("sac", {{"pi_layers", " 16 , 16 "}}), "");
  EXPECT_EQ(error_of("ppo", {{"shared_layers", "16"}, {"pi_layers", ""}, {"vf_layers", ""}}), "");
}

TEST(HostileHyperparameters, OffPolicyNetworksNeedAHiddenLayer) {
  for (const char* algorithm : {"sac", "td3", "ddpg"}) {
    for (const char* key : {"pi_layers", "qf_layers"}) {
      const std::string message = error_of(algorithm, {{key, ""}});
      EXPECT_NE(message.find("need at least one hidden layer"), std::string::npos)
          << algorithm << " " << key << "='': " << message;
      EXPECT_NE(message.find(std::string(key) + " empty"), std::string::npos) << message;
    }
  }
}

TEST(HostileHyperparameters, NetworksBeyondMemoryAreRefusedBeforeAllocating) {
  // 65536 x 65536 is 4.3e9 weights: 69 GB with gradients and Adam moments. The check runs on
  // sizes only, so this test allocates nothing large even on a machine that could.
  ASSERT_LT(network_memory_limit(), 16.0 * 65536.0 * 65536.0) << "a machine this big";
  const std::vector<std::pair<std::string, std::map<std::string, std::string>>> cases = {
      {"sac", {{"pi_layers", "65536,65536"}}},           {"sac", {{"qf_layers", "65536,65536"}}},
      {"td3", {{"qf_layers", "65536,65536"}}},           {"ppo", {{"pi_layers", "65536,65536"}}},
      {"ppo", {{"shared_layers", "65536,65536,65536"}}}, {"a2c", {{"vf_layers", "65536,65536"}}}};
  for (const auto& [algorithm, hp] : cases) {
    const std::string message = error_of(algorithm, hp);
    EXPECT_NE(message.find("half the machine's memory"), std::string::npos)
        << algorithm << " " << hp.begin()->first << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // The largest single layer a width allows still builds on a small input.
  EXPECT_EQ(error_of("sac", {{"pi_layers", "4096"}, {"qf_layers", "64"}}), "");
}

TEST(HostileHyperparameters, CheckNetworkMemoryNamesTheNetworkAndTheSizes) {
  try {
    check_network_memory("test net", 1e12);
    FAIL() << "1e12 weights passed";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("test net: 1e+12 weights need 16000.0 GB", 0), 0u) << message;
  }
  EXPECT_NO_THROW(check_network_memory("test net", 1e6));
}

}  // namespace
}  // namespace cradle::learn
