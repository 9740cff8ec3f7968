// The learners' GradSync over a dist::ProcessGroup: the one place where learn/ meets dist/.
#pragma once

#include "dist/process_group.h"
#include "learn/grad_sync.h"

namespace cradle::train {

class DistSync final : public learn::GradSync {
 public:
  explicit DistSync(dist::ProcessGroup& group) : group_(group) {}
  int rank() const override { return group_.rank(); }
  int world_size() const override { return group_.world_size(); }
  void all_reduce_sum(std::span<float> values) override {
    group_.all_reduce(values, dist::Reduce::kSum);
  }
  void all_reduce_sum(std::span<double> values) override {
    group_.all_reduce(values, dist::Reduce::kSum);
  }
  void all_reduce_max(std::span<double> values) override {
    group_.all_reduce(values, dist::Reduce::kMax);
  }
  void broadcast(std::span<float> values) override { group_.broadcast(values, 0); }

 private:
  dist::ProcessGroup& group_;
};

}  // namespace cradle::train
