// Self-touch and hand regard on scripted poses: MIMo's joints are set kinematically (coordinate
// search over one arm's angles) until a hand reaches its target, then the behaviour is measured.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "envs/babybench.h"
#include "envs/hand_regard.h"
#include "envs/self_touch.h"
#include "scene/compose.h"
#include "scene/summary.h"

namespace cradle::envs {
namespace {

scene::ModelPtr compile(Behavior behavior, SceneKind kind) {
  Config c;
  c.behavior = behavior;
  c.scene = kind;
  return scene::compile_scene(scene::compose_scene(c));
}

int body(const mjModel* m, const char* name) { return mj_name2id(m, mjOBJ_BODY, name); }

// Minimises cost(d) over the given joints' angles within their ranges by coordinate search.
void search(const mjModel* m, mjData* d, const std::vector<std::string>& joints,
            const std::function<double(const mjData*)>& cost) {
  mj_kinematics(m, d);
  double best = cost(d);
  for (double step = 0.5; step > 0.002; step *= 0.6) {
    for (int round = 0; round < 4; ++round) {
      for (const std::string& j : joints) {
        const int id = mj_name2id(m, mjOBJ_JOINT, ("robot:" + j).c_str());
        const int adr = m->jnt_qposadr[id];
        for (double delta : {step, -step}) {
          const double old = d->qpos[adr];
          d->qpos[adr] = std::clamp(old + delta, m->jnt_range[2 * id], m->jnt_range[2 * id + 1]);
          mj_kinematics(m, d);
          const double c = cost(d);
          if (c < best) {
            best = c;
          } else {
            d->qpos[adr] = old;
          }
        }
      }
    }
  }
  mj_forward(m, d);
}

double distance(const mjtNum* a, const mjtNum* b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

std::vector<std::string> arm(const std::string& side) {
  return {side + "_shoulder_horizontal",
          side + "_shoulder_ad_ab",
          side + "_shoulder_rotation",
          side + "_elbow",
          side + "_hand1",
          side + "_hand2",
          side + "_hand3"};
}

// An info list or number by key (the key must be declared).
std::vector<int> list(const Info& info, const char* key) {
  const int k = info.find(key);
  EXPECT_GE(k, 0) << key;
  return k < 0 ? std::vector<int>{} : std::vector<int>(info.list(k).begin(), info.list(k).end());
}
double value(const Info& info, const char* key) {
  const int k = info.find(key);
  EXPECT_GE(k, 0) << key;
  return k < 0 ? -1 : info.number(k);
}

bool contains(const std::vector<int>& list, int value) {
  return std::find(list.begin(), list.end(), value) != list.end();
}

TEST(SelfTouch, LeftHandOnRightForearmIsRecordedByTheLeftHand) {
  const auto m = compile(Behavior::kSelfTouch, SceneKind::kBase);
  mjData* d = mj_makeData(m.get());
  const int forearm_geom = m->body_geomadr[body(m.get(), "right_lower_arm")];
  const int palm = m->body_geomadr[body(m.get(), "left_hand")];
  // Press the left palm into the right forearm (its centre a little inside the capsule surface).
  search(m.get(), d, arm("left"), [&](const mjData* x) {
    return std::abs(distance(x->geom_xpos + 3 * palm, x->geom_xpos + 3 * forearm_geom) - 0.025);
  });
  SelfTouch task(m.get());
  Info info;
  task.declare(info);
  task.reset(m.get(), d, info);
  task.after_step(m.get(), d, info);
  EXPECT_TRUE(contains(list(info, "left_hand_touches"), forearm_geom)) << "ncon " << d->ncon;
  EXPECT_FALSE(contains(list(info, "right_hand_touches"), forearm_geom));
  // Lists hold unique ids in order of first contact: a second step adds nothing new.
  const std::vector<int> before = list(info, "left_hand_touches");
  task.after_step(m.get(), d, info);
  EXPECT_EQ(list(info, "left_hand_touches"), before);
  mj_deleteData(d);
}

TEST(SelfTouch, HandOnHandIsRecordedByBothAndOwnGeomsNever) {
  const auto m = compile(Behavior::kSelfTouch, SceneKind::kBase);
  mjData* d = mj_makeData(m.get());
  const int right_palm = m->body_geomadr[body(m.get(), "right_hand")];
  const int left_palm = m->body_geomadr[body(m.get(), "left_hand")];
  // Bring both palms together: move the right arm, then the left arm, towards each other.
  auto gap = [&](const mjData* x) {
    return std::abs(distance(x->geom_xpos + 3 * right_palm, x->geom_xpos + 3 * left_palm) - 0.015);
  };
  search(m.get(), d, arm("right"), gap);
  search(m.get(), d, arm("left"), gap);
  search(m.get(), d, arm("right"), gap);
  ASSERT_LT(distance(d->geom_xpos + 3 * right_palm, d->geom_xpos + 3 * left_palm), 0.02);
  SelfTouch task(m.get());
  Info info;
  task.declare(info);
  task.reset(m.get(), d, info);
  task.after_step(m.get(), d, info);
  ASSERT_FALSE(list(info, "right_hand_touches").empty()) << "ncon " << d->ncon;
  ASSERT_FALSE(list(info, "left_hand_touches").empty());
  // Each hand records a geom of the other hand: symmetric, unlike the reference.
  const auto& right_geoms = task.hand_geoms(0);
  const auto& left_geoms = task.hand_geoms(1);
  auto any_of = [](const std::vector<int>& list, const std::vector<int>& geoms) {
    return std::any_of(list.begin(), list.end(), [&](int g) { return contains(geoms, g); });
  };
  EXPECT_TRUE(any_of(list(info, "right_hand_touches"), left_geoms));
  EXPECT_TRUE(any_of(list(info, "left_hand_touches"), right_geoms));
  // A hand never records its own palm or fingers.
  EXPECT_FALSE(any_of(list(info, "right_hand_touches"), right_geoms));
  EXPECT_FALSE(any_of(list(info, "left_hand_touches"), left_geoms));
  mj_deleteData(d);
}

// The hand is the hand body and its fingers: 4 geoms in v1 (palm box, cylinder, mitten box and
// cylinder) and the palm plus every finger segment in v2.
TEST(SelfTouch, HandsIncludeTheirFingers) {
  const auto v1 = compile(Behavior::kSelfTouch, SceneKind::kBase);
  SelfTouch t1(v1.get());
  EXPECT_EQ(t1.hand_geoms(0).size(), 4u);
  EXPECT_EQ(t1.hand_geoms(1).size(), 4u);
  EXPECT_EQ(t1.mimo_geoms().size(), 36u);
  const auto v2 = compile(Behavior::kHandRegard, SceneKind::kBase);
  SelfTouch t2(v2.get());
  EXPECT_EQ(t2.hand_geoms(0).size(), 4u + 17u);  // palm + 3+3+3 (ff, mf, rf) + 5 (lf) + 3 (th)
  EXPECT_EQ(t2.mimo_geoms().size(), 74u);
}

TEST(HandRegard, HandInFrontOfTheEyeCountsBehindTheHeadDoesNot) {
  const auto m = compile(Behavior::kHandRegard, SceneKind::kCubes);
  mjData* d = mj_makeData(m.get());
  HandRegard task(m.get(), 15, false);
  const int cam = mj_name2id(m.get(), mjOBJ_CAMERA, "eye_right");
  // Right palm 12 cm in front of the right eye, on its optical axis.
  search(m.get(), d, arm("right"), [&](const mjData* x) {
    mj_camlight(m.get(), const_cast<mjData*>(x));
    const mjtNum* p = x->cam_xpos + 3 * cam;
    const mjtNum* r = x->cam_xmat + 9 * cam;
    const mjtNum target[3] = {p[0] - 0.12 * r[2], p[1] - 0.12 * r[5], p[2] - 0.12 * r[8]};
    const auto palm = task.palm_centre(x, 0);
    return distance(palm.data(), target);
  });
  EXPECT_LT(task.gaze_angle(d, 0, 0), 15);
  Info info;
  task.declare(info);
  task.reset(m.get(), d, info);
  task.after_step(m.get(), d, info);
  EXPECT_EQ(value(info, "right_eye_right_hand"), 1);  // right eye, right hand
  EXPECT_EQ(value(info, "right_eye_either_hand"), 1);

  // The same hand behind the head.
  search(m.get(), d, arm("right"), [&](const mjData* x) {
    const mjtNum* head = x->xpos + 3 * body(m.get(), "head");
    const mjtNum* rot = x->xmat + 9 * body(m.get(), "head");
    const mjtNum target[3] = {head[0] - 0.12 * rot[0], head[1] - 0.12 * rot[3],
                              head[2] + 0.08 - 0.12 * rot[6]};
    const auto palm = task.palm_centre(x, 0);
    return distance(palm.data(), target);
  });
  EXPECT_GT(task.gaze_angle(d, 0, 0), 90);
  task.after_step(m.get(), d, info);
  EXPECT_EQ(value(info, "right_eye_right_hand"), 1);  // unchanged
  mj_deleteData(d);
}

TEST(HandRegard, OccludedHandNotCountedWithOcclusionOn) {
  const auto m = compile(Behavior::kHandRegard, SceneKind::kCubes);
  mjData* d = mj_makeData(m.get());
  HandRegard plain(m.get(), 15, false), occluding(m.get(), 15, true);
  const int cam = mj_name2id(m.get(), mjOBJ_CAMERA, "eye_right");
  search(m.get(), d, arm("right"), [&](const mjData* x) {
    mj_camlight(m.get(), const_cast<mjData*>(x));
    const mjtNum* p = x->cam_xpos + 3 * cam;
    const mjtNum* r = x->cam_xmat + 9 * cam;
    const mjtNum target[3] = {p[0] - 0.15 * r[2], p[1] - 0.15 * r[5], p[2] - 0.15 * r[8]};
    const auto palm = plain.palm_centre(x, 0);
    return distance(palm.data(), target);
  });
  ASSERT_LT(plain.gaze_angle(d, 0, 0), 15);
  EXPECT_TRUE(occluding.visible(m.get(), d, 0, 0));

  // Move a toy (the blue cube) onto the line of sight, halfway between the eye and the palm.
  const int toy = body(m.get(), "blue_cube");
  const int adr = m->jnt_qposadr[m->body_jntadr[toy]];
  const mjtNum* eye = d->cam_xpos + 3 * cam;
  const auto palm = plain.palm_centre(d, 0);
  for (int k = 0; k < 3; ++k) d->qpos[adr + k] = 0.5 * (eye[k] + palm[k]);
  mj_forward(m.get(), d);
  EXPECT_FALSE(occluding.visible(m.get(), d, 0, 0));
  Info a, b;
  plain.declare(a);
  occluding.declare(b);
  plain.reset(m.get(), d, a);
  occluding.reset(m.get(), d, b);
  plain.after_step(m.get(), d, a);
  occluding.after_step(m.get(), d, b);
  EXPECT_EQ(value(a, "right_eye_right_hand"), 1);
  EXPECT_EQ(value(b, "right_eye_right_hand"), 0);
  mj_deleteData(d);
}

// The tasks' evaluation panels: what eval/ draws for each without knowing the task.
TEST(EvaluationPanels, SelfTouchShowsTheSkinMapAndItsTouchLists) {
  const auto m = compile(Behavior::kSelfTouch, SceneKind::kBase);
  SelfTouch task(m.get());
  const EvaluationPanels panels = task.evaluation_panels();
  EXPECT_EQ(panels.up, EvaluationPanels::View::kTouches);
  EXPECT_EQ(panels.down, EvaluationPanels::View::kTop);
  EXPECT_EQ(panels.hand_geoms[0], task.hand_geoms(0));
  EXPECT_EQ(panels.hand_geoms[1], task.hand_geoms(1));
  EXPECT_EQ(panels.mimo_geoms, task.mimo_geoms());
  ASSERT_TRUE(panels.geom_lists);
  // The listed keys are the ones the task declares, and the union is scored out of 68.
  Info info;
  task.declare(info);
  for (const std::string& key : panels.geom_lists->keys) EXPECT_GE(info.find(key), 0) << key;
  EXPECT_EQ(panels.geom_lists->labels.size(), panels.geom_lists->keys.size());
  EXPECT_EQ(panels.geom_lists->union_denominator, 68);
  EXPECT_FALSE(panels.trace);
}

TEST(EvaluationPanels, HandRegardTracesTheFourGazeAnglesAgainstItsHalfAngle) {
  const auto m = compile(Behavior::kHandRegard, SceneKind::kCubes);
  mjData* d = mj_makeData(m.get());
  mj_forward(m.get(), d);
  HandRegard task(m.get(), 12.5, false);
  const EvaluationPanels panels = task.evaluation_panels();
  EXPECT_EQ(panels.up, EvaluationPanels::View::kBinocular);
  EXPECT_FALSE(panels.geom_lists);
  ASSERT_TRUE(panels.trace);
  ASSERT_EQ(panels.trace->labels.size(), 4u);
  ASSERT_TRUE(panels.trace->threshold);
  EXPECT_EQ(panels.trace->threshold->first, 12.5);
  std::vector<double> values(4);
  task.trace(d, values);
  // Eye-major, as the labels: right eye (right, left hand), then left eye.
  for (int eye = 0; eye < 2; ++eye) {
    for (int hand = 0; hand < 2; ++hand) {
      EXPECT_EQ(values[2 * eye + hand], task.gaze_angle(d, eye, hand));
      EXPECT_GE(values[2 * eye + hand], 0);
      EXPECT_LE(values[2 * eye + hand], 180);
    }
  }
  mj_deleteData(d);
}

}  // namespace
}  // namespace cradle::envs
