// `--distributed` and its rendezvous flags, as `cradle train` and `cradle sami train` take them
// (docs/distributed.md): the ranks meet through `cradle launch`, torchrun-style variables, `srun`
// or these flags, and each rank runs the same command.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <memory>

#include "dist/process_group.h"
#include "dist/rendezvous.h"
#include "learn/grad_sync.h"

namespace cradle::apps {

struct DistributedFlags {
  bool distributed = false;
  dist::RendezvousFlags rendezvous;
};

// Adds --distributed, --world-size, --rank, --master and --dist-timeout to `cmd`.
void add_distributed_flags(CLI::App* cmd, DistributedFlags& flags);

// This process as one rank of the run (nothing without --distributed): `train` gets the ranks'
// GradSync (null alone) and returns the trained networks' hash; a failure is announced to the
// other ranks, who name this one; at the end each rank prints its line ("rank R of N: parameter
// hash H; ..."). Returns the rank (0 alone).
int run_as_rank(const DistributedFlags& flags,
                const std::function<std::uint64_t(std::shared_ptr<learn::GradSync>)>& train);

}  // namespace cradle::apps
