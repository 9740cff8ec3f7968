// The synthetic-student comparison of teachers: each teacher trains 16 simulated
// students (teach/synthetic_student.h: a 20 x 20 grid over [0, 1]^2, 60 % unlearnable, skills
// spreading from one mastered corner) for the same number of episodes, against Random on the same
// seeds. Counters: % of the space mastered (mean, std) for the teacher and Random, and Welch's t.
// Teacher parameters are the benchmark values of the reference (spec tma_sami.md §2).
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "teach/registry.h"
#include "teach/synthetic_student.h"

namespace cradle::teach {
namespace {

constexpr int kSeeds = 16;

// `name` may carry a variant after a slash: "Covar-GMM/rnd20" keeps the class default random ratio.
TeacherSetup bench_setup(const std::string& label, std::uint64_t seed) {
  const std::string name = label.substr(0, label.find('/'));
  TeacherSetup s{.name = name, .mins = {0.f, 0.f}, .maxs = {1.f, 1.f}, .seed = seed};
  s.expert_knowledge = ExpertKnowledge::low;
  if (name == "ADR") {
    // ADR grows from the known corner (high expert knowledge); thresholds as the reference.
    s.expert_knowledge = ExpertKnowledge::high;
    s.initial_dist = DiagGaussian{{0.025f, 0.025f}, {0.f, 0.f}};
    s.params = {{"boundary_sampling_p", 0.7}};
  } else if (name == "RIAC") {
    s.params = {{"max_region_size", 150}, {"nb_split_attempts", 75}, {"min_dims_range_ratio", 0.1}};
  } else if (name == "ALP-GMM") {
    s.params = {
        {"fit_rate", 150}, {"potential_ks", {2, 3, 4, 5, 6, 7, 8, 9}}, {"random_task_ratio", 0.05}};
  } else if (name == "Covar-GMM") {
    s.params = {{"fit_rate", 150},
                {"potential_ks", {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14}},
                {"random_task_ratio", label == "Covar-GMM/rnd20" ? 0.2 : 0.1}};
  } else if (name == "Self-Paced") {
    // One step per episode here, so the step schedule is in episodes (reference: 50k / 200k
    // steps of 2000-step episodes); the rest are the benchmark values.
    s.params = {{"update_frequency", 100}, {"update_offset", 200},
                {"alpha_offset", 10},      {"zeta", 0.25},
                {"max_kl", 0.1},           {"use_avg_performance", true}};
  } else if (name == "GoalGAN") {
    s.params = {{"state_noise_level", 0.1}, {"p_old", 0.1}, {"use_pretrained_samples", true}};
  } else if (name == "Setter-Solver") {
    s.params = {
        {"update_frequency", 50}, {"setter_loss_noise_ub", 0.1}, {"setter_hidden_size", 64}};
  }
  return s;
}

std::pair<double, double> mean_std(const std::vector<double>& x) {
  double m = 0, v = 0;
  for (double e : x) m += e;
  m /= static_cast<double>(x.size());
  for (double e : x) v += (e - m) * (e - m);
  return {m, std::sqrt(v / static_cast<double>(x.size() - 1))};
}

void BM_SyntheticStudent(benchmark::State& state, std::string name) {
  const int episodes = static_cast<int>(state.range(0));
  std::vector<double> teacher, random;
  for (auto _ : state) {
    teacher.clear();
    random.clear();
    for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
      auto t = make_teacher(bench_setup(name, seed));
      teacher.push_back(run_synthetic_curriculum(*t, episodes, seed));
      auto r = make_teacher(bench_setup("Random", seed));
      random.push_back(run_synthetic_curriculum(*r, episodes, seed));
    }
  }
  const auto [tm, ts] = mean_std(teacher);
  const auto [rm, rs] = mean_std(random);
  state.counters["mastered%"] = tm;
  state.counters["std"] = ts;
  state.counters["random%"] = rm;
  state.counters["random_std"] = rs;
  state.counters["welch_t"] = welch_t(teacher, random);
}

// The teacher's own cost per episode (sample_task + hooks + episodic_update, fits included) over
// the first 3000 episodes of a synthetic student: what a real run pays per episode.
void BM_TeacherEpisode(benchmark::State& state, std::string name) {
  auto teacher = make_teacher(bench_setup(name, 1));
  SyntheticStudent student({}, 1);
  teacher->set_value_estimator([](const std::vector<std::vector<float>>& states) {
    return std::vector<float>(states.size(), 0.f);
  });
  const std::vector<float> no_action;
  for (auto _ : state) {
    const Task task = teacher->sample_task();
    teacher->record_initial_state(task, task);
    const auto [ret, success] = student.play(task);  // ~50 ns: left in the timing
    teacher->step_update(task, no_action, ret, task, true);
    teacher->episodic_update(task, ret, success);
  }
}
#define CRADLE_TEACH_EPISODE(label, name) \
  BENCHMARK_CAPTURE(BM_TeacherEpisode, label, std::string(name))->Iterations(3000)
CRADLE_TEACH_EPISODE(Random, "Random");
CRADLE_TEACH_EPISODE(ADR, "ADR");
CRADLE_TEACH_EPISODE(RIAC, "RIAC");
CRADLE_TEACH_EPISODE(ALP_GMM, "ALP-GMM");
CRADLE_TEACH_EPISODE(Covar_GMM, "Covar-GMM");
CRADLE_TEACH_EPISODE(Self_Paced, "Self-Paced");
CRADLE_TEACH_EPISODE(GoalGAN, "GoalGAN");
CRADLE_TEACH_EPISODE(Setter_Solver, "Setter-Solver");

// Iterations(1): one run is 16 seeds x (teacher + Random).
#define CRADLE_TEACH_BENCH(label, name)                            \
  BENCHMARK_CAPTURE(BM_SyntheticStudent, label, std::string(name)) \
      ->Arg(10000)                                                 \
      ->Iterations(1)                                              \
      ->Unit(benchmark::kSecond)
CRADLE_TEACH_BENCH(Random, "Random");
CRADLE_TEACH_BENCH(ADR, "ADR");
CRADLE_TEACH_BENCH(RIAC, "RIAC");
CRADLE_TEACH_BENCH(ALP_GMM, "ALP-GMM");
CRADLE_TEACH_BENCH(Covar_GMM, "Covar-GMM");
CRADLE_TEACH_BENCH(Covar_GMM_rnd20, "Covar-GMM/rnd20");
CRADLE_TEACH_BENCH(Self_Paced, "Self-Paced");
CRADLE_TEACH_BENCH(GoalGAN, "GoalGAN");
CRADLE_TEACH_BENCH(Setter_Solver, "Setter-Solver");

}  // namespace
}  // namespace cradle::teach
