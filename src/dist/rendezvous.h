// Where a distributed run's processes meet, the way torchrun and Slurm say it: each process learns
// its rank, the world size and the master's address (rank 0, which hosts the store) from flags,
// from torchrun's variables (WORLD_SIZE, RANK, LOCAL_RANK, MASTER_ADDR, MASTER_PORT) or from
// Slurm's (SLURM_NTASKS, SLURM_PROCID, SLURM_LOCALID and the first host of SLURM_JOB_NODELIST).
// Flags win over torchrun's variables, which win over Slurm's.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cradle::dist {

// The master port when neither a flag nor MASTER_PORT gives one (torchrun's default). Under
// Slurm without MASTER_PORT: kSlurmPortBase + SLURM_JOB_ID % kSlurmPortSpan, so that two jobs
// sharing a node do not collide.
inline constexpr int kDefaultPort = 29500;
inline constexpr int kSlurmPortBase = 20000;
inline constexpr int kSlurmPortSpan = 10000;

struct Rendezvous {
  int rank = 0;
  int world_size = 1;
  int local_rank = 0;
  std::string master_addr;
  int master_port = kDefaultPort;
  std::string source;  // "flags", "env" (torchrun's variables) or "slurm"
  int timeout_seconds = 300;
};

// What the command line gave (unset: not given).
struct RendezvousFlags {
  std::optional<int> world_size, rank;
  std::optional<std::string> master;  // "host" or "host:port"
  int timeout_seconds = 300;
};

// Reads an environment variable (nullopt when unset); tests pass their own.
using EnvLookup = std::function<std::optional<std::string>(const std::string&)>;
EnvLookup process_env();

// The rendezvous of this process. Throws UserError naming the variable or flag that is missing
// or malformed (e.g. RANK without WORLD_SIZE, RANK >= WORLD_SIZE, no master address, a port
// outside 1..65535).
Rendezvous resolve_rendezvous(const RendezvousFlags& flags, const EnvLookup& env);

// Slurm's compressed host lists, e.g. "node[01-03,07],gpu5" -> node01 node02 node03 node07 gpu5
// (zero padding kept; several bracket groups in one name multiply out). UserError when malformed.
std::vector<std::string> expand_nodelist(const std::string& nodelist);

}  // namespace cradle::dist
