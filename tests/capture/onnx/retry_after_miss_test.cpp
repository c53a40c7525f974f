// No work on parts that are not in view (retry_after_miss_seconds): a hand side whose region
// from the body held no hand, and a face search that found nothing, are tried again only
// after 0.1 s of frame time. On asl_hand.25fps.mp4 (a hand close up: the body the pose model
// reports there has no real face and one real hand) this saves landmark and detector runs and
// finds the same; a face that appears is found within the retry time.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "avatarmap/capture/face_pipeline.hpp"
#include "avatarmap/capture/hand_pipeline.hpp"
#include "avatarmap/capture/pose_pipeline.hpp"
#include "avatarmap/media/video_source.hpp"
#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

#define SKIP_WITHOUT_MODELS_AND_DATA()                                             \
  do {                                                                             \
    if (test::models_dir().empty()) GTEST_SKIP() << "AVATARMAP_MODELS is not set"; \
    if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;       \
    if (!video_source_available()) GTEST_SKIP() << "built without FFmpeg";         \
  } while (0)

struct counts {
  int hand_runs = 0, hands_found = 0, face_searches = 0, faces_found = 0;
};

counts run_asl(double retry) {
  counts c;
  pose_pipeline_options po;
  po.models_dir = test::models_dir();
  std::unique_ptr<pose_pipeline> pose;
  EXPECT_TRUE(pose_pipeline::create(po, pose).ok());
  hand_pipeline_options ho;
  ho.models_dir = test::models_dir();
  ho.retry_after_miss_seconds = retry;
  std::unique_ptr<hand_pipeline> hands;
  EXPECT_TRUE(hand_pipeline::create(ho, hands).ok());
  face_pipeline_options fo;
  fo.models_dir = test::models_dir();
  fo.retry_after_miss_seconds = retry;
  std::unique_ptr<face_pipeline> face;
  EXPECT_TRUE(face_pipeline::create(fo, face).ok());
  if (!pose || !hands || !face) return c;
  video_source src;
  EXPECT_TRUE(src.open(test::test_data_path("motion/tfjs-models/asl_hand.25fps.mp4")).ok());
  image_view img;
  double t = 0;
  landmark_frame f;
  while (src.next(img, t) == read_result::frame) {
    f.clear();
    EXPECT_NE(pose->process(img, f), pose_result::error);
    const landmark_frame* body = f.has(frame_part::pose) ? &f : nullptr;
    EXPECT_NE(hands->process(img, body, f, t), hand_result::error);
    c.hand_runs += hands->last_timings().landmark_runs;
    c.hands_found += hands->hand_count();
    EXPECT_NE(face->process(img, body, f, t), face_result::error);
    c.face_searches += face->last_ran_detector();
    c.faces_found += f.has(frame_part::face);
  }
  return c;
}

TEST(retry_after_miss, asl_video_fewer_runs_same_findings) {
  SKIP_WITHOUT_MODELS_AND_DATA();
  const counts every = run_asl(0.0), retry = run_asl(0.1);
  std::printf(
      "[figures] asl_hand.25fps.mp4, every frame / after 0.1 s: hand landmark runs %d / %d, "
      "hands found %d / %d, face searches %d / %d, faces found %d / %d\n",
      every.hand_runs, retry.hand_runs, every.hands_found, retry.hands_found, every.face_searches,
      retry.face_searches, every.faces_found, retry.faces_found);
  EXPECT_LT(retry.hand_runs, every.hand_runs * 9 / 10);
  EXPECT_GE(retry.hands_found, every.hands_found * 98 / 100);
  // 25 frames/s: a search every third frame at most.
  EXPECT_LE(retry.face_searches, every.face_searches / 2);
  // There is no face in this video (searching every frame once takes the fist for one).
  EXPECT_LE(retry.faces_found, every.faces_found);
}

// A face that comes into view is found within the retry time: black frames, then the
// portrait, at 30 frames/s.
TEST(retry_after_miss, a_face_that_appears_is_found_within_the_retry_time) {
  SKIP_WITHOUT_MODELS_AND_DATA();
  test::loaded_image portrait;
  ASSERT_TRUE(test::load_image(test::test_data_path("motion/tfjs-models/portrait.jpg"), portrait));
  std::vector<unsigned char> black(portrait.pixels.size(), 0);
  const image_view dark{black.data(), portrait.width, portrait.height, portrait.width * 3,
                        pixel_format::rgb8};
  for (int appears_at : {5, 6, 7}) {  // each phase of the every-third-frame search
    face_pipeline_options fo;
    fo.models_dir = test::models_dir();
    std::unique_ptr<face_pipeline> face;
    ASSERT_TRUE(face_pipeline::create(fo, face).ok());
    landmark_frame f;
    int found_at = -1;
    for (int i = 0; i < 20 && found_at < 0; ++i) {
      const double t = i / 30.0;
      ASSERT_NE(face->process(i < appears_at ? dark : portrait.view(), nullptr, f, t),
                face_result::error);
      if (f.has(frame_part::face)) found_at = i;
    }
    ASSERT_GE(found_at, appears_at);
    // Within 0.1 s (three frames at 30 frames/s) of appearing.
    EXPECT_LE((found_at - appears_at) / 30.0, 0.1 + 1e-9) << "appears at frame " << appears_at;
  }
}

}  // namespace
}  // namespace avatarmap
