// Whole-array calls of the C API (avatarmap.h): what solving N frames held in memory costs per
// frame through avm_solve_frames (the figure a binding's overhead is measured against), beside
// the same job in C++ with the frames already as landmark frames (the floor: the block's
// conversion and the C boundary are the difference), avm_solver_push frame by frame, and
// avm_landmark_reader_read's reading of the same frames from a file. Frames: the scripted demo
// motion with full hands and a 478-point face, 1280x720, 30 fps. Counter per_frame = seconds
// per frame (printed as e.g. "7.5u": microseconds).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "avatarmap/avatarmap.h"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"

namespace {

using namespace avatarmap;

constexpr double k_fps = 30.0;

std::vector<landmark_frame> make_frames(int n) {
  synth_options o;
  o.body_noise_sigma = 0.003f;
  o.hand_noise_sigma = 0.001f;
  o.face_noise_sigma = 0.001f;
  landmark_synth synth(o);
  std::vector<landmark_frame> frames(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = i / k_fps;
    synth.generate(demo_motion_pose(t), frames[static_cast<std::size_t>(i)]);
    frames[static_cast<std::size_t>(i)].t = t;
  }
  return frames;
}

// The frames as a frame block's arrays (structure of arrays, NaN where a part is missing).
struct block_storage {
  std::vector<double> t;
  std::vector<float> parts[k_frame_part_count];
  avm_frame_block block{};

  explicit block_storage(const std::vector<landmark_frame>& frames) {
    const int sizes[k_frame_part_count] = {33, 33, 21, 21, 21, 21, 478};
    const auto n = frames.size();
    t.resize(n);
    for (int p = 0; p < k_frame_part_count; ++p)
      parts[p].assign(n * static_cast<std::size_t>(sizes[p]) * 5,
                      std::numeric_limits<float>::quiet_NaN());
    for (std::size_t i = 0; i < n; ++i) {
      const landmark_frame& f = frames[i];
      t[i] = f.t;
      const landmark* src[k_frame_part_count] = {f.pose.data(),       f.pose_world.data(),
                                                 f.left_hand.data(),  f.left_hand_world.data(),
                                                 f.right_hand.data(), f.right_hand_world.data(),
                                                 f.face.data()};
      for (int p = 0; p < k_frame_part_count; ++p) {
        if (!f.has(static_cast<frame_part>(p))) continue;
        const int count = p == 6 ? f.face_count : sizes[p];
        float* dst = parts[p].data() + i * static_cast<std::size_t>(sizes[p]) * 5;
        for (int k = 0; k < count; ++k) {
          dst[5 * k + 0] = src[p][k].x;
          dst[5 * k + 1] = src[p][k].y;
          dst[5 * k + 2] = src[p][k].z;
          dst[5 * k + 3] = src[p][k].visibility;
          dst[5 * k + 4] = src[p][k].presence;
        }
      }
    }
    block.struct_size = sizeof block;
    block.count = static_cast<int64_t>(n);
    block.t = t.data();
    block.pose = parts[0].data();
    block.pose_world = parts[1].data();
    block.left_hand = parts[2].data();
    block.left_hand_world = parts[3].data();
    block.right_hand = parts[4].data();
    block.right_hand_world = parts[5].data();
    block.face = parts[6].data();
  }
};

void set_per_frame(benchmark::State& state, int n) {
  state.counters["per_frame"] =
      benchmark::Counter(static_cast<double>(n) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * n);
}

avm_solver_options c_options(int filter) {
  avm_solver_options o;
  avm_solver_options_init(&o);
  o.image_width = 1280.f;
  o.image_height = 720.f;
  o.file_filter = filter;
  return o;
}

// avm_solve_frames on N frames; arg 1 = the file filter (0 offline, 1 live, 2 none).
void BM_c_solve_frames(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const block_storage b(make_frames(n));
  const avm_solver_options o = c_options(static_cast<int>(state.range(1)));
  std::vector<avm_pose> poses(static_cast<std::size_t>(n));
  char err[256];
  for (auto _ : state) {
    if (avm_solve_frames(&b.block, &o, poses.data(), err, sizeof err) != AVM_OK) {
      state.SkipWithError(err);
      break;
    }
    benchmark::DoNotOptimize(poses.data());
  }
  set_per_frame(state, n);
}

// The same job in C++ on landmark frames (no block conversion, no C boundary): the floor.
void BM_cpp_solve_job_source(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<landmark_frame> frames = make_frames(n);
  std::vector<proxy_pose> poses(static_cast<std::size_t>(n));
  solve_file_job job;
  job.image_width = 1280.f;
  job.image_height = 720.f;
  job.filter_mode = static_cast<pose_filter_mode>(state.range(1));
  job.threads = 1;
  std::size_t next = 0, out = 0;
  job.source = [&](landmark_frame& f, bool& end) {
    end = next == frames.size();
    if (!end) f = frames[next++];
    return status{};
  };
  job.sink = [&](const proxy_pose& p) {
    poses[out++] = p;
    return status{};
  };
  for (auto _ : state) {
    next = out = 0;
    solve_file_summary s;
    if (!job.run(s).ok()) {
      state.SkipWithError("job failed");
      break;
    }
    benchmark::DoNotOptimize(poses.data());
  }
  set_per_frame(state, n);
}

// avm_solver_push + avm_solver_get_pose per frame (the per-frame C API, live filter).
void BM_c_solver_push(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<landmark_frame> frames = make_frames(n);
  std::vector<avm_landmark> points;  // the frames as avm_landmark arrays
  points.reserve(frames.size() * 632);
  std::vector<avm_frame> c_frames(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const landmark_frame& f = frames[i];
    auto put = [&](const landmark* src, int count) {
      const avm_landmark* start = points.data() + points.size();
      for (int k = 0; k < count; ++k)
        points.push_back({src[k].x, src[k].y, src[k].z, src[k].visibility, src[k].presence});
      return start;
    };
    avm_frame& c = c_frames[i];
    c.t = f.t;
    c.pose = put(f.pose.data(), 33);
    c.pose_world = put(f.pose_world.data(), 33);
    c.left_hand = put(f.left_hand.data(), 21);
    c.left_hand_world = put(f.left_hand_world.data(), 21);
    c.right_hand = put(f.right_hand.data(), 21);
    c.right_hand_world = put(f.right_hand_world.data(), 21);
    c.face = put(f.face.data(), f.face_count);
    c.face_count = f.face_count;
  }
  const avm_solver_options o = c_options(AVM_FILE_FILTER_LIVE);
  avm_solver* solver = nullptr;
  avm_solver_create(&o, &solver);
  avm_pose pose;
  for (auto _ : state) {
    avm_solver_reset(solver);
    for (const avm_frame& f : c_frames) {
      avm_solver_push(solver, &f);
      avm_solver_get_pose(solver, &pose);
    }
    benchmark::DoNotOptimize(pose);
  }
  avm_solver_destroy(solver);
  set_per_frame(state, n);
}

// avm_landmark_reader_read of the same frames from a *.landmarks.jsonl, one block.
void BM_c_landmark_reader(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<landmark_frame> frames = make_frames(n);
  const std::string path = "bench_c_api." + std::to_string(n) + ".landmarks.jsonl";
  {
    landmark_writer w;
    landmark_file_header h;
    h.image_width = 1280;
    h.image_height = 720;
    h.fps = k_fps;
    if (!w.open(path, h).ok()) {
      state.SkipWithError("cannot write the landmark file");
      return;
    }
    for (const landmark_frame& f : frames) w.write(f);
    w.commit();
  }
  block_storage b(frames);
  for (auto _ : state) {
    avm_landmark_reader* r = nullptr;
    int64_t got = 0;
    avm_landmark_reader_open(path.c_str(), &r);
    avm_landmark_reader_read(r, &b.block, &got);
    avm_landmark_reader_destroy(r);
    if (got != n) {
      state.SkipWithError("short read");
      break;
    }
  }
  std::remove(path.c_str());
  set_per_frame(state, n);
}

}  // namespace

BENCHMARK(BM_c_solve_frames)
    ->ArgsProduct({{300, 3000}, {0, 1, 2}})
    ->ArgNames({"frames", "filter"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_cpp_solve_job_source)
    ->ArgsProduct({{3000}, {0, 1, 2}})
    ->ArgNames({"frames", "filter"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_c_solver_push)->Arg(3000)->ArgName("frames")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_c_landmark_reader)->Arg(3000)->ArgName("frames")->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
