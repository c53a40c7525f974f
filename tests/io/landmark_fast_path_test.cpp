// The landmark reader's compact-point path and vector number path (io/json_number.hpp) must
// not change what is read: the same frames bit for bit as nlohmann-json's reading of the same
// lines, and for any line (good or damaged) the same result and error message as the digit
// path alone.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/tfjs_import.hpp"
#include "avatarmap/synth/synth_recording.hpp"
#include "io/json_number.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

using test::read_text;
using test::temp_dir;

struct vector_path_guard {
  bool saved = io_detail::json_vector_path();
  ~vector_path_guard() { io_detail::json_vector_path() = saved; }
};

std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

// Every point of every part of a frame, as bits (NaN as one pattern), for comparisons.
std::vector<std::uint32_t> frame_bits(const landmark_frame& f) {
  std::vector<std::uint32_t> out;
  std::uint64_t t;
  std::memcpy(&t, &f.t, 8);
  out.push_back(static_cast<std::uint32_t>(t));
  out.push_back(static_cast<std::uint32_t>(t >> 32));
  out.push_back(f.parts);
  out.push_back(static_cast<std::uint32_t>(f.face_count));
  auto add = [&](const landmark* p, int n) {
    for (int i = 0; i < n; ++i)
      for (float v : {p[i].x, p[i].y, p[i].z, p[i].visibility, p[i].presence})
        out.push_back(std::isnan(v) ? 0x7fc00000u : bits(v));
  };
  if (f.has(frame_part::pose)) add(f.pose.data(), k_pose_landmark_count);
  if (f.has(frame_part::pose_world)) add(f.pose_world.data(), k_pose_landmark_count);
  if (f.has(frame_part::left_hand)) add(f.left_hand.data(), k_hand_landmark_count);
  if (f.has(frame_part::left_hand_world)) add(f.left_hand_world.data(), k_hand_landmark_count);
  if (f.has(frame_part::right_hand)) add(f.right_hand.data(), k_hand_landmark_count);
  if (f.has(frame_part::right_hand_world)) add(f.right_hand_world.data(), k_hand_landmark_count);
  if (f.has(frame_part::face)) add(f.face.data(), f.face_count);
  return out;
}

struct read_outcome {
  read_result result;
  std::vector<std::uint32_t> frame;
  std::string error;
};

// Reads the single frame line `line` (after a header giving fps, so that "t" may be missing).
read_outcome read_line(const std::string& line, bool vector) {
  vector_path_guard guard;
  io_detail::json_vector_path() = vector;
  const std::string text = "{\"format\":\"avatarmap.landmarks\",\"version\":1,\"fps\":30}\n" + line;
  landmark_reader r;
  EXPECT_TRUE(r.open_memory(text.data(), text.size(), "m.jsonl").ok());
  landmark_frame f;
  read_outcome o;
  o.result = r.next(f);
  o.frame = frame_bits(f);
  o.error = r.error();
  return o;
}

// Lines as the writer writes them: random floats of the landmark files' ranges (and every
// magnitude), the synthetic noisy scenario, and, with the shared data, Google's squat
// landmarks imported from tfjs-models.
std::vector<std::string> written_lines() {
  temp_dir dir;
  const std::string path = dir.file("corpus.landmarks.jsonl");
  std::vector<std::string> lines;
  auto add_file = [&](const std::string& p) {
    std::istringstream in(read_text(p));
    std::string line;
    std::getline(in, line);  // the header
    while (std::getline(in, line)) lines.push_back(line);
  };
  {
    landmark_writer w;
    EXPECT_TRUE(w.open(path, {}).ok());
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> unit(0.f, 1.f), world(-1.f, 1.f);
    std::uniform_int_distribution<std::uint32_t> any;
    synth_recording synth(synth_scenario_options(synth_scenario::noisy, 3));
    proxy_pose truth;
    landmark_frame f;
    for (int i = 0; i < 24; ++i) {
      synth.generate(i / 30.0, truth, f);
      if (i % 3 == 1) {
        // Random values: image-like, world-like and any bit pattern.
        auto fill = [&](landmark* p, int n) {
          for (int k = 0; k < n; ++k) {
            float* v[5] = {&p[k].x, &p[k].y, &p[k].z, &p[k].visibility, &p[k].presence};
            for (float* x : v) {
              const int kind = static_cast<int>(any(rng) % 8);
              if (kind == 0) {
                const std::uint32_t u = any(rng);
                std::memcpy(x, &u, 4);
              } else {
                *x = kind < 4 ? unit(rng) : world(rng) * (kind == 7 ? 1e-3f : 1.f);
              }
            }
          }
        };
        fill(f.pose.data(), 33);
        fill(f.pose_world.data(), 33);
        fill(f.face.data(), 478);
      }
      if (i % 5 == 2) f.set(frame_part::left_hand, false);
      if (i % 7 == 3) f.face_count = k_face_mesh_count;
      EXPECT_TRUE(w.write(f).ok());
    }
    EXPECT_TRUE(w.commit().ok());
  }
  add_file(path);
  if (!test::test_data_dir().empty()) {
    const std::string squats = dir.file("squats.landmarks.jsonl");
    EXPECT_TRUE(
        import_tfjs_pose(test::test_data_path("motion/tfjs-models/pose_squats.full.json"),
                         test::test_data_path("motion/tfjs-models/pose_squats_3d.full.json"), 720,
                         1280, 5.0, squats)
            .ok());
    add_file(squats);
  }
  return lines;
}

// A float decoded by nlohmann-json (strtod: correctly rounded double) and rounded to float.
// The same as the correctly rounded float unless the double lies exactly halfway between
// two floats; the corpus has none (checked).
float from_json(const nlohmann::json& v, bool& midpoint) {
  if (v.is_null()) return std::numeric_limits<float>::quiet_NaN();
  const double d = v.get<double>();
  std::uint64_t b;
  std::memcpy(&b, &d, 8);
  if (std::isfinite(d) && std::abs(d) < 3e38 && (b & 0x1fffffffu) == 0x10000000u) midpoint = true;
  return static_cast<float>(d);
}

TEST(landmark_fast_path, frames_equal_nlohmann_json_reading) {
  const auto lines = written_lines();
  ASSERT_GE(lines.size(), 24u);
  for (std::size_t n = 0; n < lines.size(); ++n) {
    SCOPED_TRACE("line " + std::to_string(n));
    const auto j = nlohmann::json::parse(lines[n]);
    landmark_frame expected;
    expected.t = j.at("t").get<double>();
    bool midpoint = false;
    for (int p = 0; p < k_frame_part_count; ++p) {
      const auto part = static_cast<frame_part>(p);
      const std::string key(frame_part_key(part));
      if (!j.contains(key) || j[key].is_null()) continue;
      landmark* dst = nullptr;
      switch (part) {
        case frame_part::pose:
          dst = expected.pose.data();
          break;
        case frame_part::pose_world:
          dst = expected.pose_world.data();
          break;
        case frame_part::left_hand:
          dst = expected.left_hand.data();
          break;
        case frame_part::left_hand_world:
          dst = expected.left_hand_world.data();
          break;
        case frame_part::right_hand:
          dst = expected.right_hand.data();
          break;
        case frame_part::right_hand_world:
          dst = expected.right_hand_world.data();
          break;
        case frame_part::face:
          dst = expected.face.data();
          break;
      }
      const auto& points = j[key];
      for (std::size_t i = 0; i < points.size(); ++i) {
        const auto& pt = points[i];
        dst[i].x = from_json(pt[0], midpoint);
        dst[i].y = from_json(pt[1], midpoint);
        dst[i].z = from_json(pt[2], midpoint);
        dst[i].visibility = pt.size() > 3 ? from_json(pt[3], midpoint) : 1.f;
        dst[i].presence = pt.size() > 4 ? from_json(pt[4], midpoint) : 1.f;
      }
      if (part == frame_part::face) expected.face_count = static_cast<int>(points.size());
      expected.set(part, true);
    }
    ASSERT_FALSE(midpoint);
    const read_outcome got = read_line(lines[n], true);
    ASSERT_EQ(got.result, read_result::frame) << got.error;
    EXPECT_EQ(got.frame, frame_bits(expected));
  }
}

// Damaged copies of written lines (a byte replaced, inserted, deleted or a value's text
// swapped for another token): both paths give the same frame or the same message.
TEST(landmark_fast_path, damaged_lines_read_the_same_on_both_paths) {
  const auto lines = written_lines();
  const std::vector<std::string> tokens = {" ",
                                           "\t",
                                           ",",
                                           "[",
                                           "]",
                                           "{",
                                           "}",
                                           "\"",
                                           ":",
                                           "-",
                                           ".",
                                           "e",
                                           "E",
                                           "+",
                                           "0",
                                           "1",
                                           "9",
                                           "null",
                                           "NaN",
                                           "Infinity",
                                           "-0",
                                           "1e5",
                                           "1.",
                                           "01",
                                           ".5",
                                           "1e",
                                           "0.5 ",
                                           " 0.5",
                                           "[]",
                                           "[1,2]",
                                           "[1,2,3,4,5,6]",
                                           "1.00000000000000000001",
                                           "\x01",
                                           "\xff"};
  std::mt19937 rng(29);
  long frames = 0, errors = 0;
  for (int m = 0; m < 4000; ++m) {
    std::string line = lines[static_cast<std::size_t>(m) % lines.size()];
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % line.size();
      const std::string& tok = tokens[rng() % tokens.size()];
      switch (rng() % 4) {
        case 0:
          line.replace(at, 1, tok);
          break;
        case 1:
          line.insert(at, tok);
          break;
        case 2:
          line.erase(at, 1 + rng() % 4);
          break;
        default: {
          // Replace a whole number token.
          std::size_t b = at;
          while (b < line.size() && !(line[b] == '-' || (line[b] >= '0' && line[b] <= '9'))) ++b;
          std::size_t e2 = b;
          while (e2 < line.size() && line[e2] != ',' && line[e2] != ']') ++e2;
          if (b < line.size()) line.replace(b, e2 - b, tok);
        }
      }
      if (line.empty()) line = "{";
    }
    const read_outcome v = read_line(line, true);
    const read_outcome d = read_line(line, false);
    ASSERT_EQ(v.result, d.result) << line.substr(0, 200) << "\n" << v.error << "\n" << d.error;
    ASSERT_EQ(v.error, d.error);
    ASSERT_EQ(v.frame, d.frame);
    (v.result == read_result::frame ? frames : errors)++;
  }
  // Both outcomes are well represented.
  EXPECT_GT(frames, 400);
  EXPECT_GT(errors, 400);
}

}  // namespace
}  // namespace avatarmap
