#include "learn/grad_sync.h"

#include <ATen/CPUGeneratorImpl.h>

#include "learn/grad_tensors.h"

namespace cradle::learn {
namespace {

std::span<float> floats(const torch::Tensor& tensor) {
  return {tensor.data_ptr<float>(), static_cast<size_t>(tensor.numel())};
}

}  // namespace

void average_gradients(GradSync* sync, const torch::Tensor& gradient) {
  if (!distributed(sync) || !gradient.defined()) return;
  sync->all_reduce_sum(floats(gradient));
  gradient.div_(sync->world_size());
}

void broadcast_tensor(GradSync* sync, const torch::Tensor& tensor) {
  if (!distributed(sync) || !tensor.defined() || tensor.scalar_type() != torch::kFloat32) return;
  torch::NoGradGuard no_grad;
  if (tensor.is_contiguous()) {
    sync->broadcast(floats(tensor));
    return;
  }
  const torch::Tensor copy = tensor.contiguous();
  sync->broadcast(floats(copy));
  tensor.copy_(copy);
}

void broadcast_module(GradSync* sync, torch::nn::Module& module) {
  if (!distributed(sync)) return;
  for (const torch::Tensor& p : module.parameters()) broadcast_tensor(sync, p.detach());
  for (const torch::Tensor& b : module.buffers()) broadcast_tensor(sync, b.detach());
}

double agree_max(GradSync* sync, double value) {
  if (!distributed(sync)) return value;
  sync->all_reduce_max({&value, 1});
  return value;
}

double agree_mean(GradSync* sync, double value) {
  if (!distributed(sync)) return value;
  sync->all_reduce_sum({&value, 1});
  return value / sync->world_size();
}

std::string first_disagreement(GradSync& sync,
                               const std::vector<std::pair<std::string, double>>& values) {
  // Each value's maximum and the maximum of its negation: equal magnitudes where all agree.
  std::vector<double> extremes;
  for (const auto& [name, value] : values) extremes.push_back(value);
  for (const auto& [name, value] : values) extremes.push_back(-value);
  sync.all_reduce_max(extremes);
  for (size_t i = 0; i < values.size(); ++i) {
    if (extremes[i] != -extremes[values.size() + i]) return values[i].first;
  }
  return "";
}

void offset_generator(GradSync* sync, at::Generator& generator) {
  if (!distributed(sync) || sync->rank() == 0) return;
  const std::lock_guard<std::mutex> lock(generator.mutex());
  auto* cpu = at::check_generator<at::CPUGeneratorImpl>(generator);
  const std::uint64_t seed = cpu->random64() ^ (0x9e3779b97f4a7c15ULL * sync->rank());
  cpu->set_current_seed(seed);
}

std::uint64_t tensor_hash(const std::vector<torch::Tensor>& tensors) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const torch::Tensor& t : tensors) {
    const torch::Tensor c = t.detach().contiguous();
    const auto* bytes = static_cast<const unsigned char*>(c.data_ptr());
    const size_t size = static_cast<size_t>(c.numel()) * c.element_size();
    for (size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
  }
  return hash;
}

}  // namespace cradle::learn
