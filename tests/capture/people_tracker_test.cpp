// people_tracker: the ids and the detector schedule of a several-people capture, on made-up
// detections and bodies (no models). Each test breaks one part of the rule
// (people_tracker.hpp).
#include "avatarmap/capture/people_tracker.hpp"

#include <gtest/gtest.h>

#include <array>

namespace avatarmap {
namespace {

constexpr int W = 1000, H = 1000;

// A standing person centred at (x, y) (normalised), torso 0.2 high: its detector region and
// anchors (hip centre, shoulder centre), and its 33 landmarks with the key points set.
struct person {
  float x, y, size = 0.6f;
  normalized_rect region() const { return {x, y, size, size, 0.f}; }
  void anchors(float* a) const {
    a[0] = x;
    a[1] = y + 0.1f;
    a[2] = x;
    a[3] = y - 0.1f;
  }
  std::array<landmark, k_pose_landmark_count> pose() const {
    std::array<landmark, k_pose_landmark_count> p{};
    for (landmark& l : p) l = {x, y, 0, 1, 1};
    p[0] = {x, y - 0.2f, 0, 1, 1};
    p[11] = {x + 0.05f, y - 0.1f, 0, 1, 1};
    p[12] = {x - 0.05f, y - 0.1f, 0, 1, 1};
    p[23] = {x + 0.03f, y + 0.1f, 0, 1, 1};
    p[24] = {x - 0.03f, y + 0.1f, 0, 1, 1};
    return p;
  }
};

void detect(people_tracker& tr, double t, std::initializer_list<person> people) {
  std::array<normalized_rect, k_max_people> r;
  std::array<float, 4 * k_max_people> a;
  int n = 0;
  for (const person& p : people) {
    r[n] = p.region();
    p.anchors(&a[4 * n]);
    ++n;
  }
  tr.on_detections(t, r.data(), a.data(), n, W, H);
}

// Reports every active track found at the given people (matched by slot order of `where`).
void found(people_tracker& tr, double t, int slot, const person& p) {
  const auto pose = p.pose();
  tr.on_found(slot, t, p.region(), p.region(), pose.data(), W, H);
}

int slot_of(const people_tracker& tr, int id) {
  for (int i = 0; i < tr.active_count(); ++i)
    if (tr.active(i).id == id) return tr.active(i).slot;
  return -1;
}

TEST(people_tracker, ids_largest_first_and_at_most_max_people) {
  people_tracker_options o;
  o.max_people = 2;
  people_tracker tr(o);
  EXPECT_TRUE(tr.wants_detection(0.0));
  person small{0.2f, 0.5f, 0.3f}, big{0.8f, 0.5f, 0.7f}, mid{0.5f, 0.5f, 0.5f};
  detect(tr, 0.0, {small, big, mid});
  ASSERT_EQ(tr.active_count(), 2);  // three in view, two asked
  EXPECT_EQ(tr.active(0).id, 0);
  EXPECT_FLOAT_EQ(tr.active(0).start_region.width, 0.7f);  // the largest is person 0
  EXPECT_EQ(tr.active(1).id, 1);
  EXPECT_FLOAT_EQ(tr.active(1).start_region.width, 0.5f);
  EXPECT_TRUE(tr.active(0).is_new && tr.active(1).is_new);
  found(tr, 0.0, tr.active(0).slot, big);
  found(tr, 0.0, tr.active(1).slot, mid);
  EXPECT_FALSE(tr.active(0).is_new);
  // Two tracked of two: no detector.
  EXPECT_FALSE(tr.wants_detection(0.1));
  EXPECT_FALSE(tr.wants_detection(5.0));
}

TEST(people_tracker, a_box_on_a_tracked_person_is_that_person) {
  people_tracker_options o;
  o.max_people = 3;
  people_tracker tr(o);
  person a{0.3f, 0.5f}, b{0.7f, 0.5f};
  detect(tr, 0.0, {a});
  ASSERT_EQ(tr.active_count(), 1);
  found(tr, 0.0, tr.active(0).slot, a);
  EXPECT_FALSE(tr.wants_detection(0.05));  // the schedule: every 0.1 s while fewer than 3
  EXPECT_TRUE(tr.wants_detection(o.redetect_seconds));
  // The detector again: a (moved a little, its region much larger) and a newcomer b.
  person a2{0.32f, 0.5f, 1.5f};
  detect(tr, 0.5, {a2, b});
  ASSERT_EQ(tr.active_count(), 2);
  EXPECT_FALSE(tr.active(0).is_new);  // a kept its id and its track
  EXPECT_EQ(tr.active(0).id, 0);
  EXPECT_TRUE(tr.active(1).is_new);
  EXPECT_EQ(tr.active(1).id, 1);
}

TEST(people_tracker, a_lost_id_comes_back_within_a_second_where_its_motion_leads) {
  people_tracker tr;  // max 2
  person a{0.3f, 0.5f}, b{0.7f, 0.5f};
  detect(tr, 0.0, {a, b});
  const int sa = slot_of(tr, 0), sb = slot_of(tr, 1);
  // a walks right 0.1 image widths per second.
  for (int k = 0; k <= 5; ++k) {
    person m{0.3f + 0.01f * k, 0.5f};
    found(tr, 0.1 * k, sa, m);
    found(tr, 0.1 * k, sb, b);
  }
  tr.on_lost(sa, 0.6);
  EXPECT_TRUE(tr.wants_detection(0.7));  // a track was lost
  // 0.5 s later a box where a's motion leads (0.35 + 0.05): id 0 again, not 2.
  person back{0.40f, 0.5f};
  detect(tr, 1.1, {back});
  ASSERT_EQ(tr.active_count(), 2);
  EXPECT_EQ(tr.active(0).id, 0);
  EXPECT_TRUE(tr.active(0).is_new);
  found(tr, 1.1, tr.active(0).slot, back);
  // Lost for longer than keep_lost_seconds: a new id.
  tr.on_lost(slot_of(tr, 0), 1.2);
  detect(tr, 2.5, {back});
  EXPECT_EQ(tr.active(0).id, 1);
  EXPECT_EQ(tr.active(1).id, 2);
}

TEST(people_tracker, two_tracks_on_one_body_keep_the_older_id) {
  people_tracker tr;
  person a{0.3f, 0.5f}, b{0.7f, 0.5f};
  detect(tr, 0.0, {a, b});
  found(tr, 0.0, slot_of(tr, 0), a);
  found(tr, 0.0, slot_of(tr, 1), b);
  std::array<int, k_max_people> dropped{};
  EXPECT_EQ(tr.resolve_merges(0.0, dropped.data()), 0);
  // Track 1 drifts onto a's body.
  const int s1 = slot_of(tr, 1);
  found(tr, 0.1, slot_of(tr, 0), a);
  found(tr, 0.1, s1, person{0.305f, 0.5f});
  ASSERT_EQ(tr.resolve_merges(0.1, dropped.data()), 1);
  EXPECT_EQ(dropped[0], s1);
  ASSERT_EQ(tr.active_count(), 1);
  EXPECT_EQ(tr.active(0).id, 0);
  EXPECT_TRUE(tr.wants_detection(0.2));
}

// The older track's person is hidden behind the younger one, and its track creeps onto the
// body in front (a quarter torso length a frame: too slow for the slide rule below): the track
// that jumped ends, whatever its id, and its id comes back where its person was when a box
// appears there within a second (keeping the lower id would give the person in front the
// hidden one's id).
TEST(people_tracker, the_track_that_jumped_onto_a_body_ends_and_waits_where_it_was) {
  people_tracker tr;
  person a{0.3f, 0.5f}, b{0.5f, 0.5f};
  detect(tr, 0.0, {a, b});
  const int s0 = slot_of(tr, 0), s1 = slot_of(tr, 1);
  ASSERT_EQ(tr.active(0).id, 0);
  for (int k = 0; k <= 3; ++k) {
    found(tr, 0.1 * k, s0, a);
    found(tr, 0.1 * k, s1, b);
  }
  std::array<int, k_max_people> dropped{};
  EXPECT_EQ(tr.resolve_merges(0.3, dropped.data()), 0);
  // a's track creeps onto b, who stands still: 0.05 of the image (50 px, a quarter torso)
  // each 0.1 s.
  for (int k = 1; k <= 3; ++k) {
    found(tr, 0.3 + 0.1 * k, s0, person{0.3f + 0.05f * k, 0.5f});
    found(tr, 0.3 + 0.1 * k, s1, b);
    EXPECT_EQ(tr.resolve_merges(0.3 + 0.1 * k, dropped.data()), 0) << "step " << k;
  }
  found(tr, 0.7, s0, b);
  found(tr, 0.7, s1, b);
  ASSERT_EQ(tr.resolve_merges(0.7, dropped.data()), 1);
  EXPECT_EQ(dropped[0], s0);
  ASSERT_EQ(tr.active_count(), 1);
  EXPECT_EQ(tr.active(0).id, 1) << "the person in front keeps its own id";
  // a comes out where it was: id 0 again.
  found(tr, 0.9, s1, b);
  detect(tr, 0.9, {a});
  ASSERT_EQ(tr.active_count(), 2);
  EXPECT_EQ(tr.active(0).id, 0);
  EXPECT_TRUE(tr.active(0).is_new);
}

// A hidden person's track slides in one frame onto the person crossing in front (the model
// follows the body it sees; cross.mp4 of tools/eval/people.sh at 5.8 s): it ends on that frame,
// before its skeleton spanning both people is given out, and its id comes back where its
// person was.
TEST(people_tracker, a_track_that_slides_onto_another_person_in_one_frame_ends_at_once) {
  people_tracker tr;
  person a{0.3f, 0.5f}, b{0.6f, 0.5f};
  detect(tr, 0.0, {a, b});
  const int s0 = slot_of(tr, 0), s1 = slot_of(tr, 1);
  for (int k = 0; k <= 10; ++k) {
    found(tr, 0.04 * k, s0, a);
    found(tr, 0.04 * k, s1, b);
  }
  std::array<int, k_max_people> dropped{};
  EXPECT_EQ(tr.resolve_merges(0.4, dropped.data()), 0);
  // 0.44 s: a's track moves 0.15 of the image (0.75 torso lengths, 19 a second) toward b.
  found(tr, 0.44, s0, person{0.45f, 0.5f});
  found(tr, 0.44, s1, b);
  ASSERT_EQ(tr.resolve_merges(0.44, dropped.data()), 1);
  EXPECT_EQ(dropped[0], s0);
  ASSERT_EQ(tr.active_count(), 1);
  EXPECT_EQ(tr.active(0).id, 1);
  EXPECT_TRUE(tr.wants_detection(0.48));
  detect(tr, 0.8, {a});
  ASSERT_EQ(tr.active_count(), 2);
  EXPECT_EQ(tr.active(0).id, 0) << "the hidden person's id comes back where it was";
}

// The same fast move is no slide when it does not bring the track toward anybody: a person
// alone, or one moving away from the other.
TEST(people_tracker, a_fast_move_away_from_everybody_is_no_slide) {
  std::array<int, k_max_people> dropped{};
  {
    people_tracker tr;
    const person a{0.3f, 0.5f};
    detect(tr, 0.0, {a});
    found(tr, 0.0, slot_of(tr, 0), a);
    found(tr, 0.04, slot_of(tr, 0), person{0.45f, 0.5f});
    EXPECT_EQ(tr.resolve_merges(0.04, dropped.data()), 0);
    EXPECT_EQ(tr.active_count(), 1);
  }
  people_tracker tr;
  person a{0.3f, 0.5f}, b{0.6f, 0.5f};
  detect(tr, 0.0, {a, b});
  const int s0 = slot_of(tr, 0), s1 = slot_of(tr, 1);
  found(tr, 0.0, s0, a);
  found(tr, 0.0, s1, b);
  found(tr, 0.04, s0, person{0.15f, 0.5f});  // away from b
  found(tr, 0.04, s1, b);
  EXPECT_EQ(tr.resolve_merges(0.04, dropped.data()), 0);
  // Toward b, but at 2.5 torso lengths a second (a person walking): no slide either.
  found(tr, 0.14, s0, person{0.2f, 0.5f});
  found(tr, 0.14, s1, b);
  EXPECT_EQ(tr.resolve_merges(0.14, dropped.data()), 0);
  EXPECT_EQ(tr.active_count(), 2);
}

// While a lost id waits, the detector looks on every frame (the person may come out from
// behind someone), not every redetect_seconds; once the id is given up it goes back to its
// schedule.
TEST(people_tracker, the_detector_looks_on_every_frame_while_a_lost_id_waits) {
  people_tracker tr;  // max 2
  person a{0.3f, 0.5f}, b{0.7f, 0.5f};
  detect(tr, 0.0, {a, b});
  const int sa = slot_of(tr, 0), sb = slot_of(tr, 1);
  for (int k = 0; k <= 5; ++k) {
    found(tr, 0.1 * k, sa, a);
    found(tr, 0.1 * k, sb, b);
  }
  EXPECT_FALSE(tr.wants_detection(0.55));  // two of two tracked: never
  tr.on_lost(sa, 0.6);                     // a was last seen at 0.5 s
  EXPECT_TRUE(tr.wants_detection(0.6));
  detect(tr, 0.6, {b});
  EXPECT_TRUE(tr.wants_detection(0.62));
  detect(tr, 1.45, {b});
  EXPECT_TRUE(tr.wants_detection(1.47));  // 0.97 s since a was seen
  detect(tr, 1.55, {b});
  EXPECT_FALSE(tr.wants_detection(1.57));  // given up: the 0.1 s schedule again
  EXPECT_TRUE(tr.wants_detection(1.66));
}

TEST(people_tracker, reset_starts_ids_again) {
  people_tracker tr;
  detect(tr, 0.0, {person{0.5f, 0.5f}});
  EXPECT_EQ(tr.active(0).id, 0);
  tr.reset();
  EXPECT_EQ(tr.active_count(), 0);
  detect(tr, 0.0, {person{0.5f, 0.5f}});
  EXPECT_EQ(tr.active(0).id, 0);
}

}  // namespace
}  // namespace avatarmap
