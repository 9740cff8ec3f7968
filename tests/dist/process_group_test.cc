// The process group with real processes on loopback: averaged gradients, broadcast, joining
// checks and a rank that dies.
#include "dist/process_group.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "fixture.h"
#include "ranks.h"
#include "workers.h"

namespace cradle::test {
namespace {

torch::Tensor read_floats(const std::filesystem::path& file, long n) {
  torch::Tensor t = torch::zeros({n}, torch::kFloat32);
  std::ifstream in(file, std::ios::binary);
  in.read(static_cast<char*>(t.data_ptr()), n * sizeof(float));
  return in ? t : torch::Tensor();
}

TEST(ProcessGroup, AllReducedGradientIsTheMeanOfTheRanksGradients) {
  const std::filesystem::path dir = fresh_dir("dist_gradient");
  const int port = free_port();
  Process a = spawn_worker("gradient", 0, 2, port, dir);
  Process b = spawn_worker("gradient", 1, 2, port, dir);
  ASSERT_EQ(wait_for(a), 0) << a.output();
  ASSERT_EQ(wait_for(b), 0) << b.output();
  // The mean of the two gradients computed separately, here.
  const torch::Tensor g0 = rank_gradient(0), g1 = rank_gradient(1);
  ASSERT_FALSE(torch::equal(g0, g1));
  const torch::Tensor mean = (g0 + g1) / 2;
  for (int rank : {0, 1}) {
    const torch::Tensor got =
        read_floats(dir / ("gradient_rank" + std::to_string(rank) + ".bin"), mean.numel());
    ASSERT_TRUE(got.defined());
    EXPECT_TRUE(torch::equal(got, mean))
        << "rank " << rank << " max difference " << (got - mean).abs().max().item<float>();
  }
  // Broadcast: both ranks end with rank 0's network (seed 1000), not their own.
  const std::string expected = [] {
    char buf[32];
    std::snprintf(
        buf, sizeof buf, "hash %016llx",
        static_cast<unsigned long long>(learn::tensor_hash(small_net(1000)->parameters())));
    return std::string(buf);
  }();
  EXPECT_NE(a.output().find(expected), std::string::npos) << a.output();
  EXPECT_NE(b.output().find(expected), std::string::npos) << b.output();
  std::filesystem::remove_all(dir);
}

TEST(ProcessGroup, WorldSizesThatDifferAreRefusedByName) {
  const std::filesystem::path dir = fresh_dir("dist_world");
  const int port = free_port();
  Process a = spawn_worker("join", 0, 2, port, dir);
  Process b = spawn_worker("join", 1, 3, port, dir);
  EXPECT_EQ(wait_for(a), 1);
  EXPECT_EQ(wait_for(b), 1);
  EXPECT_NE(b.output().find("world sizes differ: rank 0 has WORLD_SIZE=2, rank 1 3"),
            std::string::npos)
      << b.output();
  EXPECT_NE(a.output().find("rank 1"), std::string::npos) << a.output();
  std::filesystem::remove_all(dir);
}

TEST(ProcessGroup, AnUnreachableMasterIsOneLineWithinTheTimeout) {
  dist::Rendezvous r{.rank = 1, .world_size = 2, .master_addr = "127.0.0.1"};
  r.master_port = free_port();  // nobody listens
  r.timeout_seconds = 2;
  const auto start = std::chrono::steady_clock::now();
  try {
    dist::ProcessGroup group(r);
    FAIL() << "joined a master that does not exist";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("rank 1 cannot reach the master at 127.0.0.1:"), std::string::npos)
        << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 15);
}

TEST(ProcessGroup, AKilledRankIsNamedByTheSurvivor) {
  const std::filesystem::path dir = fresh_dir("dist_die");
  const int port = free_port();
  Process a = spawn_worker("die", 0, 2, port, dir);
  Process b = spawn_worker("die", 1, 2, port, dir);
  EXPECT_EQ(wait_for(b), 128 + SIGKILL);
  EXPECT_EQ(wait_for(a, 30), 1) << a.output();
  EXPECT_NE(a.output().find("rank 0: distributed run stopped: rank 1 died"), std::string::npos)
      << a.output();
  std::filesystem::remove_all(dir);
}

TEST(ProcessGroup, AFailingRankSaysWhyToTheOthers) {
  const std::filesystem::path dir = fresh_dir("dist_fail");
  const int port = free_port();
  Process a = spawn_worker("fail", 0, 2, port, dir);
  Process b = spawn_worker("fail", 1, 2, port, dir);
  EXPECT_EQ(wait_for(b), 1);
  EXPECT_EQ(wait_for(a, 30), 1) << a.output();
  EXPECT_NE(a.output().find("rank 1 stopped: the disk is full"), std::string::npos) << a.output();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cradle::test
