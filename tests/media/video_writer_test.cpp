#include "avatarmap/media/video_writer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "avatarmap/media/video_source.hpp"
#include "support/temp_dir.hpp"

// STB_IMAGE_IMPLEMENTATION is defined once in video_source_test.cpp (same binary): an
// independent PNG decoder for the lossless comparisons.
#include <stb/stb_image.h>

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

#define SKIP_WITHOUT_FFMPEG() \
  if (!video_source_available()) GTEST_SKIP() << "built without FFmpeg: nothing to read back"

constexpr double k_fps = 30.0;

struct rgb {
  int r, g, b;
};

constexpr rgb k_background{40, 90, 160};
constexpr rgb k_square{220, 60, 40};
constexpr int k_square_size = 16;

// Frame i of a synthetic clip: background with a square whose top-left corner moves by
// (2, 1) pixels per frame. Rows are `stride` bytes apart (the padding holds 0xEE).
struct synthetic_frame {
  int width;
  int height;
  int stride;
  int square_x;
  int square_y;
  std::vector<std::uint8_t> pixels;

  synthetic_frame(int w, int h, int i, int pad = 5)
      : width(w), height(h), stride(w * 3 + pad), square_x(4 + 2 * i), square_y(8 + i) {
    pixels.assign(static_cast<std::size_t>(stride) * h, 0xEE);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool in = x >= square_x && x < square_x + k_square_size && y >= square_y &&
                        y < square_y + k_square_size;
        const rgb c = in ? k_square : k_background;
        std::uint8_t* p = &pixels[static_cast<std::size_t>(y) * stride + 3 * x];
        p[0] = static_cast<std::uint8_t>(c.r);
        p[1] = static_cast<std::uint8_t>(c.g);
        p[2] = static_cast<std::uint8_t>(c.b);
      }
  }
  image_view view() const { return {pixels.data(), width, height, stride, pixel_format::rgb8}; }
};

// A frame read back, copied out of the source's buffer.
struct decoded {
  int width = 0;
  int height = 0;
  double t = 0.0;
  std::vector<std::uint8_t> pixels;  // tightly packed RGB
  const std::uint8_t* at(int x, int y) const {
    return &pixels[(static_cast<std::size_t>(y) * width + x) * 3];
  }
};

std::vector<decoded> read_all(const std::string& path, std::string& out_error,
                              std::string* out_codec = nullptr) {
  std::vector<decoded> r;
  video_source src;
  status st = src.open(path);
  if (!st) {
    out_error = st.message();
    return r;
  }
  if (out_codec) *out_codec = src.info().codec;
  for (int i = 0; i < 1000; ++i) {
    image_view v;
    double t = 0;
    const read_result res = src.next(v, t);
    if (res == read_result::end) break;
    if (res == read_result::error) {
      out_error = src.error();
      break;
    }
    decoded d;
    d.width = v.width;
    d.height = v.height;
    d.t = t;
    for (int y = 0; y < v.height; ++y)
      d.pixels.insert(d.pixels.end(), v.data + static_cast<std::ptrdiff_t>(y) * v.stride_bytes,
                      v.data + static_cast<std::ptrdiff_t>(y) * v.stride_bytes + v.width * 3);
    r.push_back(std::move(d));
  }
  return r;
}

// Mean colour of the w x h block at (x, y).
rgb mean_color(const decoded& d, int x, int y, int w, int h) {
  double s[3] = {0, 0, 0};
  for (int j = y; j < y + h; ++j)
    for (int i = x; i < x + w; ++i)
      for (int c = 0; c < 3; ++c) s[c] += d.at(i, j)[c];
  const double n = static_cast<double>(w) * h;
  return {static_cast<int>(std::lround(s[0] / n)), static_cast<int>(std::lround(s[1] / n)),
          static_cast<int>(std::lround(s[2] / n))};
}

void expect_near(rgb got, rgb want, int tolerance, const std::string& what) {
  EXPECT_NEAR(got.r, want.r, tolerance) << what;
  EXPECT_NEAR(got.g, want.g, tolerance) << what;
  EXPECT_NEAR(got.b, want.b, tolerance) << what;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// Writes frames 0..n-1 at t = i / fps; returns close()'s status.
status write_clip(video_writer& w, int width, int height, int n) {
  for (int i = 0; i < n; ++i) {
    const synthetic_frame f(width, height, i);
    status st = w.write(f.view(), i / k_fps);
    if (!st) return st;
  }
  return w.close();
}

// ---- without FFmpeg ------------------------------------------------------------------------

TEST(video_writer, StubSaysBuiltWithoutFfmpeg) {
  if (video_writer_available()) GTEST_SKIP() << "built with FFmpeg";
  test::temp_dir dir("vw_stub");
  video_writer w;
  const status st = w.open(dir.file("a.mp4"), 64, 48, 30.0);
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.message(), "without FFmpeg")) << st.message();
  EXPECT_FALSE(w.is_open());
  EXPECT_TRUE(dir.entries().empty());
}

// ---- round trips ---------------------------------------------------------------------------

TEST(video_writer, VideoRoundTrip) {
  SKIP_WITHOUT_FFMPEG();
  struct variant {
    const char* name;
    const char* encoder;
    int tolerance;  // levels per channel, on flat areas of the picture
  };
  // Measured: at most 6 levels off with libx264 at CRF 23, 3 with mpeg4 at quantiser 3.
  const variant variants[] = {{"clip.mp4", "", 8},       {"clip.mov", "", 8},
                              {"clip.mkv", "", 8},       {"clip.avi", "", 8},
                              {"clip2.mp4", "mpeg4", 8}, {"clip2.mkv", "mpeg4", 8}};
  constexpr int w = 64, h = 48, n = 12;
  for (const variant& v : variants) {
    SCOPED_TRACE(std::string(v.name) + " encoder '" + v.encoder + "'");
    test::temp_dir dir("vw_video");
    const std::string path = dir.file(v.name);
    video_writer_options o;
    o.encoder = v.encoder;
    video_writer wr;
    const status st = wr.open(path, w, h, k_fps, o);
    ASSERT_TRUE(st.ok()) << st.message();
    EXPECT_EQ(wr.kind(), video_writer_kind::video);
    EXPECT_EQ(wr.output_width(), w);
    EXPECT_EQ(wr.output_height(), h);
    if (std::string(v.encoder) == "mpeg4" || std::string(v.name) == "clip.avi")
      EXPECT_EQ(wr.encoder_name(), "mpeg4");
    else
      EXPECT_TRUE(wr.encoder_name() == "libx264" || wr.encoder_name() == "mpeg4");
    EXPECT_FALSE(fs::exists(path));  // not before close()
    const std::string wr_encoder = wr.encoder_name();
    const status closed = write_clip(wr, w, h, n);
    ASSERT_TRUE(closed.ok()) << closed.message();
    EXPECT_FALSE(wr.is_open());
    EXPECT_EQ(dir.entries(), std::vector<std::string>{v.name});  // no temporary file left

    std::string error, codec;
    const std::vector<decoded> frames = read_all(path, error, &codec);
    EXPECT_EQ(error, "");
    EXPECT_EQ(codec, wr_encoder == "libx264" ? "h264" : "mpeg4");
    ASSERT_EQ(frames.size(), static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const decoded& d = frames[i];
      ASSERT_EQ(d.width, w);
      ASSERT_EQ(d.height, h);
      EXPECT_NEAR(d.t, i / k_fps, 1e-3) << "frame " << i;
      // The middle 8x8 of the square and a background block away from it.
      const synthetic_frame f(w, h, i);
      expect_near(mean_color(d, f.square_x + 4, f.square_y + 4, 8, 8), k_square, v.tolerance,
                  "square of frame " + std::to_string(i));
      expect_near(mean_color(d, 48, 36, 8, 8), k_background, v.tolerance,
                  "background of frame " + std::to_string(i));
    }
  }
}

TEST(video_writer, OddSizeIsPaddedToEven) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_odd");
  const std::string path = dir.file("odd.mp4");
  constexpr int w = 37, h = 29, n = 3;
  video_writer wr;
  ASSERT_TRUE(wr.open(path, w, h, k_fps).ok());
  EXPECT_EQ(wr.output_width(), 38);
  EXPECT_EQ(wr.output_height(), 30);
  const status st = write_clip(wr, w, h, n);
  ASSERT_TRUE(st.ok()) << st.message();
  std::string error;
  const std::vector<decoded> frames = read_all(path, error);
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(n)) << error;
  for (int i = 0; i < n; ++i) {
    const decoded& d = frames[i];
    ASSERT_EQ(d.width, 38);
    ASSERT_EQ(d.height, 30);
    const synthetic_frame f(w, h, i);
    expect_near(mean_color(d, f.square_x + 4, f.square_y + 4, 8, 8), k_square, 8, "square");
    // The padding repeats the last column and row: background there.
    expect_near(mean_color(d, 34, 0, 4, 30), k_background, 8, "padded column");
    expect_near(mean_color(d, 26, 26, 12, 4), k_background, 8, "padded row");
  }
}

TEST(video_writer, TimeStampsSnapToTicksAndNeverRepeat) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_time");
  const std::string path = dir.file("t.mkv");
  // Times from 10 s on: measured from the first. Repeated or backwards times and NaN get the
  // next tick (1/30 s); 10.01 rounds to tick 0, which is taken, so it gets the next one too.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double t[] = {10.0, 10.0, 10.01, 10.0 + 5 / k_fps, 10.0 + 5 / k_fps, 9.0, 10.0 + 9 / k_fps,
                      nan};
  const int expected_ticks[] = {0, 1, 2, 5, 6, 7, 9, 10};
  video_writer wr;
  ASSERT_TRUE(wr.open(path, 64, 48, k_fps).ok());
  for (int i = 0; i < 8; ++i) {
    const synthetic_frame f(64, 48, i);
    ASSERT_TRUE(wr.write(f.view(), t[i]).ok());
  }
  EXPECT_EQ(wr.frames_written(), 8);
  const status st = wr.close();
  ASSERT_TRUE(st.ok()) << st.message();
  std::string error;
  const std::vector<decoded> frames = read_all(path, error);
  ASSERT_EQ(frames.size(), 8u) << error;
  for (int i = 0; i < 8; ++i)
    EXPECT_NEAR(frames[i].t, expected_ticks[i] / k_fps, 1e-3) << "frame " << i;
}

TEST(video_writer, PngPatternRoundTripIsExact) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_png");
  constexpr int w = 40, h = 30, n = 5;
  video_writer wr;
  ASSERT_TRUE(wr.open(dir.file("f_%03d.png"), w, h, k_fps).ok());
  EXPECT_EQ(wr.kind(), video_writer_kind::png_sequence);
  for (int i = 0; i < n; ++i) {
    const synthetic_frame f(w, h, i);
    ASSERT_TRUE(wr.write(f.view(), i / k_fps).ok());
  }
  // Before close(): only temporary files, none under a final name.
  for (const std::string& e : dir.entries()) EXPECT_TRUE(contains(e, ".tmp.")) << e;
  EXPECT_EQ(dir.entries().size(), static_cast<std::size_t>(n));
  ASSERT_TRUE(wr.close().ok());
  std::vector<std::string> names = dir.entries();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"f_000.png", "f_001.png", "f_002.png", "f_003.png",
                                             "f_004.png"}));

  std::string error;
  const std::vector<decoded> frames = read_all(dir.file("f_%03d.png"), error);
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(n)) << error;
  for (int i = 0; i < n; ++i) {
    const synthetic_frame f(w, h, i);
    ASSERT_EQ(frames[i].width, w);
    ASSERT_EQ(frames[i].height, h);
    for (int y = 0; y < h; ++y)
      ASSERT_TRUE(std::equal(f.pixels.begin() + static_cast<std::ptrdiff_t>(y) * f.stride,
                             f.pixels.begin() + static_cast<std::ptrdiff_t>(y) * f.stride + w * 3,
                             frames[i].at(0, y)))
          << "frame " << i << " row " << y;
  }

  // first_number and an unpadded %d.
  test::temp_dir dir2("vw_png2");
  video_writer_options o;
  o.first_number = 7;
  ASSERT_TRUE(wr.open(dir2.file("x%d.png"), w, h, k_fps, o).ok());
  ASSERT_TRUE(write_clip(wr, w, h, 4).ok());
  names = dir2.entries();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"x10.png", "x7.png", "x8.png", "x9.png"}));
}

TEST(video_writer, SinglePngIsTheFirstFrameExactly) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_single");
  const std::string path = dir.file("still.PNG");  // extensions are case-insensitive
  constexpr int w = 23, h = 17;                    // odd sizes are fine for PNG
  video_writer wr;
  ASSERT_TRUE(wr.open(path, w, h, k_fps).ok());
  EXPECT_EQ(wr.kind(), video_writer_kind::png_single);
  EXPECT_EQ(wr.output_width(), w);
  ASSERT_TRUE(write_clip(wr, w, h, 3).ok());  // frames 1 and 2 are ignored
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"still.PNG"});

  int rw = 0, rh = 0, channels = 0;
  unsigned char* p = stbi_load(path.c_str(), &rw, &rh, &channels, 3);
  ASSERT_NE(p, nullptr) << stbi_failure_reason();
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  const synthetic_frame first(w, h, 0);
  bool equal = rw == w && rh == h;
  for (int y = 0; equal && y < h; ++y)
    equal = std::equal(first.pixels.begin() + static_cast<std::ptrdiff_t>(y) * first.stride,
                       first.pixels.begin() + static_cast<std::ptrdiff_t>(y) * first.stride + w * 3,
                       p + static_cast<std::ptrdiff_t>(y) * w * 3);
  stbi_image_free(p);
  EXPECT_TRUE(equal) << "the PNG differs from the first frame written";
}

// ---- atomicity -----------------------------------------------------------------------------

TEST(video_writer, AbandonedWritersLeaveNothing) {
  SKIP_WITHOUT_FFMPEG();
  for (const char* name : {"a.mp4", "a.avi", "f_%02d.png", "one.png"}) {
    SCOPED_TRACE(name);
    test::temp_dir dir("vw_abandon");
    {
      video_writer wr;
      ASSERT_TRUE(wr.open(dir.file(name), 32, 32, k_fps).ok());
      for (int i = 0; i < 3; ++i) {
        const synthetic_frame f(32, 32, i);
        ASSERT_TRUE(wr.write(f.view(), i / k_fps).ok());
      }
      EXPECT_FALSE(dir.entries().empty());  // the temporary file(s)
      for (const std::string& e : dir.entries()) EXPECT_TRUE(contains(e, ".tmp.")) << e;
    }  // destroyed without close()
    EXPECT_TRUE(dir.entries().empty());
  }
}

TEST(video_writer, ReopeningDiscardsTheUnclosedFile) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_reopen");
  video_writer wr;
  ASSERT_TRUE(wr.open(dir.file("first.mp4"), 32, 32, k_fps).ok());
  const synthetic_frame f(32, 32, 0);
  ASSERT_TRUE(wr.write(f.view(), 0).ok());
  ASSERT_TRUE(wr.open(dir.file("second.png"), 32, 32, k_fps).ok());
  ASSERT_TRUE(wr.write(f.view(), 0).ok());
  ASSERT_TRUE(wr.close().ok());
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"second.png"});
}

TEST(video_writer, ExistingFileIsReplacedOnlyByClose) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_replace");
  const std::string path = dir.file("out.mp4");
  test::write_text(path, "old");
  {
    video_writer wr;
    ASSERT_TRUE(wr.open(path, 32, 32, k_fps).ok());
    const synthetic_frame f(32, 32, 0);
    ASSERT_TRUE(wr.write(f.view(), 0).ok());
  }
  EXPECT_EQ(test::read_text(path), "old");  // abandoned: untouched
  video_writer wr;
  ASSERT_TRUE(wr.open(path, 32, 32, k_fps).ok());
  const synthetic_frame f(32, 32, 0);
  ASSERT_TRUE(wr.write(f.view(), 0).ok());
  EXPECT_EQ(test::read_text(path), "old");  // still, until close()
  ASSERT_TRUE(wr.close().ok());
  const std::string now = test::read_text(path);
  ASSERT_GT(now.size(), 8u);
  EXPECT_EQ(now.substr(4, 4), "ftyp");  // an MP4 now
  EXPECT_EQ(dir.entries().size(), 1u);
}

TEST(video_writer, FailuresLeaveNothingUnderTheFinalName) {
  SKIP_WITHOUT_FFMPEG();
  // The folder disappears while a PNG sequence is written: the next file cannot be created.
  {
    test::temp_dir dir("vw_fail");
    const fs::path sub = dir.path() / "out";
    fs::create_directories(sub);
    video_writer wr;
    const std::string pattern = (sub / "f_%03d.png").string();
    ASSERT_TRUE(wr.open(pattern, 16, 16, k_fps).ok());
    const synthetic_frame f(16, 16, 0);
    ASSERT_TRUE(wr.write(f.view(), 0).ok());
    fs::remove_all(sub);
    const status st = wr.write(f.view(), 1 / k_fps);
    ASSERT_FALSE(st.ok());
    EXPECT_TRUE(contains(st.message(), pattern)) << st.message();
    EXPECT_FALSE(wr.is_open());
    const status again = wr.write(f.view(), 2 / k_fps);
    EXPECT_FALSE(again.ok());
    EXPECT_EQ(again.message(), st.message());
    EXPECT_FALSE(wr.close().ok());
    EXPECT_TRUE(dir.entries().empty());
  }
  // The folder disappears under a video: close() cannot rename it into place.
  {
    test::temp_dir dir("vw_fail2");
    const fs::path sub = dir.path() / "out";
    fs::create_directories(sub);
    const std::string path = (sub / "v.mp4").string();
    video_writer wr;
    ASSERT_TRUE(wr.open(path, 16, 16, k_fps).ok());
    const synthetic_frame f(16, 16, 0);
    ASSERT_TRUE(wr.write(f.view(), 0).ok());
    fs::remove_all(sub);
    const status st = wr.close();
    ASSERT_FALSE(st.ok());
    EXPECT_TRUE(contains(st.message(), path)) << st.message();
    EXPECT_FALSE(fs::exists(path));
    EXPECT_TRUE(dir.entries().empty());
  }
  // No frame at all: close() says so and makes no file.
  {
    test::temp_dir dir("vw_fail3");
    video_writer wr;
    ASSERT_TRUE(wr.open(dir.file("empty.mp4"), 16, 16, k_fps).ok());
    const status st = wr.close();
    ASSERT_FALSE(st.ok());
    EXPECT_TRUE(contains(st.message(), "no frame")) << st.message();
    EXPECT_TRUE(dir.entries().empty());
  }
}

// ---- errors --------------------------------------------------------------------------------

TEST(video_writer, BadOpenArgumentsAreRefusedNamingThePath) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_errors");
  test::write_text(dir.file("plain_file"), "x");
  fs::create_directories(dir.path() / "folder.mp4");
  const std::string ok_path = dir.file("ok.mp4");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct bad_case {
    std::string path;
    int w, h;
    double fps;
    video_writer_options options;
    std::string expect;  // part of the message besides the path
  };
  video_writer_options crf;
  crf.crf = 52;
  video_writer_options enc;
  enc.encoder = "h265";
  video_writer_options threads;
  threads.max_threads = 65;
  video_writer_options quality;
  quality.mpeg4_quality = 0;
  video_writer_options x264_avi;
  x264_avi.encoder = "libx264";
  video_writer_options first;
  first.first_number = -1;
  const std::vector<bad_case> cases = {
      {ok_path, 0, 48, k_fps, {}, "size"},
      {ok_path, 64, 0, k_fps, {}, "size"},
      {ok_path, -64, 48, k_fps, {}, "size"},
      {ok_path, 100000, 48, k_fps, {}, "size"},
      {ok_path, 16385, 16, k_fps, {}, "size"},
      {ok_path, 64, 48, 0.0, {}, "fps"},
      {ok_path, 64, 48, -30.0, {}, "fps"},
      {ok_path, 64, 48, nan, {}, "fps"},
      {ok_path, 64, 48, std::numeric_limits<double>::infinity(), {}, "fps"},
      {ok_path, 64, 48, 5000.0, {}, "fps"},
      {ok_path, 64, 48, k_fps, crf, "crf"},
      {ok_path, 64, 48, k_fps, enc, "encoder"},
      {ok_path, 64, 48, k_fps, threads, "max_threads"},
      {ok_path, 64, 48, k_fps, quality, "mpeg4_quality"},
      {dir.file("a%d.png"), 64, 48, k_fps, first, "first_number"},
      {dir.file("clip.xyz"), 64, 48, k_fps, {}, "unknown output format"},
      {dir.file("noextension"), 64, 48, k_fps, {}, "unknown output format"},
      {dir.file("a%s.png"), 64, 48, k_fps, {}, "%d"},
      {dir.file("a%d_%d.png"), 64, 48, k_fps, {}, "%d"},
      {dir.file("missing/clip.mp4"), 64, 48, k_fps, {}, "does not exist"},
      {dir.file("plain_file/clip.mp4"), 64, 48, k_fps, {}, "does not exist"},
      {dir.file("folder.mp4"), 64, 48, k_fps, {}, "is a folder"},
      {dir.file("clip.avi"), 64, 48, k_fps, x264_avi, "libx264"},
  };
  for (const bad_case& c : cases) {
    video_writer wr;
    const status st = wr.open(c.path, c.w, c.h, c.fps, c.options);
    ASSERT_FALSE(st.ok()) << c.path << " " << c.w << "x" << c.h << " fps " << c.fps;
    EXPECT_TRUE(contains(st.message(), c.path)) << st.message();
    EXPECT_TRUE(contains(st.message(), c.expect)) << st.message();
    EXPECT_FALSE(wr.is_open());
  }
  // Nothing was created by the failed attempts.
  std::vector<std::string> names = dir.entries();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"folder.mp4", "plain_file"}));
}

TEST(video_writer, UnknownX264PresetFailsOpen) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_preset");
  video_writer probe;
  ASSERT_TRUE(probe.open(dir.file("probe.mp4"), 16, 16, k_fps).ok());
  if (probe.encoder_name() != "libx264") GTEST_SKIP() << "no libx264 in this FFmpeg";
  probe = video_writer();  // discarded
  video_writer_options o;
  o.preset = "nonsense";
  video_writer wr;
  const status st = wr.open(dir.file("clip.mp4"), 16, 16, k_fps, o);
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.message(), "nonsense")) << st.message();
  EXPECT_TRUE(dir.entries().empty());
}

TEST(video_writer, BadFramesAreRefusedAndTheWriterGoesOn) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_frames");
  const std::string path = dir.file("clip.mkv");
  video_writer wr;
  const synthetic_frame good(64, 48, 0);
  EXPECT_FALSE(wr.write(good.view(), 0).ok());  // not open
  ASSERT_TRUE(wr.open(path, 64, 48, k_fps).ok());

  const synthetic_frame small(32, 48, 0);
  status st = wr.write(small.view(), 0);
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.message(), path)) << st.message();
  EXPECT_TRUE(contains(st.message(), "32x48")) << st.message();
  EXPECT_TRUE(contains(st.message(), "64x48")) << st.message();

  image_view v = good.view();
  v.format = pixel_format::bgr8;
  EXPECT_FALSE(wr.write(v, 0).ok());
  v = good.view();
  v.data = nullptr;
  EXPECT_FALSE(wr.write(v, 0).ok());
  v = good.view();
  v.stride_bytes = 64 * 3 - 1;
  EXPECT_FALSE(wr.write(v, 0).ok());
  EXPECT_EQ(wr.frames_written(), 0);

  EXPECT_TRUE(wr.is_open());
  ASSERT_TRUE(wr.write(good.view(), 0).ok());
  ASSERT_TRUE(wr.write(good.view(), 1 / k_fps).ok());
  st = wr.close();
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_FALSE(wr.write(good.view(), 2 / k_fps).ok());  // closed
  EXPECT_TRUE(wr.close().ok());                         // closing twice is harmless
  std::string error;
  EXPECT_EQ(read_all(path, error).size(), 2u) << error;
}

TEST(video_writer, MovedWriterKeepsWriting) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vw_move");
  video_writer a;
  ASSERT_TRUE(a.open(dir.file("m.avi"), 32, 32, k_fps).ok());
  const synthetic_frame f(32, 32, 0);
  ASSERT_TRUE(a.write(f.view(), 0).ok());
  video_writer b(std::move(a));
  ASSERT_TRUE(b.write(f.view(), 1 / k_fps).ok());
  ASSERT_TRUE(b.close().ok());
  std::string error;
  EXPECT_EQ(read_all(dir.file("m.avi"), error).size(), 2u) << error;
}

}  // namespace
}  // namespace avatarmap
