// The kinds of failure (status_code) of making an estimator: an unknown backend is
// invalid_argument, a backend this build lacks (onnx without ONNX Runtime) is unsupported,
// models or a recording that cannot be read are io, a malformed recording is parse. Through
// the real create_estimator and capture_pipeline_options::validate.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

bool has_backend(std::string_view name) {
  const estimator_backend_list list = estimator_backends();
  for (int i = 0; i < list.count; ++i)
    if (list.items[i].name == name) return true;
  return false;
}

TEST(capture_error_codes, an_unknown_backend_is_invalid_argument) {
  std::unique_ptr<estimator> est;
  EXPECT_EQ(create_estimator("no-such-backend", {}, est).code(), status_code::invalid_argument);
  capture_pipeline_options o;
  o.backend = "no-such-backend";
  EXPECT_EQ(o.validate().code(), status_code::invalid_argument);
}

TEST(capture_error_codes, onnx_without_the_runtime_is_unsupported) {
  if (has_backend("onnx")) GTEST_SKIP() << "this build has the onnx backend";
  std::unique_ptr<estimator> est;
  const status st = create_estimator("onnx", {}, est);
  EXPECT_EQ(st.code(), status_code::unsupported) << st.message();
  capture_pipeline_options o;
  o.backend = "onnx";
  EXPECT_EQ(o.validate().code(), status_code::unsupported);
}

TEST(capture_error_codes, models_that_cannot_be_read_are_io) {
  if (!has_backend("onnx")) GTEST_SKIP() << "built without the onnx backend";
  test::temp_dir dir("capture_codes");
  estimator_options o;
  o.source = dir.file("no-models-here");
  std::unique_ptr<estimator> est;
  const status st = create_estimator("onnx", o, est);
  EXPECT_EQ(st.code(), status_code::io) << st.message();
  EXPECT_NE(st.message().find("no-models-here"), std::string::npos) << st.message();
}

TEST(capture_error_codes, replay_recording_missing_is_io_malformed_is_parse) {
  test::temp_dir dir("capture_codes");
  std::unique_ptr<estimator> est;
  estimator_options o;
  EXPECT_EQ(create_estimator("replay", o, est).code(), status_code::invalid_argument);
  o.source = dir.file("none.landmarks.jsonl");
  EXPECT_EQ(create_estimator("replay", o, est).code(), status_code::io);
  o.source = dir.file("bad.landmarks.jsonl");
  test::write_text(o.source, "{\"t\":0}\n{\"t\":\n");
  ASSERT_TRUE(create_estimator("replay", o, est).ok());
  landmark_frame f;
  estimate_args args;
  ASSERT_TRUE(est->estimate(args, f).ok());
  const status st = est->estimate(args, f);
  EXPECT_EQ(st.code(), status_code::parse) << st.message();
}

}  // namespace
}  // namespace avatarmap
