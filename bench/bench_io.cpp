// Throughput of the *.landmarks.jsonl reader and the *.pose.jsonl writer (frames/s and
// bytes/s). Inputs are generated in memory with the library's own writers. Baselines:
// nlohmann::json parsing the same lines (parse only, without converting to frames), the
// reader's digit-at-a-time number path alone (io/json_number.hpp), and memchr over the text
// (finding the line ends: the floor of any line reader). A build with
// -DAVATARMAP_WITH_SIMDJSON=ON measures simdjson's on-demand parser in place of ours.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/synth/synth_recording.hpp"
#include "io/json_number.hpp"

namespace avatarmap {
namespace {

constexpr int k_frames = 2000;

std::string temp_path(const char* name) {
  return "/tmp/avatarmap_bench_io_" + std::to_string(::getpid()) + "_" + name;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A landmarks file with `frames` frames like a real capture's: image points in [0, 1],
// world points within a metre, visibility/presence in [0, 1], full float precision.
std::string make_landmark_text(int frames, bool all_parts) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u01(0.f, 1.f), um(-1.f, 1.f);
  auto fill = [&](landmark* p, int n, bool image) {
    for (int i = 0; i < n; ++i)
      p[i] = {image ? u01(rng) : um(rng), image ? u01(rng) : um(rng), um(rng) * 0.1f, u01(rng),
              u01(rng)};
  };
  auto fill3 = [&](landmark* p, int n, bool image) {
    fill(p, n, image);
    for (int i = 0; i < n; ++i) p[i].visibility = p[i].presence = 1.f;
  };
  const std::string path = temp_path("lm.jsonl");
  landmark_writer w;
  landmark_file_header h;
  h.image_width = 1280;
  h.image_height = 720;
  h.fps = 30;
  if (!w.open(path, h)) return {};
  landmark_frame f;
  for (int i = 0; i < frames; ++i) {
    f.clear();
    f.t = i / 30.0;
    fill(f.pose.data(), 33, true);
    fill(f.pose_world.data(), 33, false);
    f.set(frame_part::pose, true);
    f.set(frame_part::pose_world, true);
    if (all_parts) {
      fill3(f.left_hand.data(), 21, true);
      fill3(f.left_hand_world.data(), 21, false);
      fill3(f.right_hand.data(), 21, true);
      fill3(f.right_hand_world.data(), 21, false);
      fill3(f.face.data(), 478, true);
      f.face_count = 478;
      f.parts = (1u << k_frame_part_count) - 1;
    }
    (void)w.write(f);
  }
  (void)w.commit();
  std::string text = slurp(path);
  std::remove(path.c_str());
  return text;
}

// A full holistic recording as `avatarmap synth --scenario noisy` writes it (~23 kB a frame).
std::string make_holistic_text(int frames) {
  const std::string path = temp_path("holistic.jsonl");
  landmark_writer w;
  landmark_file_header h;
  h.image_width = 1280;
  h.image_height = 720;
  h.fps = 30;
  if (!w.open(path, h)) return {};
  synth_recording synth(synth_scenario_options(synth_scenario::noisy, 7));
  proxy_pose truth;
  landmark_frame f;
  for (int i = 0; i < frames; ++i) {
    synth.generate(i / 30.0, truth, f);
    (void)w.write(f);
  }
  (void)w.commit();
  std::string text = slurp(path);
  std::remove(path.c_str());
  return text;
}

void parse_text(benchmark::State& state, const std::string& text) {
  landmark_frame f;
  std::int64_t frames = 0;
  for (auto _ : state) {
    landmark_reader r;
    if (!r.open_memory(text.data(), text.size())) state.SkipWithError("open failed");
    int n = 0;
    while (r.next(f) == read_result::frame) ++n;
    if (n != k_frames) state.SkipWithError("wrong frame count");
    frames += n;
    benchmark::DoNotOptimize(f);
  }
  state.SetItemsProcessed(frames);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(text.size()));
  state.counters["bytes_per_frame"] = static_cast<double>(text.size()) / k_frames;
}

void parse_memory(benchmark::State& state, bool all_parts) {
  parse_text(state, make_landmark_text(k_frames, all_parts));
}

// items_per_second = frames/s.
void BM_parse_landmarks_pose_only(benchmark::State& state) { parse_memory(state, false); }
void BM_parse_landmarks_all_parts(benchmark::State& state) { parse_memory(state, true); }

// The synthetic holistic recording; range(0) = 0: the digit path alone (no vector number
// path, no compact point path).
void BM_parse_landmarks_holistic(benchmark::State& state) {
  const bool saved = io_detail::json_vector_path();
  io_detail::json_vector_path() = state.range(0) != 0;
  parse_text(state, make_holistic_text(k_frames));
  io_detail::json_vector_path() = saved;
}

// Floor: finding the line ends of the same text (what any line reader does first).
void BM_find_line_ends_holistic(benchmark::State& state) {
  const std::string text = make_holistic_text(k_frames);
  std::int64_t lines = 0;
  for (auto _ : state) {
    const char* p = text.data();
    const char* end = p + text.size();
    while (const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p))) {
      p = static_cast<const char*>(nl) + 1;
      ++lines;
    }
    benchmark::DoNotOptimize(p);
  }
  state.SetItemsProcessed(lines);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(text.size()));
}

// The same through a real file (block reads included).
void BM_parse_landmarks_pose_only_file(benchmark::State& state) {
  const std::string text = make_landmark_text(k_frames, false);
  const std::string path = temp_path("read.jsonl");
  std::ofstream(path, std::ios::binary) << text;
  landmark_frame f;
  std::int64_t frames = 0;
  for (auto _ : state) {
    landmark_reader r;
    if (!r.open(path)) state.SkipWithError("open failed");
    while (r.next(f) == read_result::frame) ++frames;
  }
  std::remove(path.c_str());
  state.SetItemsProcessed(frames);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(text.size()));
}

// Baseline: nlohmann::json DOM parse of the same lines (no conversion to frames).
void BM_parse_landmarks_pose_only_nlohmann(benchmark::State& state) {
  const std::string text = make_landmark_text(k_frames, false);
  std::int64_t frames = 0;
  for (auto _ : state) {
    std::size_t pos = text.find('\n') + 1;  // skip the header
    while (pos < text.size()) {
      std::size_t e = text.find('\n', pos);
      auto j = nlohmann::json::parse(text.begin() + static_cast<std::ptrdiff_t>(pos),
                                     text.begin() + static_cast<std::ptrdiff_t>(e));
      benchmark::DoNotOptimize(j);
      pos = e + 1;
      ++frames;
    }
  }
  state.SetItemsProcessed(frames);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(text.size()));
}

// Writing pose lines (all 55 bones, 16 expressions) to a file; formatting and write(2)
// only: the writer is dropped without commit() so no fsync or rename is timed.
// state.range(0): 1 = every bone rotated and every expression non-zero (worst case);
// 0 = a body-only capture: the 25 body bones rotated, fingers at identity, expressions 0.
void BM_write_pose_lines(benchmark::State& state) {
  const bool all_bones = state.range(0) != 0;
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<proxy_pose> poses(64);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    poses[i].t = static_cast<double>(i) / 30.0;
    poses[i].hips_position = glm::vec3(g(rng), g(rng), g(rng));
    for (int b = 0; b < (all_bones ? k_bone_count : idx(bone::left_thumb_metacarpal)); ++b)
      poses[i].rotations[b] = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
    if (all_bones)
      for (auto& e : poses[i].expressions) e = std::abs(g(rng)) * 0.3f;
  }
  const std::string path = temp_path("w.pose.jsonl");
  std::int64_t frames = 0;
  for (auto _ : state) {
    pose_writer w;
    if (!w.open(path, pose_file_header{})) state.SkipWithError("open failed");
    for (int i = 0; i < k_frames; ++i) (void)w.write(poses[static_cast<std::size_t>(i) & 63]);
    frames += k_frames;
  }
  state.SetItemsProcessed(frames);
  // Bytes per frame, measured once.
  pose_writer w;
  (void)w.open(path, pose_file_header{});
  for (int i = 0; i < k_frames; ++i) (void)w.write(poses[static_cast<std::size_t>(i) & 63]);
  (void)w.commit();
  std::size_t bytes = slurp(path).size();
  std::remove(path.c_str());
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(bytes));
  state.counters["bytes_per_frame"] = static_cast<double>(bytes) / k_frames;
}

// Writing landmark lines (pose + pose_world).
void BM_write_landmarks_pose_only(benchmark::State& state) {
  const std::string text = make_landmark_text(64, false);
  std::vector<landmark_frame> frames;
  landmark_reader r;
  (void)r.open_memory(text.data(), text.size());
  landmark_frame f;
  while (r.next(f) == read_result::frame) frames.push_back(f);
  const std::string path = temp_path("w.landmarks.jsonl");
  std::int64_t n = 0;
  for (auto _ : state) {
    landmark_writer w;
    if (!w.open(path, {})) state.SkipWithError("open failed");
    for (int i = 0; i < k_frames; ++i) (void)w.write(frames[static_cast<std::size_t>(i) & 63]);
    n += k_frames;
  }
  state.SetItemsProcessed(n);
}

BENCHMARK(BM_parse_landmarks_pose_only)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_parse_landmarks_pose_only_file)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_parse_landmarks_pose_only_nlohmann)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_parse_landmarks_all_parts)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_parse_landmarks_holistic)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_find_line_ends_holistic)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_write_pose_lines)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_write_landmarks_pose_only)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace avatarmap

BENCHMARK_MAIN();
