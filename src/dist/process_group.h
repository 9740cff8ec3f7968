// One process's membership of a distributed run: a TCPStore hosted by rank 0 and a Gloo process
// group over it (torch's c10d, as torch.distributed uses), with the collectives data-parallel
// learners need on plain arrays. Joining checks that every rank agrees on the world size and that
// no rank joins twice; a heartbeat lets a survivor name a rank that died. Every failure is a
// one-line UserError naming the rank or the address at fault.
#pragma once

#include <memory>
#include <span>
#include <string>

#include "dist/rendezvous.h"

namespace cradle::dist {

enum class Reduce { kSum, kMax, kMin };

class ProcessGroup {
 public:
  // Connects (rank 0 listens on the master port), checks the world and builds the Gloo group;
  // waits at most r.timeout_seconds for the other ranks. UserError: the master unreachable or its
  // port taken, a rank missing, world sizes that differ, a rank that joins twice.
  explicit ProcessGroup(const Rendezvous& r);
  ~ProcessGroup();
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;

  int rank() const;
  int world_size() const;
  const Rendezvous& rendezvous() const;

  // In place, the same on every rank afterwards. A collective that fails (a rank died, or no
  // answer within the timeout) throws UserError naming the rank that stopped when it can tell.
  void all_reduce(std::span<float> values, Reduce op);
  void all_reduce(std::span<double> values, Reduce op);
  // Every rank gets root's values.
  void broadcast(std::span<float> values, int root);
  void broadcast(std::span<double> values, int root);
  void barrier();

  // Tells the other ranks why this one stops (they name it in their error); never throws.
  void announce_failure(const std::string& message) noexcept;

  // Time spent in collectives, and how many, since the group was built.
  double collective_seconds() const;
  long collectives() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace cradle::dist
