// Self-touch: which of MIMo's geoms each hand has touched since reset. A hand is the hand body
// and its fingers (mitten or finger segments); both hands record symmetrically; a hand's own
// geoms never count.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "envs/task.h"

namespace cradle::envs {

class SelfTouch final : public Task {
 public:
  // The reference's denominator: 34 touchable geoms per hand (36 MIMo geoms minus 2 of the hand).
  static constexpr int kReferenceGeomsPerHand = 34;

  explicit SelfTouch(const mjModel* m);
  void reset(const mjModel* m, const mjData* d, Info& info) override;
  double after_step(const mjModel* m, const mjData* d, Info& info) override;

  // Geoms that belong to a hand (0 right, 1 left).
  const std::vector<int>& hand_geoms(int hand) const { return hand_geoms_[hand]; }
  // MIMo's geoms (the subtree of "hip"), in id order.
  const std::vector<int>& mimo_geoms() const { return mimo_geoms_; }

 private:
  void record(int hand, int other, Info& info);
  std::vector<int> hand_of_geom_;  // -1 none, 0 right hand, 1 left hand
  std::vector<char> is_mimo_;
  std::vector<int> hand_geoms_[2];
  std::vector<int> mimo_geoms_;
  std::vector<char> seen_[2];
};

// A readable label for a geom: "<body>" or "<body>/<geom name>" or "<body>#<index in body>".
std::string geom_label(const mjModel* m, int geom);

}  // namespace cradle::envs
