// Rendezvous: flags, torchrun's and Slurm's variables, and Slurm's compressed node lists.
#include "dist/rendezvous.h"

#include <gtest/gtest.h>

#include <map>

#include "core/error.h"

namespace cradle::dist {
namespace {

EnvLookup env_of(std::map<std::string, std::string> vars) {
  return [vars](const std::string& name) -> std::optional<std::string> {
    const auto it = vars.find(name);
    if (it == vars.end()) return std::nullopt;
    return it->second;
  };
}

// The UserError's message, or "" when none was thrown.
std::string error_of(const RendezvousFlags& flags, std::map<std::string, std::string> vars) {
  try {
    resolve_rendezvous(flags, env_of(std::move(vars)));
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

TEST(Nodelist, ExpandsRangesListsAndPadding) {
  using V = std::vector<std::string>;
  EXPECT_EQ(expand_nodelist("node[01-03,07]"), (V{"node01", "node02", "node03", "node07"}));
  EXPECT_EQ(expand_nodelist("a1,b[8-10],c"), (V{"a1", "b8", "b9", "b10", "c"}));
  EXPECT_EQ(expand_nodelist("r[1-2]n[3-4]"), (V{"r1n3", "r1n4", "r2n3", "r2n4"}));
  EXPECT_EQ(expand_nodelist("gpu-[098-101]"), (V{"gpu-098", "gpu-099", "gpu-100", "gpu-101"}));
  EXPECT_EQ(expand_nodelist("localhost"), V{"localhost"});
}

TEST(Nodelist, RefusesMalformedLists) {
  EXPECT_THROW(expand_nodelist(""), UserError);
  EXPECT_THROW(expand_nodelist("node[01-03"), UserError);
  EXPECT_THROW(expand_nodelist("node[3-1]"), UserError);
  EXPECT_THROW(expand_nodelist("node[a-b]"), UserError);
  EXPECT_THROW(expand_nodelist("a,,b"), UserError);
}

TEST(Rendezvous, TorchrunVariables) {
  const Rendezvous r = resolve_rendezvous({}, env_of({{"WORLD_SIZE", "4"},
                                                      {"RANK", "2"},
                                                      {"LOCAL_RANK", "0"},
                                                      {"MASTER_ADDR", "10.0.0.5"},
                                                      {"MASTER_PORT", "29400"}}));
  EXPECT_EQ(r.world_size, 4);
  EXPECT_EQ(r.rank, 2);
  EXPECT_EQ(r.master_addr, "10.0.0.5");
  EXPECT_EQ(r.master_port, 29400);
  EXPECT_EQ(r.source, "env");
}

TEST(Rendezvous, SlurmVariablesNameTheFirstNodeAndAJobPort) {
  const Rendezvous r = resolve_rendezvous({}, env_of({{"SLURM_NTASKS", "8"},
                                                      {"SLURM_PROCID", "5"},
                                                      {"SLURM_LOCALID", "1"},
                                                      {"SLURM_JOB_NODELIST", "cn[07-08,11]"},
                                                      {"SLURM_JOB_ID", "123456"}}));
  EXPECT_EQ(r.world_size, 8);
  EXPECT_EQ(r.rank, 5);
  EXPECT_EQ(r.local_rank, 1);
  EXPECT_EQ(r.master_addr, "cn07");
  EXPECT_EQ(r.master_port, kSlurmPortBase + 123456 % kSlurmPortSpan);
  EXPECT_EQ(r.source, "slurm");
}

TEST(Rendezvous, FlagsWinOverTheEnvironment) {
  RendezvousFlags flags;
  flags.world_size = 2;
  flags.rank = 1;
  flags.master = "host7:1234";
  const Rendezvous r =
      resolve_rendezvous(flags, env_of({{"WORLD_SIZE", "4"}, {"RANK", "3"}, {"MASTER_ADDR", "x"}}));
  EXPECT_EQ(r.world_size, 2);
  EXPECT_EQ(r.rank, 1);
  EXPECT_EQ(r.master_addr, "host7");
  EXPECT_EQ(r.master_port, 1234);
}

TEST(Rendezvous, OneLineErrorsNameWhatIsWrong) {
  EXPECT_NE(error_of({}, {}).find("no rank given"), std::string::npos);
  EXPECT_NE(error_of({}, {{"RANK", "0"}}).find("WORLD_SIZE is not"), std::string::npos);
  EXPECT_NE(error_of({}, {{"WORLD_SIZE", "2"}, {"RANK", "2"}, {"MASTER_ADDR", "h"}})
                .find("rank 2 is not below the world size 2"),
            std::string::npos);
  EXPECT_NE(error_of({}, {{"WORLD_SIZE", "two"}, {"RANK", "0"}}).find("WORLD_SIZE 'two'"),
            std::string::npos);
  EXPECT_NE(error_of({}, {{"WORLD_SIZE", "2"}, {"RANK", "0"}}).find("no master address"),
            std::string::npos);
  EXPECT_NE(
      error_of({}, {{"WORLD_SIZE", "2"}, {"RANK", "0"}, {"MASTER_ADDR", "h"}, {"MASTER_PORT", "0"}})
          .find("MASTER_PORT '0'"),
      std::string::npos);
  RendezvousFlags half;
  half.rank = 0;
  EXPECT_NE(error_of(half, {}).find("--world-size and --rank go together"), std::string::npos);
  for (const std::string& e : {error_of({}, {}), error_of(half, {})}) {
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace cradle::dist
