#include "avatarmap/capture/image_crop.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "support/test_data.hpp"

// The one definition of stb_image in capture_tests (Debian's libstb-dev); decoding only the
// formats of the shared reference images.
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_NO_STDIO_WARNINGS
#include <stb/stb_image.h>

namespace avatarmap {
namespace {

constexpr float k_pi = 3.14159265358979323846f;

// An owned image with a view onto it.
struct test_image {
  std::vector<std::uint8_t> pixels;
  int width = 0;
  int height = 0;
  int channels = 0;
  int stride = 0;
  pixel_format format = pixel_format::rgb8;

  image_view view() const { return {pixels.data(), width, height, stride, format}; }
};

// A w x h image whose pixel (x, y) channel c is value(x, y, c); rows padded by `pad` bytes.
template <typename F>
test_image make_image(int w, int h, pixel_format format, F value, int pad = 0) {
  const int channels = format == pixel_format::gray8                                  ? 1
                       : format == pixel_format::rgb8 || format == pixel_format::bgr8 ? 3
                                                                                      : 4;
  test_image img;
  img.width = w;
  img.height = h;
  img.channels = channels;
  img.stride = w * channels + pad;
  img.format = format;
  img.pixels.assign(static_cast<std::size_t>(img.stride) * h, 0xAB);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < channels; ++c) {
        img.pixels[static_cast<std::size_t>(y) * img.stride + x * channels + c] =
            static_cast<std::uint8_t>(value(x, y, c));
      }
    }
  }
  return img;
}

// Distinct per pixel and channel (as long as the image is under 16 x 16).
int pattern(int x, int y, int c) { return (x * 16 + y) ^ (c * 85); }

std::vector<float> crop(const test_image& img, const normalized_rect& roi,
                        const crop_options& options, crop_transform* t = nullptr) {
  std::vector<float> out(crop_output_size(options), -1000.0f);
  image_crop_job job;
  job.image = img.view();
  job.roi = roi;
  job.options = options;
  job.output = out.data();
  job.output_size = out.size();
  job.out_transform = t;
  EXPECT_TRUE(job.run());
  return out;
}

float at(const std::vector<float>& t, const crop_options& o, int x, int y, int c) {
  return t[(static_cast<std::size_t>(y) * o.output_width + x) * 3 + c];
}

crop_options options_0_255(int w, int h, bool keep, crop_border border) {
  crop_options o;
  o.output_width = w;
  o.output_height = h;
  o.range_min = 0.0f;
  o.range_max = 255.0f;
  o.keep_aspect_ratio = keep;
  o.border = border;
  return o;
}

TEST(ImageCrop, IdentityRoiReproducesTheImage) {
  const auto img = make_image(5, 4, pixel_format::rgb8, pattern);
  for (bool keep : {false, true}) {
    const auto o = options_0_255(5, 4, keep, crop_border::zero);
    const auto out = crop(img, {}, o);
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 5; ++x) {
        for (int c = 0; c < 3; ++c) ASSERT_EQ(at(out, o, x, y, c), pattern(x, y, c));
      }
    }
  }
}

TEST(ImageCrop, HalfSizeTakesEveryOtherPixel) {
  // MediaPipe's CPU path samples tensor pixel x at x / W of the ROI (corner-aligned), so a 2:1
  // downscale lands exactly on the even source pixels: no blending at all.
  const auto img = make_image(8, 6, pixel_format::rgb8, pattern);
  const auto o = options_0_255(4, 3, false, crop_border::replicate);
  const auto out = crop(img, {}, o);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) ASSERT_EQ(at(out, o, x, y, c), pattern(2 * x, 2 * y, c));
    }
  }
}

TEST(ImageCrop, HalfPixelSampleBlendsNeighbours) {
  // Source 2 x 1 -> tensor 4 x 1: x = 1 samples at 0.5, between the two pixels.
  const auto img =
      make_image(2, 1, pixel_format::gray8, [](int x, int, int) { return x ? 101 : 0; });
  const auto o = options_0_255(4, 1, false, crop_border::replicate);
  const auto out = crop(img, {}, o);
  EXPECT_EQ(at(out, o, 0, 0, 0), 0.0f);
  EXPECT_EQ(at(out, o, 1, 0, 0), 51.0f);  // (101 * 512 + 512) >> 10 = 51 (50.5 rounds up)
  EXPECT_EQ(at(out, o, 2, 0, 0), 101.0f);
  EXPECT_EQ(at(out, o, 3, 0, 0), 101.0f);  // 1.5: replicated edge
  EXPECT_EQ(at(out, o, 1, 0, 1), 51.0f);   // gray is replicated to 3 channels
}

TEST(ImageCrop, QuarterTurnOfAKnownPattern) {
  // Rotation pi/2 about the centre of a square image: tensor (x, y) samples image (N - y, x),
  // so the tensor's top row reads the column just past the right edge.
  constexpr int n = 6;
  const auto img = make_image(n, n, pixel_format::rgb8, pattern);
  normalized_rect roi;
  roi.rotation = k_pi / 2;
  for (auto border : {crop_border::replicate, crop_border::zero}) {
    const auto o = options_0_255(n, n, true, border);
    const auto out = crop(img, roi, o);
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        for (int c = 0; c < 3; ++c) {
          const int sx = n - y;
          const float expected = sx < n                        ? pattern(sx, x, c)
                                 : border == crop_border::zero ? 0.0f
                                                               : pattern(n - 1, x, c);
          ASSERT_EQ(at(out, o, x, y, c), expected) << x << "," << y << "," << c;
        }
      }
    }
  }
}

TEST(ImageCrop, BorderModesOutsideTheImage) {
  // ROI centred on the right edge: the right half of the tensor lies outside the image.
  const auto img = make_image(4, 4, pixel_format::rgb8, [](int, int, int c) { return 60 + c; });
  normalized_rect roi;
  roi.x_center = 1.0f;
  crop_options o;
  o.output_width = 8;
  o.output_height = 8;
  o.range_min = -1.0f;
  o.range_max = 1.0f;
  o.keep_aspect_ratio = false;
  for (auto border : {crop_border::replicate, crop_border::zero}) {
    o.border = border;
    const auto out = crop(img, roi, o);
    for (int y = 0; y < 8; ++y) {
      for (int x = 0; x < 8; ++x) {
        // Source (2 + x / 2, y / 2): x = 4 is 4.0 (outside); with the zero border x = 3 and
        // y = 7 sample 3.5, half of it black. Weights in 1/32 per axis, as the kernel's.
        const int wx = x < 3 ? 32 : x == 3 ? 16 : 0;
        const int wy = y < 7 ? 32 : 16;
        for (int c = 0; c < 3; ++c) {
          const float byte =
              border == crop_border::replicate ? 60 + c : ((60 + c) * wx * wy + 512) >> 10;
          ASSERT_FLOAT_EQ(at(out, o, x, y, c), byte * (2.0f / 255.0f) - 1.0f)
              << x << "," << y << "," << c;
        }
      }
    }
  }
}

TEST(ImageCrop, LetterboxBandsAndPadding) {
  // A 16 x 4 image into an 8 x 8 tensor with keep_aspect_ratio: the ROI grows to 16 x 16,
  // bands of 3/8 above and below.
  const auto img = make_image(16, 4, pixel_format::rgb8, pattern);
  const auto o = options_0_255(8, 8, true, crop_border::zero);
  crop_transform t;
  const auto out = crop(img, {}, o, &t);
  EXPECT_FLOAT_EQ(t.letterbox_padding[0], 0.0f);
  EXPECT_FLOAT_EQ(t.letterbox_padding[1], 0.375f);
  EXPECT_FLOAT_EQ(t.letterbox_padding[2], 0.0f);
  EXPECT_FLOAT_EQ(t.letterbox_padding[3], 0.375f);
  EXPECT_FLOAT_EQ(t.roi_width, 16.0f);
  EXPECT_FLOAT_EQ(t.roi_height, 16.0f);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      const int sy = 2 * y - 6;  // source row of tensor row y
      for (int c = 0; c < 3; ++c) {
        const float expected = sy >= 0 && sy < 4 ? pattern(2 * x, sy, c) : 0.0f;
        ASSERT_EQ(at(out, o, x, y, c), expected) << x << "," << y;
      }
    }
  }
  // Taller ROI than the tensor: horizontal bands instead.
  crop_transform tall;
  normalized_rect roi;
  roi.width = 0.25f;  // 4 x 4 px ROI on a 16 x 4 image, into a 8 x 4 tensor
  crop_options wide = o;
  wide.output_height = 4;
  ASSERT_TRUE(make_crop_transform(16, 4, roi, wide, tall));
  EXPECT_FLOAT_EQ(tall.letterbox_padding[0], 0.25f);
  EXPECT_FLOAT_EQ(tall.letterbox_padding[1], 0.0f);
  EXPECT_FLOAT_EQ(tall.roi_width, 8.0f);
  EXPECT_FLOAT_EQ(tall.roi_height, 4.0f);
}

TEST(ImageCrop, PixelFormatsAndStridesAgree) {
  const auto rgb = [](int x, int y, int c) { return (x * 37 + y * 11 + c * 71) & 255; };
  const auto rgb_img = make_image(37, 23, pixel_format::rgb8, rgb);
  const auto bgr_img = make_image(
      37, 23, pixel_format::bgr8, [&](int x, int y, int c) { return rgb(x, y, 2 - c); }, 5);
  const auto rgba_img = make_image(37, 23, pixel_format::rgba8,
                                   [&](int x, int y, int c) { return c < 3 ? rgb(x, y, c) : 9; });
  const auto bgra_img = make_image(
      37, 23, pixel_format::bgra8,
      [&](int x, int y, int c) { return c < 3 ? rgb(x, y, 2 - c) : 9; }, 3);
  normalized_rect roi{0.4f, 0.6f, 0.7f, 0.5f, 0.6f};
  for (auto sampling : {crop_sampling::opencv, crop_sampling::gl}) {
    for (auto border : {crop_border::replicate, crop_border::zero}) {
      crop_options o;
      o.output_width = 19;
      o.output_height = 13;
      o.border = border;
      o.sampling = sampling;
      const auto expected = crop(rgb_img, roi, o);
      EXPECT_EQ(crop(bgr_img, roi, o), expected);
      EXPECT_EQ(crop(rgba_img, roi, o), expected);
      EXPECT_EQ(crop(bgra_img, roi, o), expected);

      const auto gray = [](int x, int y, int) { return (x * 13 + y * 7) & 255; };
      const auto gray_img = make_image(37, 23, pixel_format::gray8, gray, 2);
      const auto gray_as_rgb = make_image(37, 23, pixel_format::rgb8, gray);
      EXPECT_EQ(crop(gray_img, roi, o), crop(gray_as_rgb, roi, o));
    }
  }
}

// --- crop_sampling::gl (MediaPipe's OpenGL converter) ----------------------------------------

crop_options gl_options(int w, int h, crop_border border) {
  crop_options o = options_0_255(w, h, false, border);
  o.sampling = crop_sampling::gl;
  return o;
}

TEST(ImageCropGl, IdentityRoiReproducesTheImage) {
  // Pixel centres onto pixel centres: tensor x samples image x exactly.
  const auto img = make_image(5, 4, pixel_format::rgb8, pattern);
  for (auto border : {crop_border::replicate, crop_border::zero}) {
    const auto o = gl_options(5, 4, border);
    const auto out = crop(img, {}, o);
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 5; ++x) {
        for (int c = 0; c < 3; ++c) ASSERT_EQ(at(out, o, x, y, c), pattern(x, y, c));
      }
    }
  }
}

TEST(ImageCropGl, HalfSizeAveragesEachTwoByTwoBlock) {
  // Tensor pixel x's centre x + 0.5 is image position 2x + 1, i.e. halfway between the centres
  // of pixels 2x and 2x + 1 (at 2x + 0.5 and 2x + 1.5): GL_LINEAR gives the mean of the 2 x 2
  // block, unrounded (the CPU converter takes pixel 2x alone: HalfSizeTakesEveryOtherPixel).
  const auto img = make_image(8, 6, pixel_format::rgb8, pattern);
  const auto o = gl_options(4, 3, crop_border::replicate);
  const auto out = crop(img, {}, o);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float mean = (pattern(2 * x, 2 * y, c) + pattern(2 * x + 1, 2 * y, c) +
                            pattern(2 * x, 2 * y + 1, c) + pattern(2 * x + 1, 2 * y + 1, c)) /
                           4.0f;
        ASSERT_FLOAT_EQ(at(out, o, x, y, c), mean) << x << "," << y << "," << c;
      }
    }
  }
}

TEST(ImageCropGl, ZeroBorderCutsAtTheImagesOuterEdge) {
  // A 4 x 4 image, ROI (the image's size) centred on an edge, 8 x 8 tensor: tensor pixel x
  // samples image position 0.5 x - 0.25 + 2 (right edge) or - 2 (left edge), in this file's
  // integer-centre convention. MediaPipe's zero-border shader blacks out positions beyond the
  // outer edge (< -0.5 or > 3.5) and clamps the rest to the edge pixels: on the right edge
  // x = 3 (3.25) keeps the edge value and x = 4 (3.75) is black; on the left edge x = 3 (-0.75)
  // is black and x = 4 (-0.25) is the edge value. No blend towards black as in the CPU
  // converter's (BorderModesOutsideTheImage). Replicate keeps the edge value everywhere.
  const auto img = make_image(4, 4, pixel_format::rgb8, [](int, int, int c) { return 60 + c; });
  for (const float centre_x : {1.0f, 0.0f}) {
    normalized_rect roi;
    roi.x_center = centre_x;
    for (auto border : {crop_border::replicate, crop_border::zero}) {
      crop_options o = gl_options(8, 8, border);
      o.range_min = -1.0f;
      o.range_max = 1.0f;
      const auto out = crop(img, roi, o);
      for (int y = 0; y < 8; ++y) {
        for (int x = 0; x < 8; ++x) {
          const bool outside = centre_x == 1.0f ? x >= 4 : x <= 3;
          for (int c = 0; c < 3; ++c) {
            const float expected =
                border == crop_border::zero && outside ? -1.0f : (60 + c) * (2.0f / 255.0f) - 1.0f;
            ASSERT_NEAR(at(out, o, x, y, c), expected, 1e-6f) << x << "," << y << "," << c;
          }
        }
      }
    }
  }
}

TEST(ImageCropGl, SamplingChangesThePixelsNotTheTransform) {
  // Landmarks go back through the same transform in both converters (MediaPipe projects them
  // the same way); only the sampled pixels differ, by half a tensor pixel minus half an image
  // pixel. A linear ramp in x shows it: value = 2 * position, so the GL crop reads
  // 2 * (0.5 * scale - 0.5) more than the CPU crop, scale being ROI pixels per tensor pixel.
  const auto img = make_image(64, 8, pixel_format::gray8, [](int x, int, int) { return 2 * x; });
  const normalized_rect roi{0.5f, 0.5f, 0.5f, 1.0f, 0.0f};  // 32 x 8 px -> 8 x 2: scale 4
  crop_options cpu = options_0_255(8, 2, false, crop_border::replicate);
  crop_options gl = cpu;
  gl.sampling = crop_sampling::gl;
  crop_transform t_cpu, t_gl;
  const auto a = crop(img, roi, cpu, &t_cpu);
  const auto b = crop(img, roi, gl, &t_gl);
  EXPECT_EQ(t_cpu.to_image, t_gl.to_image);
  EXPECT_EQ(t_cpu.to_tensor, t_gl.to_tensor);
  for (int x = 0; x < 8; ++x) {
    EXPECT_FLOAT_EQ(at(a, cpu, x, 0, 0), 2.0f * (16 + 4 * x));
    EXPECT_FLOAT_EQ(at(b, gl, x, 0, 0), 2.0f * (16 + 4 * x + 1.5f));
  }
}

TEST(ImageCrop, TransformMapsTensorCornersToRoiCorners) {
  const normalized_rect roi{0.3f, 0.6f, 0.4f, 0.2f, 0.5f};
  crop_options o;
  o.output_width = 64;
  o.output_height = 32;
  const int iw = 640, ih = 480;
  for (bool keep : {false, true}) {
    o.keep_aspect_ratio = keep;
    crop_transform t;
    ASSERT_TRUE(make_crop_transform(iw, ih, roi, o, t));
    // ROI in pixels, padded to the tensor's aspect (2:1 wide) when asked: 256 x 96 -> 256 x 128.
    const double w = keep ? 256.0 : 0.4 * iw, h = keep ? 128.0 : 0.2 * ih;
    EXPECT_NEAR(t.roi_width, w, 1e-3);
    EXPECT_NEAR(t.roi_height, h, 1e-3);
    const double cx = 0.3 * iw, cy = 0.6 * ih, c = std::cos(0.5), s = std::sin(0.5);
    const double corners[4][2] = {{0, 0}, {64, 0}, {0, 32}, {64, 32}};
    for (const auto& k : corners) {
      const double u = (k[0] / 64 - 0.5) * w, v = (k[1] / 32 - 0.5) * h;
      const double ex = cx + c * u - s * v, ey = cy + s * u + c * v;
      const auto p = project_to_image(t, {static_cast<float>(k[0]), static_cast<float>(k[1]), 0});
      EXPECT_NEAR(p.x * iw, ex, 1e-3) << k[0] << "," << k[1];
      EXPECT_NEAR(p.y * ih, ey, 1e-3) << k[0] << "," << k[1];
      const auto back = project_to_tensor(t, p);
      EXPECT_NEAR(back.x, k[0], 1e-3);
      EXPECT_NEAR(back.y, k[1], 1e-3);
    }
    // The matrices are inverses.
    const auto& a = t.to_image;
    const auto& b = t.to_tensor;
    EXPECT_NEAR(b[0] * a[0] + b[1] * a[3], 1.0, 1e-12);
    EXPECT_NEAR(b[0] * a[1] + b[1] * a[4], 0.0, 1e-12);
    EXPECT_NEAR(b[0] * a[2] + b[1] * a[5] + b[2], 0.0, 1e-9);
    EXPECT_NEAR(b[3] * a[2] + b[4] * a[5] + b[5], 0.0, 1e-9);
  }
}

// MediaPipe's landmark chain: TensorsToLandmarks (divide by the tensor size), then
// LandmarkLetterboxRemoval, then LandmarkProjection with the unpadded NORM_RECT.
crop_point mediapipe_chain(crop_point px, const crop_transform& t, const normalized_rect& roi) {
  const auto& pad = t.letterbox_padding;
  float x = px.x / t.tensor_width, y = px.y / t.tensor_height, z = px.z / t.tensor_width;
  x = (x - pad[0]) / (1.0f - pad[0] - pad[2]);
  y = (y - pad[1]) / (1.0f - pad[1] - pad[3]);
  z = z / (1.0f - pad[0] - pad[2]);
  const float dx = x - 0.5f, dy = y - 0.5f, c = std::cos(roi.rotation), s = std::sin(roi.rotation);
  return {(c * dx - s * dy) * roi.width + roi.x_center,
          (s * dx + c * dy) * roi.height + roi.y_center, z * roi.width};
}

TEST(ImageCrop, ProjectionMatchesMediaPipesLandmarkChain) {
  crop_options o;  // 256 x 256, keep aspect
  const int iw = 640, ih = 480;
  // A ROI square in pixels (200 x 200), rotated, as the pose and hand graphs make them.
  const normalized_rect square{0.55f, 0.45f, 200.0f / iw, 200.0f / ih, 0.7f};
  // A non-square ROI without rotation: letterboxed.
  const normalized_rect tall{0.4f, 0.5f, 0.2f, 0.6f, 0.0f};
  for (const auto& roi : {square, tall}) {
    crop_transform t;
    ASSERT_TRUE(make_crop_transform(iw, ih, roi, o, t));
    for (const crop_point p :
         {crop_point{100, 50, 30}, crop_point{0, 256, -12}, crop_point{200.5f, 17.25f, 0}}) {
      const auto got = project_to_image(t, p);
      const auto want = mediapipe_chain(p, t, roi);
      EXPECT_NEAR(got.x, want.x, 1e-5);
      EXPECT_NEAR(got.y, want.y, 1e-5);
      EXPECT_NEAR(got.z, want.z, 1e-5);
      const auto back = project_to_tensor(t, got);
      EXPECT_NEAR(back.x, p.x, 1e-3);
      EXPECT_NEAR(back.y, p.y, 1e-3);
      EXPECT_NEAR(back.z, p.z, 1e-3);
    }
  }
}

TEST(ImageCrop, ValidateRejectsEachBrokenInput) {
  const auto img = make_image(8, 8, pixel_format::rgb8, pattern);
  std::vector<float> out(16 * 16 * 3);
  image_crop_job good;
  good.image = img.view();
  good.options.output_width = 16;
  good.options.output_height = 16;
  good.output = out.data();
  good.output_size = out.size();
  ASSERT_TRUE(good.validate());

  std::vector<image_crop_job> bad(17, good);
  bad[0].image.data = nullptr;
  bad[1].image.width = 0;
  bad[2].image.height = -1;
  bad[3].image.stride_bytes = 8 * 3 - 1;
  bad[4].roi.width = 0.0f;
  bad[5].roi.height = -0.5f;
  bad[6].roi.x_center = std::nanf("");
  bad[7].roi.rotation = INFINITY;
  bad[8].options.output_width = 0;
  bad[9].options.range_min = 1.0f;  // == range_max
  bad[10].options.range_max = NAN;
  bad[11].output = nullptr;
  bad[12].output_size = out.size() - 1;
  bad[13].image.format = static_cast<pixel_format>(99);
  bad[14].roi.width = 1e7f;  // corners beyond 2^24 px
  bad[15].options.border = static_cast<crop_border>(9);
  bad[16].options.sampling = static_cast<crop_sampling>(9);
  for (std::size_t i = 0; i < bad.size(); ++i) {
    EXPECT_FALSE(bad[i].validate()) << i;
    out[0] = 123.0f;
    EXPECT_FALSE(bad[i].run()) << i;
    EXPECT_EQ(out[0], 123.0f) << i;  // output untouched
  }
}

// --- MediaPipe's own reference images --------------------------------------------------------

struct decoded {
  std::vector<std::uint8_t> pixels;
  int width = 0;
  int height = 0;
};

bool decode(const std::string& path, int channels, decoded& out) {
  int w = 0, h = 0, n = 0;
  stbi_uc* p = stbi_load(path.c_str(), &w, &h, &n, channels);
  if (p == nullptr) return false;
  out.pixels.assign(p, p + static_cast<std::size_t>(w) * h * channels);
  out.width = w;
  out.height = h;
  stbi_image_free(p);
  return true;
}

// The parameters of mediapipe/calculators/tensor/image_to_tensor_calculator_test.cc.
struct reference_case {
  const char* name;
  normalized_rect roi;
  float range_min, range_max;
  int width, height;
  bool keep_aspect;
  crop_border border;
  bool rgba_input;
};

constexpr float k_deg = k_pi / 180.0f;
const normalized_rect k_medium{0.65f, 0.4f, 0.5f, 0.5f, 0.0f};
const normalized_rect k_medium_90{0.65f, 0.4f, 0.5f, 0.5f, 90.0f * k_deg};
const normalized_rect k_medium_m45{0.65f, 0.4f, 0.5f, 0.5f, -45.0f * k_deg};
const normalized_rect k_large{0.5f, 0.5f, 1.5f, 1.1f, 0.0f};
const normalized_rect k_large_m15{0.5f, 0.5f, 1.5f, 1.1f, -15.0f * k_deg};
const normalized_rect k_full{0.5f, 0.5f, 1.0f, 1.0f, 0.0f};
constexpr auto k_rep = crop_border::replicate;
constexpr auto k_zero = crop_border::zero;

const reference_case k_reference_cases[] = {
    {"medium_sub_rect_keep_aspect", k_medium, 0, 1, 256, 256, true, k_rep, false},
    {"medium_sub_rect_keep_aspect_border_zero", k_medium, 0, 1, 256, 256, true, k_zero, false},
    {"medium_sub_rect_keep_aspect_with_rotation", k_medium_90, 0, 1, 256, 256, true, k_rep, false},
    {"medium_sub_rect_keep_aspect_with_rotation_border_zero", k_medium_90, 0, 1, 256, 256, true,
     k_zero, false},
    {"medium_sub_rect_with_rotation", k_medium_m45, -1, 1, 256, 256, false, k_rep, false},
    {"medium_sub_rect_with_rotation_border_zero", k_medium_m45, -1, 1, 256, 256, false, k_zero,
     false},
    {"large_sub_rect", k_large, 0, 1, 128, 128, false, k_rep, false},
    {"large_sub_rect_border_zero", k_large, 0, 1, 128, 128, false, k_zero, false},
    {"large_sub_rect_keep_aspect", k_large, 0, 1, 128, 128, true, k_rep, false},
    {"large_sub_rect_keep_aspect_border_zero", k_large, 0, 1, 128, 128, true, k_zero, false},
    {"large_sub_rect_keep_aspect_with_rotation", k_large_m15, 0, 1, 128, 128, true, k_rep, true},
    {"large_sub_rect_keep_aspect_with_rotation_border_zero", k_large_m15, 0, 1, 128, 128, true,
     k_zero, true},
    {"noop_except_range", k_full, 0, 1, 64, 128, true, k_rep, true},
};

TEST(ImageCrop, ReproducesMediaPipeReferenceImages) {
  const std::string dir = test::test_data_path("motion/tfjs-models/image_to_tensor/");
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  decoded rgb, rgba;
  ASSERT_TRUE(decode(dir + "image_to_tensor_input.jpg", 3, rgb)) << stbi_failure_reason();
  ASSERT_TRUE(decode(dir + "image_to_tensor_input.jpg", 4, rgba));
  for (const auto& rc : k_reference_cases) {
    decoded expected;
    ASSERT_TRUE(decode(dir + rc.name + ".png", 3, expected)) << rc.name;
    ASSERT_EQ(expected.width, rc.width) << rc.name;
    ASSERT_EQ(expected.height, rc.height) << rc.name;

    const decoded& input = rc.rgba_input ? rgba : rgb;
    image_crop_job job;
    job.image = {input.pixels.data(), input.width, input.height,
                 input.width * (rc.rgba_input ? 4 : 3),
                 rc.rgba_input ? pixel_format::rgba8 : pixel_format::rgb8};
    job.roi = rc.roi;
    job.options.output_width = rc.width;
    job.options.output_height = rc.height;
    job.options.range_min = rc.range_min;
    job.options.range_max = rc.range_max;
    job.options.keep_aspect_ratio = rc.keep_aspect;
    job.options.border = rc.border;
    std::vector<float> out(crop_output_size(job.options));
    job.output = out.data();
    job.output_size = out.size();
    ASSERT_TRUE(job.run()) << rc.name;

    // Back to bytes as MediaPipe's test does (convertTo CV_8U: round and saturate).
    const float scale = 255.0f / (rc.range_max - rc.range_min);
    int max_diff = 0;
    long sum_diff = 0;
    long differing = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const long byte = std::lrint((out[i] - rc.range_min) * scale);
      const int v = static_cast<int>(byte < 0 ? 0 : byte > 255 ? 255 : byte);
      const int d = std::abs(v - expected.pixels[i]);
      max_diff = d > max_diff ? d : max_diff;
      sum_diff += d;
      differing += d != 0;
    }
    const double mean = static_cast<double>(sum_diff) / out.size();
    std::printf("[ image_crop ] %-54s max %d  mean %.4f  differing %.2f%%\n", rc.name, max_diff,
                mean, 100.0 * differing / out.size());
    // MediaPipe's own bar: "the maximum absolute pixel-by-pixel difference is less than 5"
    // (EXPECT_LE(max_val, 5)).
    EXPECT_LE(max_diff, 5) << rc.name;
    // Our own, tighter bar. The residue is JPEG decoding alone: stb_image and libjpeg (which
    // OpenCV's imread uses) differ by up to 3 on 1.02% of this input's bytes, and with the input
    // decoded by libjpeg every reference is reproduced bit for bit (0 differing bytes,
    // measured while writing this test). Measured here with stb: mean <= 0.017.
    EXPECT_LE(mean, 0.03) << rc.name;
  }
}

}  // namespace
}  // namespace avatarmap
