#include "train/babybench_vector.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "envs/babybench.h"

namespace cradle::train {
namespace {

// Refuses a vector whose envs' MuJoCo data (stack, buffer and the dense constraint arrays, about
// 12 bytes per njmax^2 as measured on MuJoCo 2.2.2) and eye images need more than 80 % of the
// physical memory: it would be killed or swap.
void check_env_memory(const envs::BabyBenchAssets& assets, int num_envs) {
  const mjModel* m = assets.model.get();
  double per_env = static_cast<double>(m->nstack) * sizeof(mjtNum) + m->nbuffer +
                   12.0 * static_cast<double>(m->njmax) * m->njmax;
  if (assets.config.vision_active) {
    per_env += 2.0 * 4 * assets.config.vision_resolution * assets.config.vision_resolution * 4;
  }
  const double physical =
      static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  const double limit = 0.8 * physical;
  if (per_env * num_envs <= limit) return;
  char message[256];
  std::snprintf(message, sizeof message,
                "%d envs need about %.1f GB (%.0f MB each), more than 80%% of this machine's "
                "%.1f GB of memory; use at most %d envs",
                num_envs, per_env * num_envs / 1e9, per_env / 1e6, physical / 1e9,
                std::max(1, static_cast<int>(limit / per_env)));
  throw UserError(message);
}

}  // namespace

namespace {

// The vector, and each env's BabyBench face (for the training log's bookkeeping).
TrainingVector make_vector(const Config& config, int num_envs, int threads, bool training,
                           std::uint64_t seed, long continue_log, const EnvWrapper& wrap,
                           int async_batch, int procs = 0) {
  using learn::AsyncVecEnv;
  using learn::ThreadedVecEnv;
  if (num_envs < 1) throw std::invalid_argument("make_babybench_vec_env: num_envs < 1");
  // One compiled model for all; one training log shared by all (it is thread-safe).
  const auto assets = envs::make_assets(config);
  check_env_memory(*assets, num_envs);
  TrainingVector out;
  out.geom_count = assets->model->ngeom;
  if (training) out.log = envs::start_training(*assets, continue_log);
  // The log takes each env's entries in env order after every step, whatever thread ran first.
  if (out.log) out.log->set_slots(num_envs);
  auto envs = std::make_shared<std::vector<envs::BabyBenchEnv*>>(num_envs);
  auto make = [&](int i) {
    auto env = std::make_unique<envs::BabyBenchEnv>(assets, ThreadedVecEnv::env_seed(seed, i));
    if (out.log) env->attach_log(out.log, i);
    if (out.log && continue_log >= 0) env->skip_next_record();
    (*envs)[i] = env.get();
    return wrap ? wrap(std::move(env)) : std::unique_ptr<envs::Env>(std::move(env));
  };
  std::function<void()> commit;
  if (out.log) commit = [log = out.log] { log->commit(); };
  if (procs > 0) {
    // Each worker builds its envs (so the factory runs there); an env records its episodes in a
    // relay log whose entries ("R<json>" lines, "F" for a flush) reach the run's log here.
    auto outboxes = std::make_shared<std::vector<std::string>>(num_envs);
    learn::ProcVecEnv::Channels channels;
    if (out.log) {
      channels.outbox = [outboxes](int i, std::string& message) {
        std::swap(message, (*outboxes)[i]);
      };
      channels.inbox = [log = out.log](int i, std::string_view message) {
        while (!message.empty()) {
          const size_t end = message.find('\n');
          const std::string_view line = message.substr(0, end);
          if (line.starts_with('R')) {
            log->add(nlohmann::json::parse(line.substr(1)), i);
          } else {
            log->flush();
          }
          message.remove_prefix(end == std::string_view::npos ? message.size() : end + 1);
        }
      };
    }
    channels.calls.push_back([envs](int i) { (*envs)[i]->end_episode(); });
    auto make_in_worker = [&](int i) {
      auto env = std::make_unique<envs::BabyBenchEnv>(assets, ThreadedVecEnv::env_seed(seed, i));
      if (out.log) {
        env->attach_log(std::make_shared<envs::TrainingLog>([outboxes, i](const nlohmann::json* e) {
          std::string& box = (*outboxes)[i];
          box += e ? "R" + e->dump() + "\n" : std::string("F\n");
        }));
      }
      if (out.log && continue_log >= 0) env->skip_next_record();
      (*envs)[i] = env.get();
      return wrap ? wrap(std::move(env)) : std::unique_ptr<envs::Env>(std::move(env));
    };
    auto vec =
        std::make_unique<learn::ProcVecEnv>(num_envs, make_in_worker, procs, std::move(channels));
    vec->set_after_step(commit);
    learn::ProcVecEnv* raw = vec.get();
    out.end_episodes = [raw] { raw->call(0); };
    out.vec = std::move(vec);
    return out;
  }
  // Async: the envs built here, in env order; its after-step call follows every batch.
  if (async_batch > 0) {
    std::vector<std::unique_ptr<envs::Env>> list;
    for (int i = 0; i < num_envs; ++i) list.push_back(make(i));
    auto vec = std::make_unique<AsyncVecEnv>(std::move(list), async_batch, threads);
    vec->set_after_step(commit);
    out.vec = std::move(vec);
  } else {
    auto vec = std::make_unique<ThreadedVecEnv>(num_envs, make, threads);
    vec->set_after_step(commit);
    out.vec = std::move(vec);
  }
  out.end_episodes = [envs] {
    for (envs::BabyBenchEnv* env : *envs) env->end_episode();
  };
  return out;
}

}  // namespace

std::unique_ptr<learn::ThreadedVecEnv> make_babybench_vec_env(const Config& config, int num_envs,
                                                              int threads, bool training,
                                                              std::uint64_t seed, long continue_log,
                                                              const EnvWrapper& wrap) {
  // Without async_batch the vector is a ThreadedVecEnv.
  return std::unique_ptr<learn::ThreadedVecEnv>(static_cast<learn::ThreadedVecEnv*>(
      make_vector(config, num_envs, threads, training, seed, continue_log, wrap, 0).vec.release()));
}

std::unique_ptr<learn::ProcVecEnv> make_babybench_proc_vec_env(const Config& config, int num_envs,
                                                               int procs, bool training,
                                                               std::uint64_t seed) {
  return std::unique_ptr<learn::ProcVecEnv>(static_cast<learn::ProcVecEnv*>(
      make_vector(config, num_envs, 0, training, seed, -1, nullptr, 0, procs).vec.release()));
}

TrainingVector make_babybench_training(const Config& config, int num_envs, int threads,
                                       std::uint64_t seed, long continue_log,
                                       const EnvWrapper& wrap, int async_batch, int procs) {
  return make_vector(config, num_envs, threads, /*training=*/true, seed, continue_log, wrap,
                     async_batch, procs);
}

}  // namespace cradle::train
