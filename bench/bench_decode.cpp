// Cost of decoding to RGB8 with video_source (FFmpeg: demux + decode + swscale), per frame:
// pose_squats.mp4 (720 x 1280 H.264, 65 frames) with 1 decoder thread (the default: the
// estimator has the other core) and 2; a 1000 x 667 JPEG photo; and the physical floor, a
// memcpy of one 720 x 1280 RGB frame. Counter: frames/s. Needs $AVATARMAP_TEST_DATA (the
// file benchmarks are skipped without it) and a build with FFmpeg.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "avatarmap/media/video_source.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

// Decodes all of `name` per iteration (open included); counts frames.
void run_decode(benchmark::State& state, const char* name, int threads) {
  const std::string dir = test::test_data_path("motion/tfjs-models/");
  if (dir.empty()) {
    state.SkipWithError("AVATARMAP_TEST_DATA is not set");
    return;
  }
  if (!video_source_available()) {
    state.SkipWithError("built without FFmpeg");
    return;
  }
  video_source_options options;
  options.max_threads = threads;
  video_source src;
  std::int64_t frames = 0;
  std::uint64_t checksum = 0;
  for (auto _ : state) {
    const status st = src.open(dir + name, options);
    if (!st) {
      state.SkipWithError(st.message().c_str());
      break;
    }
    image_view v;
    double t = 0.0;
    for (;;) {
      const read_result r = src.next(v, t);
      if (r == read_result::end) break;
      if (r == read_result::error) {
        state.SkipWithError(src.error().c_str());
        break;
      }
      checksum += v.data[(v.height / 2) * v.stride_bytes + v.width / 2 * 3];
      ++frames;
    }
  }
  benchmark::DoNotOptimize(checksum);
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}

void BM_decode_pose_squats_mp4(benchmark::State& state) {
  run_decode(state, "pose_squats.mp4", static_cast<int>(state.range(0)));
}
BENCHMARK(BM_decode_pose_squats_mp4)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_decode_pose_jpg(benchmark::State& state) { run_decode(state, "pose.jpg", 1); }
BENCHMARK(BM_decode_pose_jpg)->Unit(benchmark::kMillisecond);

// The floor: copying one decoded 720 x 1280 RGB frame.
void BM_memcpy_rgb_frame(benchmark::State& state) {
  const std::size_t size = 720u * 1280u * 3u;
  std::vector<std::uint8_t> a(size, 1), b(size);
  std::int64_t frames = 0;
  for (auto _ : state) {
    std::memcpy(b.data(), a.data(), size);
    benchmark::ClobberMemory();
    ++frames;
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_memcpy_rgb_frame);

}  // namespace
}  // namespace avatarmap

BENCHMARK_MAIN();
