// Cost of the capture crop (MediaPipe's ImageToTensor): a 1280 x 720 frame -> a rotated,
// letterboxed 256 x 256 x 3 float tensor, as the pose landmark model takes it. Counters: ns
// per crop (the time column) and bytes/s of tensor written. Baselines: a memcpy of the
// tensor's bytes (the store floor) and the same crop without rotation.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "avatarmap/capture/image_crop.hpp"
#include "avatarmap/capture/low_light.hpp"

namespace avatarmap {
namespace {

constexpr int k_width = 1280;
constexpr int k_height = 720;

struct frame {
  std::vector<std::uint8_t> pixels;
  image_view view;
};

frame make_frame(pixel_format format, int channels) {
  frame f;
  f.pixels.resize(static_cast<std::size_t>(k_width) * k_height * channels);
  std::mt19937 rng(7);
  for (auto& p : f.pixels) p = static_cast<std::uint8_t>(rng());
  f.view = {f.pixels.data(), k_width, k_height, k_width * channels, format};
  return f;
}

// A pose-like ROI: square in pixels (500 px), partly outside the frame at the bottom.
normalized_rect pose_roi(float rotation) {
  return {0.55f, 0.6f, 500.0f / k_width, 500.0f / k_height, rotation};
}

void run_crop(benchmark::State& state, pixel_format format, int channels, float rotation,
              crop_border border, crop_sampling sampling = crop_sampling::opencv) {
  const frame f = make_frame(format, channels);
  crop_options o;
  o.output_width = 256;
  o.output_height = 256;
  o.range_min = 0.0f;
  o.range_max = 1.0f;
  o.border = border;
  o.sampling = sampling;
  std::vector<float> out(crop_output_size(o));
  image_crop_job job;
  job.image = f.view;
  job.roi = pose_roi(rotation);
  job.options = o;
  job.output = out.data();
  job.output_size = out.size();
  for (auto _ : state) {
    benchmark::DoNotOptimize(job.run());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(out.size() * sizeof(float)));
}

void bm_crop_rgb_rotated(benchmark::State& state) {
  run_crop(state, pixel_format::rgb8, 3, 0.4f, crop_border::replicate);
}
void bm_crop_rgb_rotated_zero_border(benchmark::State& state) {
  run_crop(state, pixel_format::rgb8, 3, 0.4f, crop_border::zero);
}
// MediaPipe's OpenGL converter's sampling (the pipelines' default): float bilinear.
void bm_crop_rgb_rotated_gl(benchmark::State& state) {
  run_crop(state, pixel_format::rgb8, 3, 0.4f, crop_border::replicate, crop_sampling::gl);
}
void bm_crop_rgb_rotated_gl_zero_border(benchmark::State& state) {
  run_crop(state, pixel_format::rgb8, 3, 0.4f, crop_border::zero, crop_sampling::gl);
}
void bm_crop_rgb_upright(benchmark::State& state) {
  run_crop(state, pixel_format::rgb8, 3, 0.0f, crop_border::replicate);
}
void bm_crop_bgra_rotated(benchmark::State& state) {
  run_crop(state, pixel_format::bgra8, 4, 0.4f, crop_border::replicate);
}

void bm_memcpy_tensor(benchmark::State& state) {
  std::vector<float> src(256 * 256 * 3, 0.5f), dst(src.size());
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), src.size() * sizeof(float));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(src.size() * sizeof(float)));
}

// The low-light lift on a 256 x 256 crop (low_light.hpp): a well-exposed crop is only measured
// (the histogram: every input pays this), a dim one is also stretched. Each iteration restores
// the crop first (a memcpy, as bm_memcpy_tensor).
void run_lift(benchmark::State& state, float scale) {
  crop_options o;
  o.output_width = o.output_height = 256;
  std::vector<float> src(crop_output_size(o)), t(src.size());
  std::mt19937 rng(7);
  for (float& v : src) v = scale * static_cast<float>(rng() % 256) / 255.f;
  for (auto _ : state) {
    std::memcpy(t.data(), src.data(), t.size() * sizeof(float));
    benchmark::DoNotOptimize(lift_low_light(t.data(), o, crop_transform{}));
    benchmark::ClobberMemory();
  }
}
void bm_lift_well_exposed(benchmark::State& state) { run_lift(state, 1.0f); }
void bm_lift_dim(benchmark::State& state) { run_lift(state, 0.1f); }

BENCHMARK(bm_crop_rgb_rotated);
BENCHMARK(bm_crop_rgb_rotated_zero_border);
BENCHMARK(bm_crop_rgb_rotated_gl);
BENCHMARK(bm_crop_rgb_rotated_gl_zero_border);
BENCHMARK(bm_crop_rgb_upright);
BENCHMARK(bm_crop_bgra_rotated);
BENCHMARK(bm_memcpy_tensor);
BENCHMARK(bm_lift_well_exposed);
BENCHMARK(bm_lift_dim);

}  // namespace
}  // namespace avatarmap

BENCHMARK_MAIN();
