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
  // Info: "right_hand_touches", "left_hand_touches" (geom ids in order of first contact).
  void declare(Info& info) override;
  void reset(const MimoCore& core, Info& info) override { reset(core.model(), core.data(), info); }
  double after_step(const MimoCore& core, Info& info) override {
    return after_step(core.model(), core.data(), info);
  }
  // The same on any model and data (the tests' inline models).
  void reset(const mjModel* m, const mjData* d, Info& info);
  double after_step(const mjModel* m, const mjData* d, Info& info);
  // (|right| + |left|) / 68.
  double score(const Info& info, int steps) const override;
  // The skin map above the top camera, and the touch lists charted per body part.
  EvaluationPanels evaluation_panels() const override;

  // Geoms that belong to a hand (0 right, 1 left).
  const std::vector<int>& hand_geoms(int hand) const { return hand_geoms_[hand]; }
  // MIMo's geoms (the subtree of "hip"), in id order.
  const std::vector<int>& mimo_geoms() const { return mimo_geoms_; }
  // The rule: the hand (0 right, 1 left) for which touching `other` with `hand_geom` counts, -1
  // when it does not count (not a hand geom, not MIMo's, or the same hand).
  int touching_hand(int hand_geom, int other) const {
    const int hand = hand_of_geom_[hand_geom];
    return hand >= 0 && is_mimo_[other] && hand_of_geom_[other] != hand ? hand : -1;
  }

 private:
  void record(int hand, int other, Info& info);
  int slot_[2] = {-1, -1};         // right_hand_touches, left_hand_touches
  std::vector<int> hand_of_geom_;  // -1 none, 0 right hand, 1 left hand
  std::vector<char> is_mimo_;
  std::vector<int> hand_geoms_[2];
  std::vector<int> mimo_geoms_;
  std::vector<char> seen_[2];
};

// The MIMo geoms each hand touches in this step under the self-touch rule, each once, as the
// unpublished info lists "right_hand_contacts" and "left_hand_contacts" (for learners that reward
// contact onsets). Every BabyBench env publishes them, whatever its behaviour.
class HandContacts {
 public:
  explicit HandContacts(const mjModel* m);
  void declare(Info& info);
  void update(const mjData* d, Info& info);

 private:
  SelfTouch rule_;
  int slot_[2] = {-1, -1};
  std::vector<char> marked_[2];
};

// A readable label for a geom: "<body>" or "<body>/<geom name>" or "<body>#<index in body>".
std::string geom_label(const mjModel* m, int geom);

}  // namespace cradle::envs
