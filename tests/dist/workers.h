// The ranks' side of the distributed tests (run by main.cc in a re-run of this binary) and the
// computations the tests repeat in one process to check them.
#pragma once

#include <signal.h>
#include <torch/torch.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "dist/process_group.h"
#include "learn/grad_tensors.h"
#include "learn/networks.h"
#include "train/dist_sync.h"

namespace cradle::test {

// A small MLP whose weights come from `seed`.
inline torch::nn::Sequential small_net(std::uint64_t seed) {
  torch::nn::Sequential net(torch::nn::Linear(5, 16), torch::nn::Tanh(), torch::nn::Linear(16, 3));
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(seed);
  learn::init_layers(*net, 1.0, /*orthogonal=*/false, generator);
  return net;
}

// The packed gradient of the mean squared error of small_net(7) on rank `rank`'s own batch;
// `sync` (when given) averages it over the ranks as the learners do.
inline torch::Tensor rank_gradient(int rank, learn::GradSync* sync = nullptr) {
  torch::nn::Sequential net = small_net(7);
  learn::PackedParameters packed(*net);
  at::Generator data = at::make_generator<at::CPUGeneratorImpl>(100 + rank);
  const torch::Tensor x = torch::randn({32, 5}, data);
  const torch::Tensor y = torch::randn({32, 3}, data);
  packed.zero_grad();
  (net->forward(x) - y).square().mean().backward();
  learn::average_gradients(sync, packed.tensor().grad());
  return packed.tensor().grad().clone();
}

inline void write_tensor(const std::filesystem::path& file, const torch::Tensor& t) {
  std::ofstream out(file, std::ios::binary);
  out.write(static_cast<const char*>(t.data_ptr()), t.numel() * t.element_size());
}

inline dist::Rendezvous worker_rendezvous() {
  dist::RendezvousFlags flags;
  flags.timeout_seconds = 20;
  return dist::resolve_rendezvous(flags, dist::process_env());
}

// One rank of a test run; returns the exit code.
inline int run_worker(const std::string& name) {
  const std::filesystem::path dir = std::getenv("CRADLE_DIST_DIR");
  dist::ProcessGroup group(worker_rendezvous());
  train::DistSync sync(group);
  const std::string rank = std::to_string(group.rank());
  if (name == "gradient") {
    // The averaged gradient, and rank 0's network broadcast over this rank's own.
    write_tensor(dir / ("gradient_rank" + rank + ".bin"), rank_gradient(group.rank(), &sync));
    torch::nn::Sequential net = small_net(1000 + group.rank());
    learn::broadcast_module(&sync, *net);
    std::printf("hash %016llx\n",
                static_cast<unsigned long long>(learn::tensor_hash(net->parameters())));
    return 0;
  }
  if (name == "join") {
    group.barrier();
    std::printf("joined\n");
    return 0;
  }
  if (name == "die" || name == "fail") {
    // Rank 1 stops after a few all-reduces (killed, or failing and saying why); the others go on.
    std::vector<float> values(1000, 1.0f);
    for (int i = 0;; ++i) {
      if (group.rank() == 1 && i == 3) {
        if (name == "die") ::raise(SIGKILL);
        group.announce_failure("the disk is full");
        return 1;
      }
      group.all_reduce(values, dist::Reduce::kSum);
      for (float& v : values) v /= static_cast<float>(group.world_size());
    }
  }
  std::fprintf(stderr, "unknown worker %s\n", name.c_str());
  return 2;
}

}  // namespace cradle::test
