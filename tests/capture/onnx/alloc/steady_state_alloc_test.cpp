// No heap allocation per frame in the capture pipelines' steady state outside ONNX Runtime:
// the onnx estimator (body, hands, face; one ORT thread per lane, so ORT runs everything on
// the lane's own thread inside bound_model::run) tracks pose.jpg frame after frame while a replaced
// global operator new counts the allocations made outside ORT's Run. Its own executable, so the
// replacement affects no other test.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include "../onnx_support.hpp"
#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "capture/onnx/ort_model.hpp"
#include "support/test_data.hpp"

namespace {
std::atomic<long> g_outside{0};
std::atomic<bool> g_counting{false};
}  // namespace

void* operator new(std::size_t n) {
  // Our threads only (those that run models), outside a run: ONNX Runtime's own threads were
  // seen allocating at times with several people (its business, not the pipelines').
  if (g_counting.load(std::memory_order_relaxed) && avatarmap::ort_run_depth() == 0 &&
      avatarmap::ort_thread_has_run())
    g_outside.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace avatarmap {
namespace {

// `threads` 1: one lane; 2: two lanes (a worker thread runs the hands beside the face, and
// with `pipelined` the body of the next frame beside them).
// `people` > 1: three_people.jpg with max_people = people (every person's body, hands, face).
void count_steady_state_allocations(int threads, bool pipelined, int people = 1) {
  const std::string models = test::models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  test::loaded_image img;
  ASSERT_TRUE(
      test::load_image(test::test_data_path(people > 1 ? "motion/tfjs-models/three_people.jpg"
                                                       : "motion/tfjs-models/pose.jpg"),
                       img));
  estimator_options o;
  o.source = models;
  o.threads = threads;
  o.hands = o.face = true;
  o.max_people = people;
  std::unique_ptr<estimator> est;
  const status s = create_estimator("onnx", o, est);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(est->pipeline_delay(), threads > 1 ? 1 : 0);
  landmark_frame f;
  estimate_args a;
  a.image = img.view();
  int parts = 0, seen = 0, detector_runs = 0;
  g_outside = 0;
  for (int i = 0; i < 40; ++i) {
    a.t = i / 30.0;
    if (i == 10) g_counting = true;  // after warm-up: tracking, buffers sized
    bool ready = true;
    if (pipelined)
      ASSERT_TRUE(est->estimate_pipelined(&a, f, ready).ok());
    else
      ASSERT_TRUE(est->estimate(a, f).ok());
    if (ready) parts |= static_cast<int>(f.parts);
    if (people > 1 && ready && i >= 10) {
      const estimator::people_view v = est->last_people();
      seen = std::max(seen, v.count);
      // Every person's parts: the first one (the lowest id) may be one whose track restarted
      // (three_people.jpg's seated man drifts onto his neighbour, docs/capture-people.md).
      for (int k = 0; k < v.count; ++k) parts |= static_cast<int>(v.frames[k].parts);
    }
    if (ready && i >= 10 && est->last_timings())
      detector_runs += est->last_timings()->detector_runs;
  }
  g_counting = false;
  EXPECT_TRUE(f.has(frame_part::pose));
  if (people > 1)
    EXPECT_TRUE(parts & (1 << static_cast<int>(frame_part::face)));
  else
    EXPECT_TRUE(f.has(frame_part::face));
  // The three people of three_people.jpg (one may be lost for a frame and found again).
  if (people > 1) EXPECT_EQ(seen, people);
  std::printf(
      "[figures] threads %d%s, people %d: parts seen: 0x%x; allocations outside ONNX Runtime in "
      "30 frames: %ld (detector runs %d)\n",
      threads, pipelined ? ", pipelined" : "", people, parts, g_outside.load(), detector_runs);
  EXPECT_EQ(g_outside.load(), 0);
}

TEST(steady_state, no_allocation_outside_onnx_runtime) { count_steady_state_allocations(1, false); }

TEST(steady_state, two_lanes_allocate_nothing_outside_onnx_runtime) {
  count_steady_state_allocations(2, false);
  count_steady_state_allocations(2, true);
}

TEST(steady_state, several_people_allocate_nothing_outside_onnx_runtime) {
  count_steady_state_allocations(1, false, 3);
  count_steady_state_allocations(2, true, 3);
}

// The same through capture_pipeline (what the C API's estimator and live handles run): the
// estimator, the solver and the live filter together allocate nothing per frame either.
TEST(steady_state, capture_pipeline_allocates_nothing_outside_onnx_runtime) {
  const std::string models = test::models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  test::loaded_image img;
  ASSERT_TRUE(test::load_image(test::test_data_path("motion/tfjs-models/pose.jpg"), img));
  capture_pipeline_options o;
  o.estimator.source = models;
  o.estimator.threads = 1;
  o.estimator.hands = o.estimator.face = true;
  std::unique_ptr<capture_pipeline> p;
  const status s = capture_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();
  landmark_frame f;
  proxy_pose pose;
  g_outside = 0;
  for (int i = 0; i < 40; ++i) {
    if (i == 10) g_counting = true;
    ASSERT_TRUE(p->process(img.view(), i / 30.0, f, pose).ok());
  }
  g_counting = false;
  EXPECT_TRUE(f.has(frame_part::pose));
  std::printf("[figures] capture_pipeline: allocations outside ONNX Runtime in 30 frames: %ld\n",
              g_outside.load());
  EXPECT_EQ(g_outside.load(), 0);
}

// Several people through capture_pipeline (the C API's avm_estimator_process_people and the
// live session): each person's stream in its slot allocates nothing per frame either.
TEST(steady_state, capture_pipeline_people_allocate_nothing_outside_onnx_runtime) {
  const std::string models = test::models_dir();
  if (models.empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set (folder of converted models)";
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  test::loaded_image img;
  ASSERT_TRUE(test::load_image(test::test_data_path("motion/tfjs-models/three_people.jpg"), img));
  capture_pipeline_options o;
  o.estimator.source = models;
  o.estimator.threads = 1;
  o.estimator.hands = o.estimator.face = true;
  o.estimator.max_people = 3;
  o.estimator.static_images = true;  // the same three people, slots kept, every frame
  std::unique_ptr<capture_pipeline> p;
  const status s = capture_pipeline::create(o, p);
  ASSERT_TRUE(s.ok()) << s.message();
  landmark_frame f;
  people_poses people;
  g_outside = 0;
  int least = k_max_people;
  for (int i = 0; i < 30; ++i) {
    if (i == 10) g_counting = true;
    ASSERT_TRUE(p->estimate(img.view(), i / 30.0, f).ok());
    p->solve_people(f, people);
    if (i >= 10) least = std::min(least, people.count);
  }
  g_counting = false;
  EXPECT_EQ(least, 3);
  std::printf(
      "[figures] capture_pipeline, 3 people: allocations outside ONNX Runtime in 20 frames: "
      "%ld\n",
      g_outside.load());
  EXPECT_EQ(g_outside.load(), 0);
}

}  // namespace
}  // namespace avatarmap
