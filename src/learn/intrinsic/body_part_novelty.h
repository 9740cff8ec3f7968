// body_part_novelty: count-based novelty of self-touch, per hand and per touched MIMo geom.
//
// Events. In each step, env i produces
//   first touches: the geom ids appended this step to the info lists "right_hand_touches" (hand 0)
//     and "left_hand_touches" (hand 1), i.e. the geoms a hand touches for the first time in the
//     episode (the env's self-touch behaviour decides what a touch is: any contact between a hand
//     geom and another MIMo geom outside that hand);
//   contact onsets (when the env publishes "right_hand_contacts" and "left_hand_contacts", the
//     geoms each hand touches in this step by the same rule): the (hand, geom) pairs in contact
//     in this step but not in the previous one.
// Counts over the whole training run, shared by every env of the vector:
//   n(h, g): first touches of geom g by hand h so far;   m(h, g): contact onsets so far;
//   D_h: the number of geoms with n(h, g) > 0 (distinct geoms hand h has ever touched).
// Reward of env i in a step:
//   r = sum over first touches (h, g):  w_h / sqrt(1 + n(h, g))
//     + onset_weight x sum over onsets (h, g):  w_h / sqrt(1 + m(h, g))
// with the hand balance weight
//   w_h = (1 - balance) + balance x 2 (1 + D_o) / (2 + D_h + D_o),   o the other hand,
// which is 1 for both hands when they have touched equally many geoms and moves towards 2 for the
// hand that lags (and towards 0 for the one that leads) as the gap grows. Counts and D are read
// before the step and updated after every env's reward is computed, so the result does not depend
// on env order. A geom's first touch is worth 1 the first time ever and fades as 1/sqrt(1 + n)
// over episodes: the bonus tracks the metric (the union of touched geoms over training) while
// still paying, a little, for re-finding known geoms in every episode.
//
// Reads only Info; its cost is a scan of this step's contact lists.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

struct BodyPartNoveltyOptions {
  double onset_weight = 0.1;  // weight of contact-onset events relative to first touches
                              // (0: first touches only)
  double balance = 0.5;       // 0: hands weighted equally; 1: full weighting towards the hand
                              // with fewer distinct geoms (formula above)
};

class BodyPartNovelty final : public IntrinsicReward {
 public:
  using Options = BodyPartNoveltyOptions;
  explicit BodyPartNovelty(double scale = 1.0, Options options = {});

  std::string_view name() const override { return "body_part_novelty"; }
  void bind(const VecEnv& env) override;
  void reset(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;
  void save(const std::filesystem::path& dir) const override;
  void load(const std::filesystem::path& dir) override;

  // Counts so far (0 for geoms never seen).
  long first_touches(int hand, int geom) const { return count(first_[hand], geom); }
  long onsets(int hand, int geom) const { return count(onset_[hand], geom); }
  int distinct_geoms(int hand) const { return distinct_[hand]; }
  // The balance weight w_h with the current counts.
  double hand_weight(int hand) const;

 private:
  struct Event {
    int hand, geom;
    bool onset;
  };
  static long count(const std::vector<long>& counts, int geom) {
    return geom >= 0 && geom < static_cast<int>(counts.size()) ? counts[geom] : 0;
  }
  void start_episode(int id);
  // Appends the contact onsets of slot i (env id `id`) in this step to events_ and remembers its
  // contacts.
  void collect_onsets(const VecEnv& env, int i, int id);

  Options options_;
  // Counts over training (index: geom id; grown on demand).
  std::array<std::vector<long>, 2> first_, onset_;
  std::array<int, 2> distinct_{0, 0};

  // Per env id: entries of the Info touch lists already rewarded, and (for onsets) which geoms
  // each hand touched in the previous step (indexed id * 2 + hand, then geom id; grown on
  // demand).
  std::vector<std::array<size_t, 2>> seen_;
  std::vector<std::vector<std::uint8_t>> in_contact_, now_;
  detail::EpisodeStarts starts_;

  // Info slots of the env's touch and contact lists per hand (-1: not published).
  std::array<int, 2> touches_slot_{-1, -1}, contacts_slot_{-1, -1};
  bool onsets_ = false;         // the env publishes its contacts and onset_weight > 0
  std::vector<Event> events_;   // scratch: this step's events
  std::vector<int> event_env_;  // scratch: the slot of each event
};

}  // namespace cradle::learn::intrinsic
