// The kinds of failure (status_code) of video and image input and output: a file that is not
// there is io, a file that is not media is parse, a bad option is invalid_argument, and a
// build without FFmpeg says unsupported. Through the real video_source and video_writer.
#include <gtest/gtest.h>

#include <string>

#include "avatarmap/media/video_source.hpp"
#include "avatarmap/media/video_writer.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

TEST(media_error_codes, video_source_missing_is_io_not_media_is_parse_bad_option_invalid) {
  test::temp_dir dir("media_codes");
  if (!video_source_available()) GTEST_SKIP() << "built without FFmpeg";
  video_source src;
  const status missing = src.open(dir.file("none.mp4"));
  EXPECT_EQ(missing.code(), status_code::io) << missing.message();
  const std::string text = dir.file("text.mp4");
  test::write_text(text, "this is not a video, only some text long enough to probe\n");
  const status not_media = src.open(text);
  EXPECT_EQ(not_media.code(), status_code::parse) << not_media.message();
  const std::string empty = dir.file("empty.mp4");
  test::write_text(empty, "");
  EXPECT_EQ(src.open(empty).code(), status_code::parse);
  video_source_options o;
  o.max_threads = -1;
  const status bad = src.open(text, o);
  EXPECT_EQ(bad.code(), status_code::invalid_argument) << bad.message();
}

TEST(media_error_codes, video_writer_unwritable_is_io_bad_option_invalid) {
  if (!video_writer_available()) GTEST_SKIP() << "built without FFmpeg";
  test::temp_dir dir("media_codes");
  video_writer w;
  const status bad_fps = w.open(dir.file("x.mp4"), 64, 64, -1.0);
  EXPECT_EQ(bad_fps.code(), status_code::invalid_argument) << bad_fps.message();
  const status folder = w.open(dir.file("no-such-folder/x.mp4"), 64, 64, 30.0);
  EXPECT_EQ(folder.code(), status_code::io) << folder.message();
  const status format = w.open(dir.file("x.txt"), 64, 64, 30.0);
  EXPECT_EQ(format.code(), status_code::invalid_argument) << format.message();
}

TEST(media_error_codes, without_ffmpeg_opening_is_unsupported) {
  if (video_source_available() && video_writer_available()) GTEST_SKIP() << "this build has FFmpeg";
  test::temp_dir dir("media_codes");
  if (!video_source_available()) {
    video_source src;
    const status st = src.open(dir.file("none.mp4"));
    EXPECT_EQ(st.code(), status_code::unsupported) << st.message();
  }
  if (!video_writer_available()) {
    video_writer w;
    const status st = w.open(dir.file("x.mp4"), 64, 64, 30.0);
    EXPECT_EQ(st.code(), status_code::unsupported) << st.message();
  }
}

}  // namespace
}  // namespace avatarmap
