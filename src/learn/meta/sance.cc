#include "learn/meta/sance.h"

#include <algorithm>

namespace cradle::learn::meta {
namespace {

// Masked steps zeroed, (time, trajectory) flattened, optionally mapped by W, L2-normalised
// (zero vectors stay zero).
torch::Tensor embeddings(const torch::Tensor& x, const torch::Tensor& mask,
                         const torch::Tensor& bilinear) {
  torch::Tensor flat = (x * mask.unsqueeze(2)).reshape({-1, x.size(2)});
  if (bilinear.defined()) flat = torch::matmul(flat, bilinear.t());
  // F.normalize's own sum (x / max(|x|, 1e-12) per row), written out: copying its options (an
  // optional<Tensor> inside) is a -Wmaybe-uninitialized error of GCC 12 in the -O1 sanitizer build.
  return flat / flat.norm(2, 1, true).clamp_min(1e-12);
}

}  // namespace

torch::Tensor sance_loss(const torch::Tensor& queries, const torch::Tensor& positive_keys,
                         const torch::Tensor& negative_keys, const torch::Tensor& positive_mask,
                         const torch::Tensor& negative_mask, double temperature,
                         const torch::Tensor& bilinear) {
  const torch::Tensor q = embeddings(queries, positive_mask, {});
  const torch::Tensor kp = embeddings(positive_keys, positive_mask, bilinear);
  const torch::Tensor kn = embeddings(negative_keys, negative_mask, bilinear);
  const torch::Tensor positive_logits = torch::matmul(q, kp.t()) / temperature;
  const torch::Tensor negative_logits = torch::matmul(q, kn.t()) / temperature;
  // log(1 - sigmoid(x)) = log sigmoid(-x).
  return -torch::log_sigmoid(positive_logits).mean() - torch::log_sigmoid(-negative_logits).mean();
}

double sance_weight(double lambda, double positive_return, double negative_return) {
  return std::clamp(lambda * (positive_return - negative_return), 0.0, 1.0);
}

}  // namespace cradle::learn::meta
