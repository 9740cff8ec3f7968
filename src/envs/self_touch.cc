#include "envs/self_touch.h"

#include <string_view>

#include "scene/summary.h"

namespace cradle::envs {
namespace {

// The hand body itself and every body below it (fingers).
std::vector<int> hand_bodies(const mjModel* m, const char* hand) {
  return scene::subtree_bodies(m, hand);
}

}  // namespace

SelfTouch::SelfTouch(const mjModel* m) : hand_of_geom_(m->ngeom, -1), is_mimo_(m->ngeom, 0) {
  for (int body : scene::subtree_bodies(m, "hip")) {
    for (int g = m->body_geomadr[body]; g < m->body_geomadr[body] + m->body_geomnum[body]; ++g) {
      is_mimo_[g] = 1;
    }
  }
  for (int g = 0; g < m->ngeom; ++g) {
    if (is_mimo_[g]) mimo_geoms_.push_back(g);
  }
  const char* hands[2] = {"right_hand", "left_hand"};
  for (int h = 0; h < 2; ++h) {
    for (int body : hand_bodies(m, hands[h])) {
      for (int g = m->body_geomadr[body]; g < m->body_geomadr[body] + m->body_geomnum[body]; ++g) {
        hand_of_geom_[g] = h;
        hand_geoms_[h].push_back(g);
      }
    }
    seen_[h].assign(m->ngeom, 0);
  }
}

void SelfTouch::declare(Info& info) {
  slot_[0] = info.declare("right_hand_touches", InfoType::kIntList);
  slot_[1] = info.declare("left_hand_touches", InfoType::kIntList);
}

void SelfTouch::reset(const mjModel* m, const mjData*, Info& info) {
  for (int h = 0; h < 2; ++h) {
    seen_[h].assign(m->ngeom, 0);
    // Capacity for every geom, so recording never allocates during an episode.
    info.list(slot_[h]).clear();
    info.list(slot_[h]).reserve(m->ngeom);
  }
}

double SelfTouch::score(const Info& info, int) const {
  return static_cast<double>(info.list(slot_[0]).size() + info.list(slot_[1]).size()) /
         (2 * kReferenceGeomsPerHand);
}

EvaluationPanels SelfTouch::evaluation_panels() const {
  return {.up = EvaluationPanels::View::kTouches,
          .hand_geoms = {hand_geoms_[0], hand_geoms_[1]},
          .mimo_geoms = mimo_geoms_,
          .geom_lists =
              EvaluationPanels::GeomLists{.keys = {"right_hand_touches", "left_hand_touches"},
                                          .labels = {"right hand", "left hand"},
                                          .title = "Self-touch coverage per body part (evaluation)",
                                          .union_label = "union of touches so far",
                                          .file = "touch_coverage.png",
                                          .union_denominator = 2 * kReferenceGeomsPerHand}};
}

void SelfTouch::record(int hand, int other, Info& info) {
  // Only MIMo's own geoms count, never the hand's own (palm and fingers).
  if (!is_mimo_[other] || hand_of_geom_[other] == hand || seen_[hand][other]) return;
  seen_[hand][other] = 1;
  info.list(slot_[hand]).push_back(other);
}

double SelfTouch::after_step(const mjModel*, const mjData* d, Info& info) {
  for (int i = 0; i < d->ncon; ++i) {
    const int g1 = d->contact[i].geom1;
    const int g2 = d->contact[i].geom2;
    // Each side of the contact is tested for each hand, so both hands record symmetrically.
    if (hand_of_geom_[g1] >= 0) record(hand_of_geom_[g1], g2, info);
    if (hand_of_geom_[g2] >= 0) record(hand_of_geom_[g2], g1, info);
  }
  return 0;
}

HandContacts::HandContacts(const mjModel* m) : rule_(m) {
  for (auto& marked : marked_) marked.assign(m->ngeom, 0);
}

void HandContacts::declare(Info& info) {
  slot_[0] = info.declare("right_hand_contacts", InfoType::kIntList, /*published=*/false);
  slot_[1] = info.declare("left_hand_contacts", InfoType::kIntList, /*published=*/false);
}

void HandContacts::update(const mjData* d, Info& info) {
  for (int h = 0; h < 2; ++h) {
    info.list(slot_[h]).clear();
    info.list(slot_[h]).reserve(marked_[h].size());
  }
  auto touch = [&](int hand_geom, int other) {
    const int hand = rule_.touching_hand(hand_geom, other);
    if (hand < 0 || marked_[hand][other]) return;
    marked_[hand][other] = 1;
    info.list(slot_[hand]).push_back(other);
  };
  for (int c = 0; c < d->ncon; ++c) {
    touch(d->contact[c].geom1, d->contact[c].geom2);
    touch(d->contact[c].geom2, d->contact[c].geom1);
  }
  // The marks only dedupe within this step.
  for (int h = 0; h < 2; ++h) {
    for (int g : info.list(slot_[h])) marked_[h][g] = 0;
  }
}

std::string geom_label(const mjModel* m, int geom) {
  const int body = m->geom_bodyid[geom];
  const char* body_name = mj_id2name(m, mjOBJ_BODY, body);
  std::string label(body_name ? body_name : "world");
  if (const char* name = mj_id2name(m, mjOBJ_GEOM, geom)) {
    label.append("/").append(name);
  } else if (m->body_geomnum[body] > 1) {
    label.append("#").append(std::to_string(geom - m->body_geomadr[body]));
  }
  return label;
}

}  // namespace cradle::envs
