// Reading landmark frames and writing poses allocate nothing per frame once warm: a counting
// global operator new (for this test executable) proves it for landmark_reader::next (from
// memory and from a file, full holistic frames, compact and spaced text) and
// pose_writer::write.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/synth/synth_recording.hpp"
#include "support/counting_new.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

using test::read_text;
using test::temp_dir;

TEST(io_allocation, counting_allocator_sees_allocations) {
  const long before = g_allocations.load();
  void* p = ::operator new(16);  // a direct call: not elided like a new-expression may be
  ::operator delete(p);
  EXPECT_EQ(g_allocations.load() - before, 1);  // the counter works, so 0 below means 0
}

// A landmark file of `frames` full frames (noisy synthetic scenario); every third line with
// white space after each ',' so that the general path runs too.
std::string landmark_file(const temp_dir& dir, int frames) {
  const std::string path = dir.file("a.landmarks.jsonl");
  landmark_writer w;
  EXPECT_TRUE(w.open(path, {}).ok());
  synth_recording synth(synth_scenario_options(synth_scenario::noisy, 5));
  proxy_pose truth;
  landmark_frame f;
  for (int i = 0; i < frames; ++i) {
    synth.generate(i / 30.0, truth, f);
    EXPECT_TRUE(w.write(f).ok());
  }
  EXPECT_TRUE(w.commit().ok());
  std::string text = read_text(path), spaced;
  int line = 0;
  for (char c : text) {
    spaced += c;
    if (c == '\n') ++line;
    if (c == ',' && line % 3 == 2) spaced += ' ';
  }
  test::write_text(path, spaced);
  return path;
}

TEST(io_allocation, landmark_reader_next_allocates_nothing_per_frame) {
  temp_dir dir;
  const std::string path = landmark_file(dir, 40);
  const std::string text = read_text(path);
  for (int from_file = 0; from_file < 2; ++from_file) {
    SCOPED_TRACE(from_file ? "file" : "memory");
    landmark_reader r;
    ASSERT_TRUE((from_file ? r.open(path) : r.open_memory(text.data(), text.size())).ok());
    landmark_frame f;
    for (int i = 0; i < 4; ++i) ASSERT_EQ(r.next(f), read_result::frame) << r.error();  // warm-up
    const long before = g_allocations.load();
    int frames = 0;
    while (r.next(f) == read_result::frame) ++frames;
    EXPECT_EQ(g_allocations.load() - before, 0);
    EXPECT_EQ(frames, 36);
    EXPECT_TRUE(r.error().empty()) << r.error();
  }
}

TEST(io_allocation, pose_writer_write_allocates_nothing_per_frame) {
  temp_dir dir;
  pose_writer w;
  pose_write_options o;
  o.write_confidence = true;
  ASSERT_TRUE(w.open(dir.file("a.pose.jsonl"), {}, o).ok());
  synth_recording synth(synth_scenario_options(synth_scenario::noisy, 5));
  proxy_pose pose;
  landmark_frame f;
  synth.generate(0.0, pose, f);
  ASSERT_TRUE(w.write(pose).ok());  // warm-up
  const long before = g_allocations.load();
  // ~3 kB a pose: the output buffer is written out several times.
  for (int i = 0; i < 1000; ++i) {
    pose.t = i / 30.0;
    ASSERT_TRUE(w.write(pose).ok());
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  ASSERT_TRUE(w.commit().ok());
}

}  // namespace
}  // namespace avatarmap
