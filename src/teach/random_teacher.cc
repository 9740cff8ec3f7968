// Random teacher: uniform tasks in the box, learns nothing (the baseline of every ACL comparison).
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

class RandomTeacher final : public Teacher {
 public:
  using Teacher::Teacher;
  Task sample_task() override { return uniform_task(); }
  void episodic_update(const Task& task, double ret, bool) override { check_episode(task, ret); }
  const char* name() const override { return "random"; }
};

}  // namespace

std::unique_ptr<Teacher> make_random_teacher(std::vector<float> mins, std::vector<float> maxs,
                                             std::uint64_t seed) {
  return std::make_unique<RandomTeacher>(std::move(mins), std::move(maxs), seed);
}

}  // namespace cradle::teach
