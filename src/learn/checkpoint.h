// Checkpoint files: one LibTorch archive holding a header (format version, algorithm, config
// text, step counter) and whatever the learner adds (modules, optimisers, the observation
// normaliser, random generators) under its own keys, sealed with checksums (core/sealed_file.h):
// a truncated or altered file is a one-line UserError. Writes are atomic: the file goes to
// "<file>.tmp" in the same folder, synced and renamed over <file>, so a crash or a full disk never
// leaves a half-written checkpoint behind (the temp file is removed on a write error).
#pragma once

#include <torch/torch.h>

#include <filesystem>
#include <functional>
#include <string>

#include "learn/learner.h"
#include "learn/preprocess.h"

namespace cradle::learn {

inline constexpr long kCheckpointFormat = 1;
// The LibTorch archive's section in the sealed checkpoint file (core/sealed_file.h); a trainer
// may add sections of its own (run state, intrinsic rewards) beside it.
inline constexpr const char* kCheckpointPayload = "learner";

using ArchiveWriter = std::function<void(torch::serialize::OutputArchive&)>;
// Reads the body; gets the header (e.g. to check the saved config against the learner's).
using ArchiveReader =
    std::function<void(const CheckpointInfo& header, torch::serialize::InputArchive&)>;

// Writes the header and then calls `write_body`; creates the parent folder if needed.
void write_checkpoint(const std::filesystem::path& file, const CheckpointInfo& header,
                      const ArchiveWriter& write_body);
// Reads the header, checks the format and the algorithm (UserError on a mismatch), then calls
// `read_body`. LibTorch errors (missing keys, shape mismatches) become UserErrors naming the file.
CheckpointInfo read_checkpoint(const std::filesystem::path& file, std::string_view algorithm,
                               const ArchiveReader& read_body);

// Nested archives for the parts. read_module checks every parameter's and buffer's shape before
// copying any (UserError naming the first mismatch; the module is then unchanged) and copies
// in place, so tensors keep their storage (PackedParameters stay packed).
void write_module(torch::serialize::OutputArchive& archive, const std::string& key,
                  const torch::nn::Module& module);
void read_module(torch::serialize::InputArchive& archive, const std::string& key,
                 torch::nn::Module& module);
// read_module in two halves, for checkpoints of several modules: reads and checks every shape
// (nothing changes; UserError on a mismatch) and returns the copy to run once all have passed.
std::function<void()> stage_module(torch::serialize::InputArchive& archive, const std::string& key,
                                   torch::nn::Module& module);
void write_optimizer(torch::serialize::OutputArchive& archive, const std::string& key,
                     const torch::optim::Optimizer& optimizer);
void read_optimizer(torch::serialize::InputArchive& archive, const std::string& key,
                    torch::optim::Optimizer& optimizer);
// A generator's full state, so sampling continues exactly where it stopped.
void write_generator(torch::serialize::OutputArchive& archive, const std::string& key,
                     const at::Generator& generator);
void read_generator(torch::serialize::InputArchive& archive, const std::string& key,
                    at::Generator& generator);

// The observation normaliser's statistics (ObservationPipeline::save / load) in a nested archive.
void write_normalizer(torch::serialize::OutputArchive& archive, const std::string& key,
                      const ObservationPipeline& pipeline);
void read_normalizer(torch::serialize::InputArchive& archive, const std::string& key,
                     ObservationPipeline& pipeline);

// The whole checkpoint of a policy-gradient learner (PPO, A2C): its policy, optimiser,
// observation normaliser and generator under fixed keys, then whatever `extra` adds.
void save_policy_checkpoint(const std::filesystem::path& file, const CheckpointInfo& header,
                            const torch::nn::Module& policy,
                            const torch::optim::Optimizer& optimizer,
                            const ObservationPipeline& pipeline, const at::Generator& generator,
                            const ArchiveWriter& extra = {});
// Reads one back after checking its observation settings against `observation` and running
// `check` (it reads and checks what `extra` wrote, before anything changes); returns the header
// (its step counter is the learner's).
CheckpointInfo load_policy_checkpoint(const std::filesystem::path& file, std::string_view algorithm,
                                      const ObservationConfig& observation,
                                      torch::nn::Module& policy, torch::optim::Optimizer& optimizer,
                                      ObservationPipeline& pipeline, at::Generator& generator,
                                      const ArchiveReader& check = {});

}  // namespace cradle::learn
