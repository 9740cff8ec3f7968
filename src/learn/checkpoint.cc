#include "learn/checkpoint.h"

#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/sealed_file.h"

namespace cradle::learn {
namespace {

// The first line of a library message (LibTorch's run over several).
std::string first_line(std::string_view text) {
  return std::string(text.substr(0, text.find('\n')));
}

std::string read_string(torch::serialize::InputArchive& archive, const std::string& key) {
  c10::IValue value;
  archive.read(key, value);
  return value.toStringRef();
}

long read_int(torch::serialize::InputArchive& archive, const std::string& key) {
  c10::IValue value;
  archive.read(key, value);
  return value.toInt();
}

// Reads the header of an already loaded archive.
CheckpointInfo read_header(torch::serialize::InputArchive& archive,
                           const std::filesystem::path& file) {
  const long format = read_int(archive, "format");
  if (format != kCheckpointFormat) {
    throw UserError(file.string() + ": checkpoint format " + std::to_string(format) +
                    ", this build reads format " + std::to_string(kCheckpointFormat));
  }
  return {.algorithm = read_string(archive, "algorithm"),
          .config = read_string(archive, "config"),
          .steps = read_int(archive, "steps")};
}

// Verifies the sealed file (sizes, checksums) before LibTorch sees a byte of it.
void load_archive(torch::serialize::InputArchive& archive, const std::filesystem::path& file) {
  const Sections sections = read_sealed(file, "checkpoint");
  const auto payload = sections.find(kCheckpointPayload);
  if (payload == sections.end()) {
    throw UserError(file.string() + ": not a Cradle checkpoint (no learner payload)");
  }
  try {
    std::istringstream in(payload->second);
    archive.load_from(in);
  } catch (const c10::Error& error) {
    throw UserError(file.string() + ": not a Cradle checkpoint (" +
                    first_line(error.what_without_backtrace()) + ")");
  } catch (const std::exception& error) {
    throw UserError(file.string() + ": not a Cradle checkpoint (" + first_line(error.what()) + ")");
  }
}

}  // namespace

void write_checkpoint(const std::filesystem::path& file, const CheckpointInfo& header,
                      const ArchiveWriter& write_body) {
  torch::serialize::OutputArchive archive;
  archive.write("format", c10::IValue(static_cast<int64_t>(kCheckpointFormat)));
  archive.write("algorithm", c10::IValue(header.algorithm));
  archive.write("config", c10::IValue(header.config));
  archive.write("steps", c10::IValue(static_cast<int64_t>(header.steps)));
  write_body(archive);

  // Serialised in memory, then sealed (checksums) and written atomically.
  std::ostringstream bytes;
  try {
    archive.save_to(bytes);
  } catch (const c10::Error& error) {
    throw UserError(file.string() + ": cannot write checkpoint (" +
                    first_line(error.what_without_backtrace()) + ")");
  }
  write_sealed(file, {{kCheckpointPayload, std::move(bytes).str()}});
}

CheckpointInfo read_checkpoint(const std::filesystem::path& file, std::string_view algorithm,
                               const ArchiveReader& read_body) {
  torch::serialize::InputArchive archive;
  load_archive(archive, file);
  try {
    CheckpointInfo info = read_header(archive, file);
    if (info.algorithm != algorithm) {
      throw UserError(file.string() + ": a " + info.algorithm + " checkpoint, not " +
                      std::string(algorithm));
    }
    try {
      read_body(info, archive);
    } catch (const UserError& error) {
      throw UserError(file.string() + ": does not fit this learner (" + error.what() + ")");
    }
    return info;
  } catch (const c10::Error& error) {
    throw UserError(file.string() + ": does not fit this learner (" +
                    first_line(error.what_without_backtrace()) + ")");
  }
}

CheckpointInfo read_checkpoint_info(const std::filesystem::path& file) {
  torch::serialize::InputArchive archive;
  load_archive(archive, file);
  try {
    return read_header(archive, file);
  } catch (const c10::Error& error) {
    throw UserError(file.string() + ": not a Cradle checkpoint (" +
                    first_line(error.what_without_backtrace()) + ")");
  }
}

namespace {

// Parameters and buffers under their names, each child module in a nested archive.
void write_tensors(torch::serialize::OutputArchive& archive, const torch::nn::Module& module) {
  for (const auto& parameter : module.named_parameters(/*recurse=*/false)) {
    archive.write(parameter.key(), parameter.value());
  }
  for (const auto& buffer : module.named_buffers(/*recurse=*/false)) {
    archive.write(buffer.key(), buffer.value(), /*is_buffer=*/true);
  }
  for (const auto& child : module.named_children()) {
    torch::serialize::OutputArchive nested(archive.compilation_unit());
    write_tensors(nested, *child.value());
    archive.write(child.key(), nested);
  }
}

// Reads what write_tensors wrote into (destination, stored) pairs, checking every shape.
void stage_tensors(torch::serialize::InputArchive& archive, torch::nn::Module& module,
                   const std::string& prefix,
                   std::vector<std::pair<torch::Tensor, torch::Tensor>>& staged) {
  auto stage = [&](const std::string& name, const torch::Tensor& destination, bool is_buffer) {
    torch::Tensor stored;
    archive.read(name, stored, is_buffer);
    if (stored.sizes() != destination.sizes()) {
      std::ostringstream message;
      message << prefix << name << " has shape " << stored.sizes() << " in the checkpoint, "
              << destination.sizes() << " in this network";
      throw UserError(message.str());
    }
    staged.emplace_back(destination, stored);
  };
  for (const auto& parameter : module.named_parameters(/*recurse=*/false)) {
    stage(parameter.key(), parameter.value(), false);
  }
  for (const auto& buffer : module.named_buffers(/*recurse=*/false)) {
    stage(buffer.key(), buffer.value(), true);
  }
  for (const auto& child : module.named_children()) {
    torch::serialize::InputArchive nested;
    archive.read(child.key(), nested);
    stage_tensors(nested, *child.value(), prefix + child.key() + ".", staged);
  }
}

}  // namespace

void write_module(torch::serialize::OutputArchive& archive, const std::string& key,
                  const torch::nn::Module& module) {
  torch::serialize::OutputArchive nested(archive.compilation_unit());
  write_tensors(nested, module);
  archive.write(key, nested);
}

std::function<void()> stage_module(torch::serialize::InputArchive& archive, const std::string& key,
                                   torch::nn::Module& module) {
  torch::serialize::InputArchive nested;
  archive.read(key, nested);
  std::vector<std::pair<torch::Tensor, torch::Tensor>> staged;
  stage_tensors(nested, module, key + ".", staged);
  // Every shape matched: the copy is in place (the tensors keep their storage).
  return [staged = std::move(staged)] {
    torch::NoGradGuard no_grad;
    for (const auto& [destination, stored] : staged) destination.copy_(stored);
  };
}

void read_module(torch::serialize::InputArchive& archive, const std::string& key,
                 torch::nn::Module& module) {
  stage_module(archive, key, module)();
}

namespace {

// Optimiser state keyed by (group, parameter) index. LibTorch's own Optimizer::save keys it by
// each parameter's address, which made identical runs write different checkpoints.
std::string slot(size_t group, size_t param) {
  return "group" + std::to_string(group) + "/param" + std::to_string(param);
}

std::string tensor_key(const torch::Tensor& t) {
  return c10::guts::to_string(t.unsafeGetTensorImpl());
}

template <class State, class Options>
void write_states(torch::serialize::OutputArchive& nested, const torch::optim::Optimizer& opt) {
  const auto& groups = opt.param_groups();
  for (size_t g = 0; g < groups.size(); ++g) {
    torch::serialize::OutputArchive options(nested.compilation_unit());
    static_cast<const Options&>(groups[g].options()).serialize(options);
    nested.write("group" + std::to_string(g) + "/options", options);
    const auto& params = groups[g].params();
    for (size_t p = 0; p < params.size(); ++p) {
      const auto it = opt.state().find(tensor_key(params[p]));
      if (it == opt.state().end()) continue;
      torch::serialize::OutputArchive state(nested.compilation_unit());
      static_cast<const State&>(*it->second).serialize(state);
      nested.write(slot(g, p), state);
    }
  }
}

template <class State, class Options>
void read_states(torch::serialize::InputArchive& nested, torch::optim::Optimizer& opt) {
  auto& groups = opt.param_groups();
  opt.state().clear();
  for (size_t g = 0; g < groups.size(); ++g) {
    torch::serialize::InputArchive options;
    nested.read("group" + std::to_string(g) + "/options", options);
    static_cast<Options&>(groups[g].options()).serialize(options);
    const auto& params = groups[g].params();
    for (size_t p = 0; p < params.size(); ++p) {
      torch::serialize::InputArchive archive;
      if (!nested.try_read(slot(g, p), archive)) continue;
      auto state = std::make_unique<State>();
      state->serialize(archive);
      opt.state()[tensor_key(params[p])] = std::move(state);
    }
  }
}

}  // namespace

void write_optimizer(torch::serialize::OutputArchive& archive, const std::string& key,
                     const torch::optim::Optimizer& optimizer) {
  torch::serialize::OutputArchive nested(archive.compilation_unit());
  if (dynamic_cast<const torch::optim::Adam*>(&optimizer)) {
    nested.write("kind", c10::IValue(std::string("adam")));
    write_states<torch::optim::AdamParamState, torch::optim::AdamOptions>(nested, optimizer);
  } else if (dynamic_cast<const torch::optim::RMSprop*>(&optimizer)) {
    nested.write("kind", c10::IValue(std::string("rmsprop")));
    write_states<torch::optim::RMSpropParamState, torch::optim::RMSpropOptions>(nested, optimizer);
  } else {
    optimizer.save(nested);  // other optimisers: LibTorch's format
  }
  archive.write(key, nested);
}

void read_optimizer(torch::serialize::InputArchive& archive, const std::string& key,
                    torch::optim::Optimizer& optimizer) {
  torch::serialize::InputArchive nested;
  archive.read(key, nested);
  c10::IValue kind;
  if (!nested.try_read("kind", kind)) {
    optimizer.load(nested);
    return;
  }
  if (kind.toStringRef() == "adam" && dynamic_cast<torch::optim::Adam*>(&optimizer)) {
    read_states<torch::optim::AdamParamState, torch::optim::AdamOptions>(nested, optimizer);
  } else if (kind.toStringRef() == "rmsprop" && dynamic_cast<torch::optim::RMSprop*>(&optimizer)) {
    read_states<torch::optim::RMSpropParamState, torch::optim::RMSpropOptions>(nested, optimizer);
  } else {
    throw UserError(key + ": a " + kind.toStringRef() + " optimiser state, not this learner's");
  }
}

void write_generator(torch::serialize::OutputArchive& archive, const std::string& key,
                     const at::Generator& generator) {
  archive.write(key, generator.get_state());
}

void read_generator(torch::serialize::InputArchive& archive, const std::string& key,
                    at::Generator& generator) {
  torch::Tensor state;
  archive.read(key, state);
  generator.set_state(state);
}

void write_normalizer(torch::serialize::OutputArchive& archive, const std::string& key,
                      const ObservationPipeline& pipeline) {
  torch::serialize::OutputArchive nested(archive.compilation_unit());
  pipeline.save(nested);
  archive.write(key, nested);
}

void read_normalizer(torch::serialize::InputArchive& archive, const std::string& key,
                     ObservationPipeline& pipeline) {
  torch::serialize::InputArchive nested;
  archive.read(key, nested);
  pipeline.load(nested);
}

void save_policy_checkpoint(const std::filesystem::path& file, const CheckpointInfo& header,
                            const torch::nn::Module& policy,
                            const torch::optim::Optimizer& optimizer,
                            const ObservationPipeline& pipeline, const at::Generator& generator,
                            const ArchiveWriter& extra) {
  write_checkpoint(file, header, [&](torch::serialize::OutputArchive& archive) {
    write_module(archive, "policy", policy);
    write_optimizer(archive, "optimizer", optimizer);
    write_normalizer(archive, "normalizer", pipeline);
    write_generator(archive, "generator", generator);
    if (extra) extra(archive);
  });
}

CheckpointInfo load_policy_checkpoint(const std::filesystem::path& file, std::string_view algorithm,
                                      const ObservationConfig& observation,
                                      torch::nn::Module& policy, torch::optim::Optimizer& optimizer,
                                      ObservationPipeline& pipeline, at::Generator& generator,
                                      const ArchiveReader& check) {
  return read_checkpoint(
      file, algorithm, [&](const CheckpointInfo& header, torch::serialize::InputArchive& archive) {
        observation.check_matches(header.config);
        if (check) check(header, archive);
        read_module(archive, "policy", policy);
        read_optimizer(archive, "optimizer", optimizer);
        read_normalizer(archive, "normalizer", pipeline);
        read_generator(archive, "generator", generator);
      });
}

}  // namespace cradle::learn
