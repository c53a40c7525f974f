#include "avatarmap/io/landmark_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "io/line_source.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

// A fresh, empty folder per test, removed afterwards.
using test::read_text;
using test::temp_dir;
using test::write_text;

// Restores the line source limits changed by a test.
struct limits_guard {
  io_detail::line_source_limits saved = io_detail::default_line_source_limits();
  ~limits_guard() { io_detail::default_line_source_limits() = saved; }
};

std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

// Same value bit for bit, or both non-finite (written as null, read back as NaN).
::testing::AssertionResult same_float(float a, float b) {
  if (!std::isfinite(a) && !std::isfinite(b)) return ::testing::AssertionSuccess();
  if (bits(a) == bits(b)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " != " << b;
}

void expect_same_points(const landmark* a, const landmark* b, int n, const char* what) {
  for (int i = 0; i < n; ++i) {
    SCOPED_TRACE(std::string(what) + " point " + std::to_string(i));
    EXPECT_TRUE(same_float(a[i].x, b[i].x));
    EXPECT_TRUE(same_float(a[i].y, b[i].y));
    EXPECT_TRUE(same_float(a[i].z, b[i].z));
    EXPECT_TRUE(same_float(a[i].visibility, b[i].visibility));
    EXPECT_TRUE(same_float(a[i].presence, b[i].presence));
  }
}

void expect_same_frame(const landmark_frame& a, const landmark_frame& b) {
  EXPECT_EQ(a.t, b.t);
  ASSERT_EQ(a.parts, b.parts);
  if (a.has(frame_part::pose)) expect_same_points(a.pose.data(), b.pose.data(), 33, "pose");
  if (a.has(frame_part::pose_world))
    expect_same_points(a.pose_world.data(), b.pose_world.data(), 33, "pose_world");
  if (a.has(frame_part::left_hand))
    expect_same_points(a.left_hand.data(), b.left_hand.data(), 21, "left_hand");
  if (a.has(frame_part::left_hand_world))
    expect_same_points(a.left_hand_world.data(), b.left_hand_world.data(), 21, "lhw");
  if (a.has(frame_part::right_hand))
    expect_same_points(a.right_hand.data(), b.right_hand.data(), 21, "right_hand");
  if (a.has(frame_part::right_hand_world))
    expect_same_points(a.right_hand_world.data(), b.right_hand_world.data(), 21, "rhw");
  if (a.has(frame_part::face)) {
    ASSERT_EQ(a.face_count, b.face_count);
    expect_same_points(a.face.data(), b.face.data(), a.face_count, "face");
  }
}

// Frames with awkward floats: random bits of every magnitude, -0, subnormals, extremes.
std::vector<landmark_frame> make_frames(int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.f, 1.f);
  std::uniform_int_distribution<std::uint32_t> any_bits;
  auto value = [&](int k) -> float {
    switch (k % 9) {
      case 0: {
        std::uint32_t u = any_bits(rng);
        float f;
        std::memcpy(&f, &u, 4);
        return std::isfinite(f) ? f : 0.5f;
      }
      case 1:
        return -0.f;
      case 2:
        return std::numeric_limits<float>::denorm_min();
      case 3:
        return std::numeric_limits<float>::max();
      case 4:
        return 1e-7f;
      default:
        return unit(rng);
    }
  };
  std::vector<landmark_frame> frames(static_cast<std::size_t>(count));
  int k = 0;
  for (int i = 0; i < count; ++i) {
    landmark_frame& f = frames[static_cast<std::size_t>(i)];
    f.clear();
    f.t = i * (1.0 / 30.0);
    f.parts = static_cast<std::uint32_t>(i % 2 == 0 ? 0x7f : (i * 37) & 0x7f);
    f.face_count = f.has(frame_part::face) ? (i % 4 == 0 ? 478 : 468) : 0;
    auto fill = [&](landmark* p, int n, bool five) {
      for (int j = 0; j < n; ++j) {
        p[j].x = value(k++);
        p[j].y = value(k++);
        p[j].z = value(k++);
        p[j].visibility = five || j % 5 == 0 ? unit(rng) : 1.f;
        p[j].presence = five ? unit(rng) : 1.f;
      }
    };
    fill(f.pose.data(), 33, true);
    fill(f.pose_world.data(), 33, true);
    fill(f.left_hand.data(), 21, false);
    fill(f.left_hand_world.data(), 21, false);
    fill(f.right_hand.data(), 21, false);
    fill(f.right_hand_world.data(), 21, false);
    fill(f.face.data(), 478, false);
  }
  return frames;
}

std::string points_json(int n, const char* point = "[0.5,0.25,-0.125,0.9,1]") {
  std::string s = "[";
  for (int i = 0; i < n; ++i) {
    if (i) s += ',';
    s += point;
  }
  return s + "]";
}

// Reads `text` from memory and returns the result of the first next().
struct one_frame {
  read_result result;
  landmark_frame frame;
  std::string error;
  long line;
};
one_frame read_one(const std::string& text) {
  landmark_reader r;
  EXPECT_TRUE(r.open_memory(text.data(), text.size(), "mem.jsonl").ok());
  one_frame o;
  o.result = r.next(o.frame);
  o.error = r.error();
  o.line = r.line();
  return o;
}

TEST(landmark_file, round_trip_is_bit_exact) {
  temp_dir dir;
  const std::string path = dir.file("a.landmarks.jsonl");
  auto frames = make_frames(40, 7);
  landmark_file_header h;
  h.image_width = 1280;
  h.image_height = 720;
  h.fps = 29.97;
  {
    landmark_writer w;
    ASSERT_TRUE(w.open(path, h).ok());
    for (auto& f : frames) ASSERT_TRUE(w.write(f).ok());
    ASSERT_TRUE(w.commit().ok());
  }
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  EXPECT_TRUE(r.header().present);
  EXPECT_EQ(r.header().version, 1);
  EXPECT_EQ(r.header().image_width, 1280);
  EXPECT_EQ(r.header().image_height, 720);
  EXPECT_EQ(r.header().fps, 29.97);
  landmark_frame f;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    EXPECT_EQ(r.line(), static_cast<long>(i) + 2);
    expect_same_frame(frames[i], f);
  }
  EXPECT_EQ(r.next(f), read_result::end);
  EXPECT_EQ(r.next(f), read_result::end);
}

TEST(landmark_file, non_finite_values_are_written_as_null_and_read_as_not_seen) {
  temp_dir dir;
  const std::string path = dir.file("nan.landmarks.jsonl");
  landmark_frame f;
  f.t = 0.25;
  f.set(frame_part::pose, true);
  f.pose[3].x = std::numeric_limits<float>::quiet_NaN();
  f.pose[4].y = std::numeric_limits<float>::infinity();
  f.pose[5].z = -std::numeric_limits<float>::infinity();
  landmark_writer w;
  ASSERT_TRUE(w.open(path, {}).ok());
  ASSERT_TRUE(w.write(f).ok());
  ASSERT_TRUE(w.commit().ok());
  std::string text = read_text(path);
  EXPECT_NE(text.find("[null,0,0,1,1]"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  landmark_frame g;
  ASSERT_EQ(r.next(g), read_result::frame) << r.error();
  EXPECT_FALSE(std::isfinite(g.pose[3].x));
  EXPECT_FALSE(std::isfinite(g.pose[4].y));
  EXPECT_FALSE(std::isfinite(g.pose[5].z));
  EXPECT_EQ(g.pose[6].x, 0.f);
}

TEST(landmark_file, special_numbers) {
  std::string pose =
      "[[null,1e400,-1e400,1,1],[1e308,-1e308,1e-400,1,1],[NaN,Infinity,-Infinity],"
      "[-0,1e-7,1E+2],[0.5e1,-2.5E-3,123456789012345678901234567890]";
  for (int i = 5; i < 33; ++i) pose += ",[0,0,0]";
  pose += "]";
  auto o = read_one("{\"t\":1,\"pose\":" + pose + "}\n");
  ASSERT_EQ(o.result, read_result::frame) << o.error;
  const auto& p = o.frame.pose;
  EXPECT_TRUE(std::isnan(p[0].x));
  EXPECT_TRUE(std::isinf(p[0].y) && p[0].y > 0);
  EXPECT_TRUE(std::isinf(p[0].z) && p[0].z < 0);
  // 1e308 is a finite double but no float: read as +-inf, i.e. "not seen".
  EXPECT_TRUE(std::isinf(p[1].x) && p[1].x > 0);
  EXPECT_TRUE(std::isinf(p[1].y) && p[1].y < 0);
  EXPECT_EQ(p[1].z, 0.f);
  EXPECT_TRUE(std::isnan(p[2].x));
  EXPECT_TRUE(std::isinf(p[2].y));
  EXPECT_EQ(p[2].visibility, 1.f);
  EXPECT_EQ(p[3].x, 0.f);
  EXPECT_TRUE(std::signbit(p[3].x));
  EXPECT_EQ(p[3].y, 1e-7f);
  EXPECT_EQ(p[3].z, 100.f);
  EXPECT_EQ(p[4].x, 5.f);
  EXPECT_EQ(p[4].y, -2.5e-3f);
  EXPECT_EQ(p[4].z, std::strtof("123456789012345678901234567890", nullptr));
}

TEST(landmark_file, point_value_counts_and_defaults) {
  std::string pose = "[[1,2,3],[1,2,3,0.5]";
  for (int i = 2; i < 33; ++i) pose += ",[1,2,3,0.25,0.75]";
  pose += "]";
  std::string hand = "[[1,2,3,0.5,0.25]";
  for (int i = 1; i < 21; ++i) hand += ",[1,2,3]";
  hand += "]";
  auto o = read_one("{\"t\":1,\"pose\":" + pose + ",\"left_hand\":" + hand + "}");
  ASSERT_EQ(o.result, read_result::frame) << o.error;
  EXPECT_EQ(o.frame.pose[0].visibility, 1.f);
  EXPECT_EQ(o.frame.pose[0].presence, 1.f);
  EXPECT_EQ(o.frame.pose[1].visibility, 0.5f);
  EXPECT_EQ(o.frame.pose[1].presence, 1.f);
  EXPECT_EQ(o.frame.pose[2].presence, 0.75f);
  EXPECT_EQ(o.frame.left_hand[0].visibility, 0.5f);
  EXPECT_EQ(o.frame.left_hand[0].presence, 0.25f);
  EXPECT_EQ(o.frame.left_hand[1].visibility, 1.f);
  EXPECT_TRUE(o.frame.has(frame_part::left_hand));
  EXPECT_FALSE(o.frame.has(frame_part::right_hand));
  EXPECT_FALSE(o.frame.has(frame_part::face));
}

TEST(landmark_file, any_key_order_unknown_keys_whitespace_and_null_parts) {
  std::string text =
      " { \"extra\" : {\"a\":[1,{\"b\":null},\"s\\\"\\u00e9\\ud83d\\ude00\"],\"c\":true} ,"
      "\"face\":" +
      points_json(468, "[ 1 , 2 , 3 ]") +
      ",\t\"right_hand\" : null, \"n\":-1.5e3, \"f\":false, \"e\":[] , \"o\":{},"
      "\"pose_world\":" +
      points_json(33) + ", \"t\" : 2.5 }  \t";
  auto o = read_one(text);
  ASSERT_EQ(o.result, read_result::frame) << o.error;
  EXPECT_EQ(o.frame.t, 2.5);
  EXPECT_TRUE(o.frame.has(frame_part::face));
  EXPECT_EQ(o.frame.face_count, 468);
  EXPECT_TRUE(o.frame.has(frame_part::pose_world));
  EXPECT_FALSE(o.frame.has(frame_part::right_hand));
  EXPECT_FALSE(o.frame.has(frame_part::pose));
  EXPECT_EQ(o.frame.face[467].z, 3.f);
  EXPECT_EQ(o.frame.pose_world[32].visibility, 0.9f);
}

struct bad_case {
  const char* name;
  std::string line;
  const char* expected_in_error;
};

TEST(landmark_file, malformed_lines_name_file_line_and_problem_and_reading_goes_on) {
  const std::string good_pose = points_json(33);
  std::vector<bad_case> cases = {
      {"array line", "[1,2,3]", "expected '{'"},
      {"string line", "\"frame\"", "expected '{'"},
      {"garbage", "hello", "expected '{'"},
      {"pose 32 points", "{\"t\":0,\"pose\":" + points_json(32) + "}",
       "in \"pose\": has 32 points (expected 33)"},
      {"pose 34 points", "{\"t\":0,\"pose\":" + points_json(34) + "}",
       "has 34 points (expected 33)"},
      {"hand 20 points", "{\"t\":0,\"left_hand_world\":" + points_json(20, "[1,2,3]") + "}",
       "\"left_hand_world\": has 20 points (expected 21)"},
      {"face 470 points", "{\"t\":0,\"face\":" + points_json(470, "[1,2,3]") + "}",
       "has 470 points (expected 468 or 478)"},
      {"face 500 points", "{\"t\":0,\"face\":" + points_json(500, "[1,2,3]") + "}",
       "has 500 points (expected 468 or 478)"},
      {"two values", "{\"t\":0,\"pose\":[[1,2]]}", "point 0: 2 values (expected 3 to 5"},
      {"six values", "{\"t\":0,\"pose\":[[1,2,3,4,5,6]]}", "more than 5 values"},
      {"string value", "{\"t\":0,\"pose\":[[1,\"2\",3]]}",
       "point 0: expected a number or null, found '\"'"},
      {"bool value", "{\"t\":0,\"pose\":[[1,true,3]]}", "expected a number or null"},
      {"point not array", "{\"t\":0,\"pose\":[1,2,3]}", "expected '[' starting a point"},
      {"part not array", "{\"t\":0,\"pose\":{}}", "in \"pose\": expected '[' starting an array"},
      {"truncated", "{\"t\":0,\"pose\":[[1,2,3],[4,", "found end of line"},
      {"truncated after key", "{\"t\":0,\"po", "unterminated string"},
      {"missing t", "{\"pose\":" + good_pose + "}", "missing \"t\""},
      {"null t", "{\"t\":null}", "\"t\": not a finite number"},
      {"string t", "{\"t\":\"0\"}", "in \"t\": expected a number or null"},
      {"trailing text", "{\"t\":0} x", "unexpected text after the frame object"},
      {"two objects", "{\"t\":0}{\"t\":1}", "unexpected text after the frame object"},
      {"missing colon", "{\"t\" 0}", "expected ':'"},
      {"missing comma", "{\"t\":0 \"pose\":[]}", "expected ',' or '}'"},
      {"late header", "{\"format\":\"avatarmap.landmarks\",\"version\":1}",
       "only allowed as the first line"},
      {"leading plus", "{\"t\":+1}", "expected a number or null"},
      {"bare inf", "{\"t\":0,\"pose\":[[inf,0,0]]}", "expected a number or null"},
      {"control char", std::string("{\"t\":0,\"a\x01\":1}"), "control character"},
      {"deep nesting", "{\"t\":0,\"x\":" + std::string(300, '[') + std::string(300, ']') + "}",
       "nesting too deep"},
      // One level over the documented 256, with an empty innermost array (this passed before).
      {"257 levels", "{\"t\":0,\"x\":" + std::string(257, '[') + std::string(257, ']') + "}",
       "nesting too deep"},
      {"leading zero t", "{\"t\":00.5}", "in \"t\": not a JSON number"},
      {"leading zero point", "{\"t\":0,\"pose\":[[01,0,0]]}", "not a JSON number"},
      {"dot without digits", "{\"t\":1.}", "not a JSON number"},
  };
  // Each bad line sits between good lines; the reader reports it and goes on.
  std::string text = "{\"format\":\"avatarmap.landmarks\",\"version\":1}\n";
  for (auto& c : cases) {
    text += "{\"t\":1}\n";
    text += c.line + "\n";
  }
  text += "{\"t\":2}\n";
  landmark_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size(), "bad.jsonl").ok());
  landmark_frame f;
  long line = 1;
  for (auto& c : cases) {
    SCOPED_TRACE(c.name);
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    EXPECT_EQ(r.line(), ++line);
    EXPECT_EQ(f.t, 1.0);
    ASSERT_EQ(r.next(f), read_result::error);
    EXPECT_EQ(r.line(), ++line);
    EXPECT_EQ(f.parts, 0u);
    const std::string prefix = "bad.jsonl:" + std::to_string(line) + ": ";
    EXPECT_EQ(r.error().rfind(prefix, 0), 0u) << r.error();
    EXPECT_NE(r.error().find(c.expected_in_error), std::string::npos) << r.error();
  }
  ASSERT_EQ(r.next(f), read_result::frame) << r.error();
  EXPECT_EQ(f.t, 2.0);
  EXPECT_TRUE(r.error().empty());
  EXPECT_EQ(r.next(f), read_result::end);
}

TEST(landmark_file, unknown_values_nest_up_to_256_levels) {
  for (int levels : {255, 256}) {
    const std::string text = "{\"t\":0.5,\"x\":" + std::string(levels, '[') +
                             std::string(levels, ']') + ",\"y\":" + std::string(levels, '[') + "1" +
                             std::string(levels, ']') + "}\n";
    landmark_reader r;
    ASSERT_TRUE(r.open_memory(text.data(), text.size()).ok());
    landmark_frame f;
    ASSERT_EQ(r.next(f), read_result::frame) << levels << ": " << r.error();
    EXPECT_EQ(f.t, 0.5);
  }
}

TEST(landmark_file, header_fps_too_small_for_the_frame_times) {
  // index / fps overflows to +inf from the second frame on: an error, not an infinite time.
  std::string text = "{\"format\":\"avatarmap.landmarks\",\"fps\":1e-310}\n{}\n{}\n";
  landmark_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size(), "tiny.jsonl").ok());
  landmark_frame f;
  ASSERT_EQ(r.next(f), read_result::frame);
  EXPECT_EQ(f.t, 0.0);
  ASSERT_EQ(r.next(f), read_result::error);
  EXPECT_NE(r.error().find("tiny.jsonl:3: the frame time"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("\"fps\" is too small"), std::string::npos) << r.error();
}

TEST(landmark_file, missing_t_uses_header_fps) {
  std::string text =
      "{\"format\":\"avatarmap.landmarks\",\"version\":1,\"fps\":4}\n{}\n\n{\"t\":7}\nbad\n{}\n";
  landmark_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size()).ok());
  EXPECT_EQ(r.header().fps, 4.0);
  landmark_frame f;
  ASSERT_EQ(r.next(f), read_result::frame);
  EXPECT_EQ(f.t, 0.0);
  ASSERT_EQ(r.next(f), read_result::frame);
  EXPECT_EQ(f.t, 7.0);
  ASSERT_EQ(r.next(f), read_result::error);
  ASSERT_EQ(r.next(f), read_result::frame);
  EXPECT_EQ(f.t, 0.75);  // frame index 3 (bad lines count too) / 4 fps
}

TEST(landmark_file, header_rules) {
  {
    std::string t = "{\"t\":0}\n";
    landmark_reader r;
    ASSERT_TRUE(r.open_memory(t.data(), t.size()).ok());
    EXPECT_FALSE(r.header().present);
    landmark_frame f;
    EXPECT_EQ(r.next(f), read_result::frame);
  }
  {
    std::string t =
        "\n  \n{\"version\":1,\"image_size\":[640,480],\"x\":[1],"
        "\"format\":\"avatarmap.landmarks\"}\n{\"t\":0}\n";
    landmark_reader r;
    ASSERT_TRUE(r.open_memory(t.data(), t.size()).ok());
    EXPECT_TRUE(r.header().present);
    EXPECT_EQ(r.header().image_width, 640);
    EXPECT_EQ(r.header().image_height, 480);
    EXPECT_EQ(r.header().fps, 0.0);
    landmark_frame f;
    EXPECT_EQ(r.next(f), read_result::frame);
    EXPECT_EQ(r.line(), 4);
  }
  struct {
    std::string line;
    const char* expected;
  } bad[] = {
      {"{\"format\":\"avatarmap.pose\",\"version\":1}", "wrong format \"avatarmap.pose\""},
      {"{\"format\":\"avatarmap.landmarks\",\"version\":3}", "version 3 is newer"},
      {"{\"format\":\"avatarmap.landmarks\",\"version\":0}", "\"version\" must be"},
      {"{\"format\":\"avatarmap.landmarks\",\"image_size\":[640]}", "\"image_size\" must be"},
      {"{\"format\":\"avatarmap.landmarks\",\"fps\":-1}", "\"fps\" must be"},
      {"{\"format\":7}", "expected a string"},
  };
  for (auto& b : bad) {
    SCOPED_TRACE(b.line);
    landmark_reader r;
    std::string t = b.line + "\n{\"t\":0}\n";
    status s = r.open_memory(t.data(), t.size(), "h.jsonl");
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.message().rfind("h.jsonl:1: bad header line", 0), 0u) << s.message();
    EXPECT_NE(s.message().find(b.expected), std::string::npos) << s.message();
  }
}

// Version 2 (several people): each line carries its person; the writer writes it only with a
// version-2 header, so a version-1 file's bytes do not change; the reader filters by person.
TEST(landmark_file, version_2_carries_a_person_per_line) {
  temp_dir dir;
  auto frames = make_frames(12, 3);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    frames[i].t = static_cast<double>(i / 3) / 30.0;  // three people per time
    frames[i].person = static_cast<int>(i % 3) * 7;   // ids 0, 7, 14
  }
  landmark_file_header h;
  h.version = 2;
  h.fps = 30.0;
  const std::string path = dir.file("three.landmarks.jsonl");
  {
    landmark_writer w;
    ASSERT_TRUE(w.open(path, h).ok());
    for (auto& f : frames) ASSERT_TRUE(w.write(f).ok());
    ASSERT_TRUE(w.commit().ok());
  }
  EXPECT_EQ(read_text(path).rfind("{\"format\":\"avatarmap.landmarks\",\"version\":2", 0), 0u);
  EXPECT_NE(read_text(path).find("{\"t\":0,\"person\":7,"), std::string::npos);
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  EXPECT_EQ(r.header().version, 2);
  landmark_frame f;
  for (const landmark_frame& want : frames) {
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    EXPECT_EQ(f.person, want.person);
    expect_same_frame(want, f);
  }
  EXPECT_EQ(r.next(f), read_result::end);
  // One person's lines only.
  landmark_reader one;
  ASSERT_TRUE(one.open(path).ok());
  one.set_person(7);
  for (int k = 0; k < 4; ++k) {
    ASSERT_EQ(one.next(f), read_result::frame) << one.error();
    EXPECT_EQ(f.person, 7);
    EXPECT_EQ(f.t, k / 30.0);
    expect_same_frame(frames[static_cast<std::size_t>(3 * k + 1)], f);
  }
  EXPECT_EQ(one.next(f), read_result::end);
  std::vector<int> ids;
  ASSERT_TRUE(people_in_file(path, ids).ok());
  EXPECT_EQ(ids, (std::vector<int>{0, 7, 14}));

  // The same frames through a version-1 writer: no person written, every line person 0.
  const std::string v1 = dir.file("one.landmarks.jsonl");
  {
    landmark_writer w;
    ASSERT_TRUE(w.open(v1, landmark_file_header{}).ok());
    for (auto& f2 : frames) ASSERT_TRUE(w.write(f2).ok());
    ASSERT_TRUE(w.commit().ok());
  }
  EXPECT_EQ(read_text(v1).find("person"), std::string::npos);
  ASSERT_TRUE(people_in_file(v1, ids).ok());
  EXPECT_EQ(ids, (std::vector<int>{0}));
  landmark_reader r1;
  ASSERT_TRUE(r1.open(v1).ok());
  r1.set_person(7);
  EXPECT_EQ(r1.next(f), read_result::end);

  // Bad persons, and a version-2 line without its time, name their line; reading goes on.
  const std::string bad =
      "{\"format\":\"avatarmap.landmarks\",\"version\":2,\"fps\":30}\n"
      "{\"t\":0,\"person\":-1}\n{\"t\":0,\"person\":1.5}\n{\"t\":0,\"person\":\"a\"}\n"
      "{\"t\":0,\"person\":1000000}\n{\"person\":2}\n{\"t\":0.5,\"person\":3}\n";
  landmark_reader rb;
  ASSERT_TRUE(rb.open_memory(bad.data(), bad.size(), "b.jsonl").ok());
  for (int line = 2; line <= 5; ++line) {
    ASSERT_EQ(rb.next(f), read_result::error) << line;
    EXPECT_EQ(rb.error().rfind("b.jsonl:" + std::to_string(line) + ":", 0), 0u) << rb.error();
    EXPECT_NE(rb.error().find("person"), std::string::npos) << rb.error();
  }
  ASSERT_EQ(rb.next(f), read_result::error);
  EXPECT_NE(rb.error().find("missing \"t\""), std::string::npos) << rb.error();
  ASSERT_EQ(rb.next(f), read_result::frame) << rb.error();
  EXPECT_EQ(f.person, 3);
  EXPECT_EQ(f.t, 0.5);
}

TEST(landmark_file, blank_lines_crlf_bom_and_last_line_without_newline) {
  temp_dir dir;
  const std::string path = dir.file("crlf.jsonl");
  std::string pose = points_json(33);
  write_text(path,
             "\xEF\xBB\xBF{\"format\":\"avatarmap.landmarks\",\"version\":1}\r\n\r\n"
             "{\"t\":1,\"pose\":" +
                 pose + "}\r\n   \r\n\t\n{\"t\":2}\r\n{\"t\":3}");
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  EXPECT_TRUE(r.header().present);
  landmark_frame f;
  ASSERT_EQ(r.next(f), read_result::frame) << r.error();
  EXPECT_EQ(r.line(), 3);
  EXPECT_TRUE(f.has(frame_part::pose));
  ASSERT_EQ(r.next(f), read_result::frame) << r.error();
  EXPECT_EQ(r.line(), 6);
  EXPECT_EQ(f.t, 2.0);
  ASSERT_EQ(r.next(f), read_result::frame) << r.error();
  EXPECT_EQ(r.line(), 7);
  EXPECT_EQ(f.t, 3.0);
  EXPECT_EQ(r.next(f), read_result::end);
}

TEST(landmark_file, truncated_last_line_is_an_error_with_its_line) {
  std::string text = "{\"t\":1}\n{\"t\":2,\"pose\":[[1,2,3],[1,2";
  landmark_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size(), "cut.jsonl").ok());
  landmark_frame f;
  ASSERT_EQ(r.next(f), read_result::frame);
  ASSERT_EQ(r.next(f), read_result::error);
  EXPECT_EQ(r.error().rfind("cut.jsonl:2: in \"pose\" point 1:", 0), 0u) << r.error();
  EXPECT_EQ(r.next(f), read_result::end);
}

TEST(landmark_file, lines_across_block_boundaries_read_the_same_for_every_block_size) {
  limits_guard guard;
  temp_dir dir;
  const std::string path = dir.file("blocks.jsonl");
  auto frames = make_frames(6, 3);
  {
    landmark_writer w;
    ASSERT_TRUE(w.open(path, {}).ok());
    for (auto& f : frames) ASSERT_TRUE(w.write(f).ok());
    ASSERT_TRUE(w.commit().ok());
  }
  // Add blank lines and CRLF so that line ends fall on every kind of boundary.
  std::string text = read_text(path);
  std::string crlf;
  for (char c : text) {
    if (c == '\n')
      crlf += "\r\n\n";
    else
      crlf += c;
  }
  write_text(path, crlf);
  for (std::size_t block : {1u, 2u, 7u, 100u, 4093u, 65536u}) {
    SCOPED_TRACE("block " + std::to_string(block));
    io_detail::default_line_source_limits().block_size = block;
    landmark_reader r;
    ASSERT_TRUE(r.open(path).ok());
    EXPECT_TRUE(r.header().present);
    landmark_frame f;
    for (auto& expected : frames) {
      ASSERT_EQ(r.next(f), read_result::frame) << r.error();
      expect_same_frame(expected, f);
    }
    EXPECT_EQ(r.next(f), read_result::end);
  }
}

TEST(landmark_file, very_long_lines_and_the_line_cap) {
  limits_guard guard;
  temp_dir dir;
  const std::string path = dir.file("long.jsonl");
  // A 3 MiB line (an unknown key with a long string) spans several 1 MiB blocks.
  std::string big(3u << 20, 'x');
  write_text(path,
             "{\"t\":1,\"junk\":\"" + big + "\",\"pose\":" + points_json(33) + "}\n{\"t\":2}\n");
  {
    landmark_reader r;
    ASSERT_TRUE(r.open(path).ok());
    landmark_frame f;
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    EXPECT_TRUE(f.has(frame_part::pose));
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    EXPECT_EQ(f.t, 2.0);
  }
  // Over the cap: an error for that line, then the next line reads normally.
  io_detail::default_line_source_limits().block_size = 4096;
  io_detail::default_line_source_limits().max_line = 100000;
  for (int first_line_long = 0; first_line_long < 2; ++first_line_long) {
    write_text(path, std::string(first_line_long ? "" : "{\"t\":0}\n") + "{\"t\":1,\"junk\":\"" +
                         big + "\"}\n{\"t\":2}\n{\"t\":3,\"junk\":\"" + big + "\"}");
    landmark_reader r;
    ASSERT_TRUE(r.open(path).ok());
    landmark_frame f;
    long line = 0;
    if (!first_line_long) {
      ASSERT_EQ(r.next(f), read_result::frame) << r.error();
      ++line;
    }
    ASSERT_EQ(r.next(f), read_result::error);
    EXPECT_EQ(r.line(), ++line);
    EXPECT_NE(r.error().find("longer than 100000 bytes"), std::string::npos) << r.error();
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    EXPECT_EQ(r.line(), ++line);
    EXPECT_EQ(f.t, 2.0);
    ASSERT_EQ(r.next(f), read_result::error);
    EXPECT_EQ(r.line(), ++line);
    EXPECT_EQ(r.next(f), read_result::end);
  }
}

TEST(landmark_file, open_errors) {
  landmark_reader r;
  status s = r.open("/nonexistent/dir/x.jsonl");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/nonexistent/dir/x.jsonl: cannot open"), std::string::npos);
  landmark_writer w;
  s = w.open("/nonexistent/dir/x.jsonl", {});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/nonexistent/dir/x.jsonl"), std::string::npos);
  landmark_reader empty;
  landmark_frame f;
  ASSERT_TRUE(empty.open_memory("", 0).ok());
  EXPECT_EQ(empty.next(f), read_result::end);
}

TEST(landmark_file, writes_are_atomic) {
  temp_dir dir;
  const std::string path = dir.file("target.landmarks.jsonl");
  write_text(path, "old contents\n");
  auto frames = make_frames(3, 11);
  {
    landmark_writer w;
    ASSERT_TRUE(w.open(path, {}).ok());
    for (auto& f : frames) ASSERT_TRUE(w.write(f).ok());
    EXPECT_EQ(dir.entries().size(), 2u);  // target + temporary file
    EXPECT_EQ(read_text(path), "old contents\n");
  }  // destroyed without commit
  EXPECT_EQ(read_text(path), "old contents\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"target.landmarks.jsonl"});
  {
    landmark_writer w;
    ASSERT_TRUE(w.open(path, {}).ok());
    for (auto& f : frames) ASSERT_TRUE(w.write(f).ok());
    ASSERT_TRUE(w.commit().ok());
  }
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"target.landmarks.jsonl"});
  landmark_reader r;
  ASSERT_TRUE(r.open(path).ok());
  landmark_frame f;
  for (auto& e : frames) {
    ASSERT_EQ(r.next(f), read_result::frame) << r.error();
    expect_same_frame(e, f);
  }
}

}  // namespace
}  // namespace avatarmap
