// A simulated learner for comparing teachers without an env (the synthetic student of Portelas et
// al.'s ALP-GMM paper, simplified): the task space [0, 1]^2 is a grid of cells; practising a cell
// raises its competence only when the cell is learnable and it, or a neighbour, is already under
// way, so skills spread outward from a mastered corner and a large region can never be learnt.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "teach/teacher.h"

namespace cradle::teach {

struct SyntheticStudentOptions {
  int cells = 20;             // per dimension
  int learnable_columns = 8;  // cells with x index below this can be learnt (40 %)
  double gain = 0.1;          // competence per practice episode
  double mastery = 0.9;       // competence at which a cell counts as mastered
  double max_return = 200;    // return = max_return * competence + noise
  double noise = 1.0;         // return noise std
};

class SyntheticStudent {
 public:
  // Throws UserError on non-positive sizes or a gain / mastery outside (0, 1].
  SyntheticStudent(SyntheticStudentOptions options, std::uint64_t seed);
  // One episode on a task in [0, 1]^2 (clipped into the grid): the return and the success.
  std::pair<double, bool> play(const Task& task);
  // The return a task would give now without noise (a perfect critic, for SPDL).
  double expected_return(const Task& task) const;
  // Share of all cells mastered, in %.
  double mastered_percent() const;

 private:
  // Competence at mastery, up to rounding (9 gains of 0.1 make 0.8999...).
  bool mastered(double c) const;
  int cell_of(float x) const;
  bool can_learn(int cx, int cy) const;

  SyntheticStudentOptions o_;
  Rng rng_;
  std::vector<double> competence_;  // row-major, x index fastest
};

// Trains a fresh student with `teacher` for `episodes` one-step episodes (the task is the initial
// state; the student's noiseless expected return is the value estimate); the % of cells mastered.
double run_synthetic_curriculum(Teacher& teacher, int episodes, std::uint64_t seed,
                                const SyntheticStudentOptions& options = {});

// Welch's t statistic of a against b (positive when a's mean is larger).
double welch_t(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace cradle::teach
