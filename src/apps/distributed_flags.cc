#include "apps/distributed_flags.h"

#include <cstdio>
#include <exception>

#include "train/dist_sync.h"

namespace cradle::apps {

void add_distributed_flags(CLI::App* cmd, DistributedFlags& flags) {
  CLI::Option* distributed = cmd->add_flag(
      "--distributed", flags.distributed,
      "Data-parallel over ranks (WORLD_SIZE/RANK/MASTER_ADDR/MASTER_PORT or Slurm's variables)");
  cmd->add_option("--world-size", flags.rendezvous.world_size, "Ranks in all (with --distributed)")
      ->check(CLI::Range(1, 1 << 20))
      ->needs(distributed);
  cmd->add_option("--rank", flags.rendezvous.rank, "This process's rank (with --distributed)")
      ->check(CLI::Range(0, 1 << 20))
      ->needs(distributed);
  cmd->add_option("--master", flags.rendezvous.master, "Rank 0's host[:port] (with --distributed)")
      ->needs(distributed);
  cmd->add_option("--dist-timeout", flags.rendezvous.timeout_seconds,
                  "Seconds to wait for the other ranks before failing")
      ->check(CLI::Range(1, 86400))
      ->needs(distributed);
}

int run_as_rank(const DistributedFlags& flags,
                const std::function<std::uint64_t(std::shared_ptr<learn::GradSync>)>& train) {
  if (!flags.distributed) {
    train(nullptr);
    return 0;
  }
  dist::ProcessGroup group(dist::resolve_rendezvous(flags.rendezvous, dist::process_env()));
  std::uint64_t hash = 0;
  try {
    hash = train(std::make_shared<train::DistSync>(group));
  } catch (const std::exception& e) {
    group.announce_failure(e.what());  // the other ranks name this one
    throw;
  }
  std::printf("rank %d of %d: parameter hash %016llx; %ld collectives, %.2f s\n", group.rank(),
              group.world_size(), static_cast<unsigned long long>(hash), group.collectives(),
              group.collective_seconds());
  return group.rank();
}

}  // namespace cradle::apps
