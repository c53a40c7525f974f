// The kinds of failure the file readers and writers report (status_code), given where each
// failure happens: a file that cannot be opened or read is io, malformed content is parse, a
// bad argument is invalid_argument. Through the real readers and writers on real files.
#include <gtest/gtest.h>

#include <string>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/io/tfjs_import.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

bool names(const status& s, const std::string& what) {
  return s.message().find(what) != std::string::npos;
}

TEST(io_error_codes, a_missing_file_is_io) {
  test::temp_dir dir("io_codes");
  const std::string missing = dir.file("none.landmarks.jsonl");
  landmark_reader lr;
  const status a = lr.open(missing);
  EXPECT_EQ(a.code(), status_code::io) << a.message();
  EXPECT_TRUE(names(a, missing)) << a.message();
  pose_reader pr;
  const status b = pr.open(dir.file("none.pose.jsonl"));
  EXPECT_EQ(b.code(), status_code::io) << b.message();
}

TEST(io_error_codes, a_bad_header_is_parse) {
  test::temp_dir dir("io_codes");
  const std::string lm = dir.file("v9.landmarks.jsonl");
  test::write_text(lm, "{\"format\":\"avatarmap.landmarks\",\"version\":9}\n{\"t\":0}\n");
  landmark_reader lr;
  const status a = lr.open(lm);
  EXPECT_EQ(a.code(), status_code::parse) << a.message();
  const std::string ps = dir.file("v9.pose.jsonl");
  test::write_text(ps, "{\"format\":\"avatarmap.pose\",\"version\":9}\n");
  pose_reader pr;
  const status b = pr.open(ps);
  EXPECT_EQ(b.code(), status_code::parse) << b.message();
}

TEST(io_error_codes, a_malformed_line_is_parse) {
  test::temp_dir dir("io_codes");
  const std::string lm = dir.file("bad.landmarks.jsonl");
  test::write_text(lm, "{\"t\":0}\n{\"t\":oops}\n");
  landmark_reader lr;
  ASSERT_TRUE(lr.open(lm).ok());
  landmark_frame f;
  EXPECT_EQ(lr.next(f), read_result::frame);
  ASSERT_EQ(lr.next(f), read_result::error);
  EXPECT_EQ(lr.error_code(), status_code::parse) << lr.error();
  EXPECT_TRUE(names(status::parse_error(lr.error()), lm + ":2:")) << lr.error();

  const std::string ps = dir.file("bad.pose.jsonl");
  test::write_text(ps, "{\"t\":0,\"bones\":{\"notABone\":[0,0,0,1]}}\n");
  pose_reader pr;
  ASSERT_TRUE(pr.open(ps).ok());
  proxy_pose p;
  ASSERT_EQ(pr.next(p), read_result::error);
  EXPECT_EQ(pr.error_code(), status_code::parse) << pr.error();
}

TEST(io_error_codes, a_read_failure_is_io_not_parse) {
  // A folder opens as a stream on Linux, but reading it fails (EISDIR): the reader reports
  // the read error, as io, at the first frame.
  test::temp_dir dir("io_codes");
  landmark_reader lr;
  if (!lr.open(dir.path().string()).ok()) GTEST_SKIP() << "this system refuses to open a folder";
  landmark_frame f;
  ASSERT_EQ(lr.next(f), read_result::error);
  EXPECT_EQ(lr.error_code(), status_code::io) << lr.error();
  EXPECT_TRUE(names(status::io_error(lr.error()), "read error")) << lr.error();
}

TEST(io_error_codes, an_output_that_cannot_be_written_is_io) {
  test::temp_dir dir("io_codes");
  pose_writer pw;
  const status a = pw.open(dir.file("no-such-folder/x.pose.jsonl"), {});
  EXPECT_EQ(a.code(), status_code::io) << a.message();
  landmark_writer lw;
  const status b = lw.open(dir.file("no-such-folder/x.landmarks.jsonl"), {});
  EXPECT_EQ(b.code(), status_code::io) << b.message();
  const status c = pw.open("", {});
  EXPECT_EQ(c.code(), status_code::invalid_argument) << c.message();
}

TEST(io_error_codes, tfjs_import_tells_arguments_files_and_content_apart) {
  test::temp_dir dir("io_codes");
  const std::string out = dir.file("out.landmarks.jsonl");
  const std::string image = dir.file("image.json");
  const std::string world = dir.file("world.json");
  test::write_text(image, "[]");
  test::write_text(world, "[]");
  // A bad option.
  EXPECT_EQ(import_tfjs_pose(image, world, 0, 480, 30.0, out).code(),
            status_code::invalid_argument);
  // A file that is not there.
  const status missing = import_tfjs_pose(dir.file("none.json"), world, 640, 480, 30.0, out);
  EXPECT_EQ(missing.code(), status_code::io) << missing.message();
  // Malformed JSON, and JSON of the wrong shape.
  test::write_text(image, "[[1, 2,");
  const status broken = import_tfjs_pose(image, world, 640, 480, 30.0, out);
  EXPECT_EQ(broken.code(), status_code::parse) << broken.message();
  test::write_text(image, "{\"frames\": []}");
  const status shape = import_tfjs_pose(image, world, 640, 480, 30.0, out);
  EXPECT_EQ(shape.code(), status_code::parse) << shape.message();
}

}  // namespace
}  // namespace avatarmap
