// Several people through capture_pipeline and live_session (issue 25), driven by the "replay"
// backend on a version-2 recording (one line per person and frame): each person must come out
// exactly as the same pipeline gives that person's lines alone, in a slot that is the person's
// for as long as its id lives, and the live session must hand every held person to its outputs
// with its id and slot.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/live/live_session.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

constexpr double k_fps = 30.0;
constexpr int k_frames = 120;  // 4 s

// Who is in view at frame i: person 0 throughout; person 1 for the first 1.5 s; person 2 from
// 3 s on (person 1 has then been gone for 1.5 s, longer than k_person_hold_seconds).
bool in_view(int person, int i) {
  const double t = i / k_fps;
  if (person == 0) return true;
  if (person == 1) return t < 1.5;
  return t >= 3.0;
}

// Each person's own motion: the demo motion at its own phase, on a body of its own place.
landmark_frame person_frame(landmark_synth& synth, int person, int i) {
  landmark_frame f;
  const double t = i / k_fps;
  synth.generate(demo_motion_pose(t + 1.7 * person, synth.skeleton()), f);
  f.t = t;
  f.person = person;
  return f;
}

struct recordings {
  std::string together;              // version 2: every person's lines, by frame and id
  std::array<std::string, 3> alone;  // version 1: each person's lines on their own
};

recordings write_recordings(const test::temp_dir& dir) {
  recordings r;
  r.together = dir.file("people.landmarks.jsonl");
  synth_options o;
  o.body_noise_sigma = o.hand_noise_sigma = o.face_noise_sigma = 0.002f;
  std::array<landmark_synth, 3> synth{landmark_synth(o), landmark_synth(o), landmark_synth(o)};
  landmark_writer together;
  landmark_file_header h2;
  h2.version = 2;
  EXPECT_TRUE(together.open(r.together, h2).ok());
  std::array<landmark_writer, 3> alone;
  for (int p = 0; p < 3; ++p) {
    r.alone[p] = dir.file("alone" + std::to_string(p) + ".landmarks.jsonl");
    EXPECT_TRUE(alone[p].open(r.alone[p], {}).ok());
  }
  for (int i = 0; i < k_frames; ++i)
    for (int p = 0; p < 3; ++p) {
      if (!in_view(p, i)) continue;
      const landmark_frame f = person_frame(synth[p], p, i);
      EXPECT_TRUE(together.write(f).ok());
      landmark_frame one = f;
      one.person = 0;
      EXPECT_TRUE(alone[p].write(one).ok());
    }
  EXPECT_TRUE(together.commit().ok());
  for (auto& w : alone) EXPECT_TRUE(w.commit().ok());
  return r;
}

capture_pipeline_options replay_options(const std::string& path, int people) {
  capture_pipeline_options o;
  o.backend = "replay";
  o.estimator.source = path;
  o.estimator.hands = o.estimator.face = true;
  o.estimator.max_people = people;
  return o;
}

float max_degrees(const proxy_pose& a, const proxy_pose& b) {
  float worst = 0.f;
  for (int k = 0; k < k_bone_count; ++k)
    worst = std::max(worst, angle_between(a.rotations[k], b.rotations[k]) * 180.f / k_pi);
  return worst;
}

TEST(capture_pipeline_people, each_person_as_alone_in_a_slot_kept_while_its_id_lives) {
  test::temp_dir dir("pipeline_people");
  const recordings rec = write_recordings(dir);
  std::unique_ptr<capture_pipeline> both;
  ASSERT_TRUE(capture_pipeline::create(replay_options(rec.together, 3), both).ok());
  ASSERT_EQ(both->max_people(), 3);
  std::array<std::unique_ptr<capture_pipeline>, 3> alone;
  for (int p = 0; p < 3; ++p)
    ASSERT_TRUE(capture_pipeline::create(replay_options(rec.alone[p], 1), alone[p]).ok());

  landmark_frame frame, one;
  people_poses people;
  proxy_pose want;
  std::map<int, glm::vec3> root_shift;  // id -> its hips minus its lines alone
  for (int i = 0; i < k_frames; ++i) {
    const double t = i / k_fps;
    ASSERT_TRUE(both->estimate(image_view{}, t, frame).ok()) << i;
    both->solve_people(frame, people);
    int expected = 0;
    for (int p = 0; p < 3; ++p) expected += in_view(p, i);
    ASSERT_EQ(people.count, expected) << "frame " << i;
    for (int k = 0; k < people.count; ++k) {
      const person_pose& got = people.people[k];
      ASSERT_TRUE(in_view(got.id, i)) << "frame " << i << " id " << got.id;
      if (k > 0) EXPECT_LT(people.people[k - 1].id, got.id);
      // The slots: person 0 in slot 0, person 1 in slot 1, and person 2, who comes after
      // person 1 has been gone for longer than the hold, takes the freed slot 1.
      EXPECT_EQ(got.slot, got.id == 0 ? 0 : 1) << "frame " << i << " id " << got.id;
      ASSERT_NE(got.frame, nullptr);
      EXPECT_EQ(got.frame->person, got.id);
      EXPECT_DOUBLE_EQ(got.pose.t, t);
      // The same pose as the person's lines alone (its stream started with it), but for
      // where its root is measured from: one origin for everyone, person 0's first place, so
      // a person's hips differ from its lines alone by a constant (0 for person 0).
      ASSERT_TRUE(alone[got.id]->process(image_view{}, t, one, want).ok());
      EXPECT_LT(max_degrees(got.pose, want), 1e-4f) << "frame " << i << " id " << got.id;
      const glm::vec3 shift = got.pose.hips_position - want.hips_position;
      EXPECT_NEAR(shift.y, 0.f, 1e-5f);
      auto [it, first] = root_shift.emplace(got.id, shift);
      if (!first) EXPECT_LT(glm::length(shift - it->second), 1e-4f) << "frame " << i;
      if (got.id == 0) EXPECT_LT(glm::length(shift), 1e-5f) << "frame " << i;
    }
    // Slot 1 is held by person 1 until 1 s after its last frame, then free until person 2
    // (the frame at exactly 1 s is left out: either is right within rounding).
    const double gone = t - 44 / k_fps;
    if (std::abs(gone - k_person_hold_seconds) < 1e-6) continue;
    if (gone < k_person_hold_seconds)
      EXPECT_EQ(both->slot_person(1), 1) << "frame " << i;
    else if (t < 3.0)
      EXPECT_EQ(both->slot_person(1), -1) << "frame " << i;
    else
      EXPECT_EQ(both->slot_person(1), 2) << "frame " << i;
    EXPECT_EQ(both->slot_person(2), -1);
  }
  // Persons 1 and 2 stand elsewhere than person 0 in the synthetic images (their own phase of
  // the motion): their roots are placed from person 0's origin, not their own.
  ASSERT_EQ(root_shift.size(), 3u);
  EXPECT_GT(glm::length(root_shift[1]) + glm::length(root_shift[2]), 1e-4f);
}

TEST(capture_pipeline_people, one_person_file_with_several_wanted_is_person_zero) {
  test::temp_dir dir("pipeline_people_one");
  const recordings rec = write_recordings(dir);
  std::unique_ptr<capture_pipeline> p, q;
  ASSERT_TRUE(capture_pipeline::create(replay_options(rec.alone[0], 2), p).ok());
  ASSERT_TRUE(capture_pipeline::create(replay_options(rec.alone[0], 1), q).ok());
  landmark_frame f, g;
  people_poses people, single;
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(p->estimate(image_view{}, i / k_fps, f).ok());
    ASSERT_TRUE(q->estimate(image_view{}, i / k_fps, g).ok());
    p->solve_people(f, people);
    q->solve_people(g, single);  // one person: the same call gives slot 0, id 0
    ASSERT_EQ(people.count, 1);
    ASSERT_EQ(single.count, 1);
    EXPECT_EQ(people.people[0].id, 0);
    EXPECT_EQ(single.people[0].slot, 0);
    EXPECT_LT(max_degrees(people.people[0].pose, single.people[0].pose), 1e-4f);
  }
}

// Waits (up to 10 s) until the worker has dealt with every pushed image.
void settle(const live_session& s) {
  for (int i = 0; i < 1000; ++i) {
    const live_session_stats st = s.stats();
    if (st.processed + st.dropped + st.failed >= st.pushed) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

TEST(live_session_people, outputs_and_samples_every_held_person_with_its_id_and_slot) {
  test::temp_dir dir("live_people");
  const recordings rec = write_recordings(dir);
  live_session_options o;
  o.pipeline = replay_options(rec.together, 3);
  o.output_fps = 200.0;
  std::mutex m;
  std::map<int, int> slot_of;      // id -> slot, as the outputs saw it
  std::map<int, long> outputs_of;  // id -> outputs
  o.outputs.push_back([&](const proxy_pose&, const live_output_report& r) {
    std::lock_guard<std::mutex> lock(m);
    auto it = slot_of.find(r.person);
    if (it == slot_of.end())
      slot_of[r.person] = r.slot;
    else
      EXPECT_EQ(it->second, r.slot) << "person " << r.person << " changed slot";
    ++outputs_of[r.person];
  });
  int frames_with_people = 0;
  o.on_frame = [&](const live_frame_report& r) {
    if (r.people != nullptr && r.people->count > 0) ++frames_with_people;
    return true;
  };
  std::unique_ptr<live_session> s;
  ASSERT_TRUE(live_session::create(o, s).ok());
  std::vector<std::uint8_t> px(4 * 4 * 3, 128);
  const image_view img{px.data(), 4, 4, 12, pixel_format::rgb8};
  // The first second: persons 0 and 1, every image waited for.
  for (int i = 0; i < 30; ++i) {
    ASSERT_TRUE(s->push(img, i / k_fps).ok());
    settle(*s);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // a few output ticks
  std::array<live_person, k_max_people> held;
  ASSERT_EQ(s->people(held.data(), k_max_people), 2);
  EXPECT_EQ(held[0].id, 0);
  EXPECT_EQ(held[1].id, 1);
  EXPECT_EQ(held[0].slot, 0);
  EXPECT_EQ(held[1].slot, 1);
  EXPECT_DOUBLE_EQ(held[1].seen_t, 29 / k_fps);
  // sample_person: each person's own stream; sample() the lowest id.
  proxy_pose a, b, first;
  ASSERT_TRUE(s->sample_person(0, 29 / k_fps, a));
  ASSERT_TRUE(s->sample_person(1, 29 / k_fps, b));
  ASSERT_TRUE(s->sample(29 / k_fps, first));
  EXPECT_LT(max_degrees(a, first), 1e-5f);
  EXPECT_GT(max_degrees(a, b), 5.f);                 // two people in their own poses
  EXPECT_FALSE(s->sample_person(2, 29 / k_fps, a));  // not in view yet
  EXPECT_FALSE(s->sample_person(-1, 29 / k_fps, a));
  s->stop();
  std::lock_guard<std::mutex> lock(m);
  EXPECT_EQ(frames_with_people, 30);
  ASSERT_EQ(slot_of.size(), 2u);
  EXPECT_EQ(slot_of[0], 0);
  EXPECT_EQ(slot_of[1], 1);
  EXPECT_GT(outputs_of[0], 0);
  EXPECT_GT(outputs_of[1], 0);
}

// A person who leaves is reported gone once, with its slot, after its last output and before
// the next person takes that slot (the viewer's server forgets its pose then).
TEST(live_session_people, a_person_who_left_is_reported_gone_before_the_slot_is_reused) {
  test::temp_dir dir("live_people_gone");
  const recordings rec = write_recordings(dir);
  live_session_options o;
  o.pipeline = replay_options(rec.together, 3);
  o.output_fps = 200.0;
  std::mutex m;
  struct event {
    bool gone;
    int person, slot;
  };
  std::vector<event> events;
  o.outputs.push_back([&](const proxy_pose&, const live_output_report& r) {
    std::lock_guard<std::mutex> lock(m);
    events.push_back({false, r.person, r.slot});
  });
  o.on_person_gone.push_back([&](int person, int slot) {
    std::lock_guard<std::mutex> lock(m);
    events.push_back({true, person, slot});
  });
  std::unique_ptr<live_session> s;
  ASSERT_TRUE(live_session::create(o, s).ok());
  std::vector<std::uint8_t> px(4 * 4 * 3, 128);
  const image_view img{px.data(), 4, 4, 12, pixel_format::rgb8};
  for (int i = 0; i < k_frames; ++i) {
    ASSERT_TRUE(s->push(img, i / k_fps).ok());
    settle(*s);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // output ticks between frames
  }
  s->stop();
  std::lock_guard<std::mutex> lock(m);
  int gone_at = -1, last_of_1 = -1, first_of_2 = -1;
  for (int i = 0; i < static_cast<int>(events.size()); ++i) {
    const event& e = events[static_cast<std::size_t>(i)];
    if (e.gone) {
      EXPECT_EQ(gone_at, -1) << "a second gone report: person " << e.person;
      EXPECT_EQ(e.person, 1);
      EXPECT_EQ(e.slot, 1);
      gone_at = i;
    } else if (e.person == 1) {
      last_of_1 = i;
    } else if (e.person == 2 && first_of_2 < 0) {
      first_of_2 = i;
      EXPECT_EQ(e.slot, 1) << "person 2 takes the freed slot";
    }
  }
  ASSERT_GE(gone_at, 0) << "person 1 was never reported gone";
  ASSERT_GE(first_of_2, 0);
  EXPECT_LT(last_of_1, gone_at);
  EXPECT_LT(gone_at, first_of_2);
}

}  // namespace
}  // namespace avatarmap
