#include "avatarmap/media/video_source.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

// The one definition of stb_image in media_tests (Debian's libstb-dev); decoding only the
// formats the tests write.
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_NO_STDIO_WARNINGS
#include <stb/stb_image.h>

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

std::string tfjs(const std::string& name) {
  const std::string dir = test::test_data_path("motion/tfjs-models/");
  return dir.empty() ? "" : dir + name;
}

#define SKIP_WITHOUT_FFMPEG() \
  if (!video_source_available()) GTEST_SKIP() << "built without FFmpeg"

#define SKIP_WITHOUT_DATA() \
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data

// Everything a source gives, up to `limit` calls of next().
struct drained {
  std::vector<double> times;
  std::vector<std::string> errors;
  int width = 0;
  int height = 0;
  bool ended = false;
};

drained drain(video_source& src, int limit = 10000) {
  drained d;
  for (int i = 0; i < limit; ++i) {
    image_view v;
    double t = -1.0;
    const read_result r = src.next(v, t);
    if (r == read_result::end) {
      d.ended = true;
      break;
    }
    if (r == read_result::error) {
      d.errors.push_back(src.error());
      continue;
    }
    EXPECT_NE(v.data, nullptr);
    EXPECT_EQ(v.format, pixel_format::rgb8);
    EXPECT_GE(v.stride_bytes, v.width * 3);
    d.width = v.width;
    d.height = v.height;
    d.times.push_back(t);
  }
  return d;
}

// A binary PPM (P6) image whose pixel (x, y) is (x * 7 + y, y * 5, 255 - x).
std::string ppm(int w, int h, int shift = 0) {
  std::string s = "P6\n" + std::to_string(w) + " " + std::to_string(h) + "\n255\n";
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      s += static_cast<char>((x * 7 + y + shift) & 255);
      s += static_cast<char>((y * 5) & 255);
      s += static_cast<char>((255 - x) & 255);
    }
  return s;
}

// Silences FFmpeg's stderr log for a test that feeds it broken data on purpose.
struct quiet_log {
  quiet_log() { video_source_quiet_log(true); }
  ~quiet_log() { video_source_quiet_log(false); }
};

void copy(const std::string& from, const std::string& to) {
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

// ---- without FFmpeg ------------------------------------------------------------------------

TEST(VideoSource, StubSaysBuiltWithoutFfmpeg) {
  if (video_source_available()) GTEST_SKIP() << "built with FFmpeg";
  video_source src;
  const status st = src.open("clip.mp4");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("without FFmpeg"), std::string::npos) << st.message();
  image_view v;
  double t = 0;
  EXPECT_EQ(src.next(v, t), read_result::error);
}

// ---- synthetic inputs (always run) ---------------------------------------------------------

TEST(VideoSource, NotOpenGivesError) {
  video_source src;
  image_view v;
  double t = 0;
  EXPECT_FALSE(src.is_open());
  EXPECT_EQ(src.next(v, t), read_result::error);
}

TEST(VideoSource, BadOptionsAreRefused) {
  test::temp_dir dir("vs_opts");
  test::write_text(dir.file("a.ppm"), ppm(4, 4));
  video_source src;
  video_source_options o;
  o.output_format = pixel_format::bgr8;
  EXPECT_NE(src.open(dir.file("a.ppm"), o).message().find("rgb8"), std::string::npos);
  o = {};
  o.max_threads = -1;
  EXPECT_NE(src.open(dir.file("a.ppm"), o).message().find("max_threads"), std::string::npos);
  o = {};
  o.sequence_fps = 0.0;
  EXPECT_NE(src.open(dir.file("a.ppm"), o).message().find("sequence_fps"), std::string::npos);
  o = {};
  o.max_size = 20000;
  EXPECT_NE(src.open(dir.file("a.ppm"), o).message().find("max_size"), std::string::npos);
}

TEST(VideoSource, PpmImageIsExact) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vs_ppm");
  const std::string path = dir.file("a.ppm");
  test::write_text(path, ppm(37, 21));
  video_source src;
  ASSERT_TRUE(src.open(path).ok()) << src.open(path).message();
  EXPECT_EQ(src.info().kind, video_source_kind::image);
  EXPECT_EQ(src.info().width, 37);
  EXPECT_EQ(src.info().height, 21);
  EXPECT_EQ(src.info().frame_count, 1);
  image_view v;
  double t = -1;
  ASSERT_EQ(src.next(v, t), read_result::frame) << src.error();
  EXPECT_EQ(t, 0.0);
  ASSERT_EQ(v.width, 37);
  ASSERT_EQ(v.height, 21);
  for (int y = 0; y < 21; ++y)
    for (int x = 0; x < 37; ++x) {
      const std::uint8_t* p = v.data + y * v.stride_bytes + x * 3;
      ASSERT_EQ(p[0], (x * 7 + y) & 255) << x << "," << y;
      ASSERT_EQ(p[1], (y * 5) & 255);
      ASSERT_EQ(p[2], (255 - x) & 255);
    }
  EXPECT_EQ(src.next(v, t), read_result::end);
  EXPECT_EQ(src.next(v, t), read_result::end);
}

TEST(VideoSource, ExistingFileWithPercentOrColonIsThatFile) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vs_names");
  for (const char* name : {"a%05d.ppm", "concat:b.ppm"}) {
    test::write_text(dir.file(name), ppm(5, 3));
    video_source src;
    ASSERT_TRUE(src.open(dir.file(name)).ok()) << src.open(dir.file(name)).message();
    EXPECT_EQ(src.info().kind, video_source_kind::image) << name;
    const drained d = drain(src);
    EXPECT_EQ(d.times.size(), 1u) << name;
    EXPECT_EQ(d.width, 5);
  }
}

TEST(VideoSource, GrayImageIsFullRange) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vs_pgm");
  const std::string path = dir.file("g.pgm");
  test::write_text(path, "P5\n4 2\n255\n" + std::string("\x00\x10\x80\xff\x01\x02\xc8\xfe", 8));
  video_source src;
  ASSERT_TRUE(src.open(path).ok());
  image_view v;
  double t;
  ASSERT_EQ(src.next(v, t), read_result::frame) << src.error();
  const int expected[8] = {0x00, 0x10, 0x80, 0xff, 0x01, 0x02, 0xc8, 0xfe};
  for (int i = 0; i < 8; ++i) {
    const std::uint8_t* p = v.data + (i / 4) * v.stride_bytes + (i % 4) * 3;
    EXPECT_EQ(p[0], expected[i]) << i;
    EXPECT_EQ(p[1], expected[i]) << i;
    EXPECT_EQ(p[2], expected[i]) << i;
  }
}

TEST(VideoSource, FolderAndPatternSequences) {
  SKIP_WITHOUT_FFMPEG();
  test::temp_dir dir("vs_seq");
  // Written out of order; the folder is read sorted by name.
  for (int i : {2, 0, 1}) {
    char name[32];
    std::snprintf(name, sizeof name, "%05d.ppm", i + 1);
    test::write_text(dir.file(name), ppm(8, 6, i * 10));
  }
  test::write_text(dir.file("notes.txt"), "not an image");

  video_source_options o;
  o.sequence_fps = 10.0;
  for (const std::string& path : {dir.path().string(), dir.file("%05d.ppm")}) {
    video_source src;
    ASSERT_TRUE(src.open(path, o).ok()) << path << ": " << src.open(path, o).message();
    EXPECT_EQ(src.info().kind, video_source_kind::sequence);
    EXPECT_EQ(src.info().frame_count, 3);
    EXPECT_EQ(src.info().width, 8);
    EXPECT_DOUBLE_EQ(src.info().fps, 10.0);
    for (int i = 0; i < 3; ++i) {
      image_view v;
      double t = -1;
      ASSERT_EQ(src.next(v, t), read_result::frame) << src.error();
      EXPECT_DOUBLE_EQ(t, i / 10.0);
      EXPECT_EQ(v.data[0], i * 10) << path << " frame " << i;  // in order
    }
    image_view v;
    double t;
    EXPECT_EQ(src.next(v, t), read_result::end);
  }
}

TEST(VideoSource, BrokenImageInASequenceIsReportedAndSkipped) {
  SKIP_WITHOUT_FFMPEG();
  const quiet_log quiet;
  test::temp_dir dir("vs_seqbad");
  test::write_text(dir.file("a.ppm"), ppm(8, 6));
  test::write_text(dir.file("b.ppm"), "P6\n8 6\n255\nshort");
  test::write_text(dir.file("c.ppm"), ppm(8, 6));
  video_source src;
  ASSERT_TRUE(src.open(dir.path().string()).ok());
  const drained d = drain(src);
  EXPECT_TRUE(d.ended);
  EXPECT_EQ(d.times.size(), 2u);
  ASSERT_EQ(d.errors.size(), 1u);
  EXPECT_NE(d.errors[0].find("b.ppm"), std::string::npos) << d.errors[0];
}

TEST(VideoSource, OpenErrorsNameThePath) {
  SKIP_WITHOUT_FFMPEG();
  const quiet_log quiet;
  test::temp_dir dir("vs_err");
  video_source src;

  status st = src.open(dir.file("missing.mp4"));
  EXPECT_NE(st.message().find("missing.mp4"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("no such file"), std::string::npos) << st.message();

  test::write_text(dir.file("empty.mp4"), "");
  st = src.open(dir.file("empty.mp4"));
  EXPECT_NE(st.message().find("empty.mp4: empty file"), std::string::npos) << st.message();

  st = src.open(dir.file("frames/%05d.png"));
  EXPECT_NE(st.message().find("no file matches"), std::string::npos) << st.message();
  st = src.open(dir.file("frames/%s.png"));
  EXPECT_NE(st.message().find("pattern"), std::string::npos) << st.message();

  fs::create_directories(dir.file("no_images"));
  test::write_text(dir.file("no_images/readme.txt"), "x");
  st = src.open(dir.file("no_images"));
  EXPECT_NE(st.message().find("no image files"), std::string::npos) << st.message();

  // A WAV file: a media file, but audio only.
  std::string wav = "RIFF";
  const auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) wav += static_cast<char>((v >> (8 * i)) & 255);
  };
  const auto u16 = [&](std::uint16_t v) {
    wav += static_cast<char>(v & 255);
    wav += static_cast<char>(v >> 8);
  };
  const std::uint32_t samples = 8000;
  u32(36 + samples * 2);
  wav += "WAVEfmt ";
  u32(16);
  u16(1);  // PCM
  u16(1);  // mono
  u32(8000);
  u32(16000);
  u16(2);
  u16(16);
  wav += "data";
  u32(samples * 2);
  wav += std::string(samples * 2, '\0');
  test::write_text(dir.file("audio.wav"), wav);
  st = src.open(dir.file("audio.wav"));
  EXPECT_NE(st.message().find("audio.wav: no video stream"), std::string::npos) << st.message();

  EXPECT_FALSE(src.is_open());
}

TEST(VideoSource, CameraThatCannotOpenIsNamed) {
  SKIP_WITHOUT_FFMPEG();
  video_source src;
  const status st = src.open("v4l2:/dev/video0");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("v4l2"), std::string::npos) << st.message();
}

TEST(VideoSource, ZeroSizeAndHugeImagesAreRefused) {
  SKIP_WITHOUT_FFMPEG();
  const quiet_log quiet;
  test::temp_dir dir("vs_size");
  video_source src;
  test::write_text(dir.file("huge.ppm"), "P6\n20000 20000\n255\n" + std::string(300, 'x'));
  status st = src.open(dir.file("huge.ppm"));
  if (st.ok()) {
    const drained d = drain(src, 10);  // refused by the decoder at the latest
    EXPECT_TRUE(d.times.empty());
  } else {
    EXPECT_NE(st.message().find("huge.ppm"), std::string::npos) << st.message();
  }
  test::write_text(dir.file("ok.ppm"), ppm(64, 48));
  video_source_options o;
  o.max_size = 32;
  st = src.open(dir.file("ok.ppm"), o);
  EXPECT_NE(st.message().find("64x48, larger than the 32x32 limit"), std::string::npos)
      << st.message();

  test::write_text(dir.file("zero.ppm"), "P6\n0 0\n255\n");
  st = src.open(dir.file("zero.ppm"));
  if (st.ok()) {
    const drained d = drain(src, 10);
    EXPECT_TRUE(d.times.empty());
  } else {
    EXPECT_NE(st.message().find("zero.ppm"), std::string::npos) << st.message();
  }
}

TEST(VideoSource, GarbageNeverCrashes) {
  SKIP_WITHOUT_FFMPEG();
  const quiet_log quiet;
  test::temp_dir dir("vs_garbage");
  std::mt19937 rng(11);
  std::string bytes(64 * 1024, '\0');
  for (auto& c : bytes) c = static_cast<char>(rng());
  test::write_text(dir.file("random.mp4"), bytes);
  test::write_text(dir.file("text.jpg"), "this is a text file, not a JPEG\n");
  for (const char* name : {"random.mp4", "text.jpg"}) {
    video_source src;
    const status st = src.open(dir.file(name));
    if (!st.ok()) {
      EXPECT_NE(st.message().find(name), std::string::npos) << st.message();
      continue;
    }
    const drained d = drain(src, 1000);
    EXPECT_TRUE(d.ended) << name;
    for (const auto& e : d.errors) EXPECT_NE(e.find(name), std::string::npos) << e;
  }
}

// ---- real data ($AVATARMAP_TEST_DATA) ------------------------------------------------------

TEST(VideoSource, PoseSquatsMp4) {
  SKIP_WITHOUT_FFMPEG();
  SKIP_WITHOUT_DATA();
  video_source src;
  const std::string path = tfjs("pose_squats.mp4");
  ASSERT_TRUE(src.open(path).ok()) << src.open(path).message();
  const video_info& info = src.info();
  EXPECT_EQ(info.kind, video_source_kind::video);
  EXPECT_EQ(info.width, 720);
  EXPECT_EQ(info.height, 1280);
  EXPECT_NEAR(info.fps, 5.0, 1e-6);
  EXPECT_EQ(info.frame_count, 65);
  EXPECT_NEAR(info.duration, 13.0, 0.21);
  EXPECT_EQ(info.codec, "h264");
  const drained d = drain(src);
  EXPECT_TRUE(d.ended);
  EXPECT_TRUE(d.errors.empty()) << d.errors.front();
  ASSERT_EQ(d.times.size(), 65u);
  EXPECT_EQ(d.width, 720);
  EXPECT_EQ(d.height, 1280);
  for (std::size_t i = 0; i < d.times.size(); ++i) EXPECT_NEAR(d.times[i], 0.2 * i, 1e-6) << i;
}

TEST(VideoSource, AslHandMp4At25Fps) {
  SKIP_WITHOUT_FFMPEG();
  SKIP_WITHOUT_DATA();
  video_source src;
  const std::string path = tfjs("asl_hand.25fps.mp4");
  ASSERT_TRUE(src.open(path).ok()) << src.open(path).message();
  EXPECT_NEAR(src.info().fps, 25.0, 1e-6);
  const drained d = drain(src);
  EXPECT_TRUE(d.ended);
  EXPECT_TRUE(d.errors.empty());
  ASSERT_FALSE(d.times.empty());
  if (src.info().frame_count > 0)
    EXPECT_EQ(static_cast<std::int64_t>(d.times.size()), src.info().frame_count);
  EXPECT_EQ(d.width, src.info().width);
  EXPECT_EQ(d.height, src.info().height);
  EXPECT_EQ(d.times.front(), 0.0);
  for (std::size_t i = 1; i < d.times.size(); ++i)
    EXPECT_NEAR(d.times[i] - d.times[i - 1], 0.04, 1e-6) << i;
}

TEST(VideoSource, Photos) {
  SKIP_WITHOUT_FFMPEG();
  SKIP_WITHOUT_DATA();
  struct photo {
    const char* name;
    int width, height;
  };
  for (const photo& p : {photo{"pose.jpg", 1000, 667}, photo{"hands.jpg", 720, 382},
                         photo{"portrait.jpg", 820, 1024}}) {
    video_source src;
    const std::string path = tfjs(p.name);
    ASSERT_TRUE(src.open(path).ok()) << src.open(path).message();
    EXPECT_EQ(src.info().kind, video_source_kind::image);
    EXPECT_EQ(src.info().codec, "mjpeg");
    const drained d = drain(src);
    ASSERT_EQ(d.times.size(), 1u) << p.name;
    EXPECT_EQ(d.times[0], 0.0);
    EXPECT_EQ(d.width, p.width) << p.name;
    EXPECT_EQ(d.height, p.height) << p.name;
  }
}

TEST(VideoSource, JpegPixelsMatchStbImage) {
  SKIP_WITHOUT_FFMPEG();
  SKIP_WITHOUT_DATA();
  const std::string path = tfjs("pose.jpg");
  int w = 0, h = 0, n = 0;
  unsigned char* ref = stbi_load(path.c_str(), &w, &h, &n, 3);
  ASSERT_NE(ref, nullptr) << stbi_failure_reason();
  video_source src;
  ASSERT_TRUE(src.open(path).ok());
  image_view v;
  double t;
  ASSERT_EQ(src.next(v, t), read_result::frame) << src.error();
  ASSERT_EQ(v.width, w);
  ASSERT_EQ(v.height, h);
  // Decoders differ by a few levels (IDCT, chroma upsampling): a per-pixel bound at a few
  // points and a tight mean over the whole image.
  double sum = 0.0;
  int worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(v.data[y * v.stride_bytes + x * 3 + c] - ref[(y * w + x) * 3 + c]);
        sum += d;
        worst = std::max(worst, d);
      }
  const double mean = sum / (3.0 * w * h);
  for (const auto& xy : {std::pair{10, 10}, std::pair{500, 333}, std::pair{999, 666},
                         std::pair{250, 600}, std::pair{750, 100}}) {
    for (int c = 0; c < 3; ++c) {
      const int a = v.data[xy.second * v.stride_bytes + xy.first * 3 + c];
      const int b = ref[(xy.second * w + xy.first) * 3 + c];
      EXPECT_LE(std::abs(a - b), 8) << xy.first << "," << xy.second << " channel " << c;
    }
  }
  EXPECT_LT(mean, 1.5) << "worst " << worst;
  stbi_image_free(ref);
}

TEST(VideoSource, JpegSequenceFromFolderAndPattern) {
  SKIP_WITHOUT_FFMPEG();
  SKIP_WITHOUT_DATA();
  test::temp_dir dir("vs_jpgseq");
  for (int i = 1; i <= 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%05d.jpg", i);
    copy(tfjs("hands.jpg"), dir.file(name));
  }
  for (const std::string& path : {dir.path().string(), dir.file("%05d.jpg")}) {
    video_source src;
    ASSERT_TRUE(src.open(path).ok()) << src.open(path).message();
    EXPECT_EQ(src.info().frame_count, 3);
    EXPECT_DOUBLE_EQ(src.info().fps, 30.0);
    const drained d = drain(src);
    EXPECT_TRUE(d.errors.empty());
    ASSERT_EQ(d.times.size(), 3u) << path;
    EXPECT_EQ(d.width, 720);
    EXPECT_EQ(d.height, 382);
    EXPECT_DOUBLE_EQ(d.times[2], 2.0 / 30.0);
  }
}

TEST(VideoSource, TruncatedMp4NeverCrashes) {
  SKIP_WITHOUT_FFMPEG();
  const quiet_log quiet;
  SKIP_WITHOUT_DATA();
  test::temp_dir dir("vs_trunc");
  const std::string bytes = test::read_text(tfjs("pose_squats.mp4"));
  ASSERT_GT(bytes.size(), 1000u);
  test::write_text(dir.file("cut.mp4"), bytes.substr(0, bytes.size() * 3 / 10));
  video_source src;
  const status st = src.open(dir.file("cut.mp4"));
  if (!st.ok()) {
    // pose_squats.mp4 keeps its index (moov) at the end: cut, it cannot be opened at all.
    EXPECT_NE(st.message().find("cut.mp4"), std::string::npos) << st.message();
    return;
  }
  const drained d = drain(src);
  EXPECT_TRUE(d.ended);
  EXPECT_FALSE(d.times.empty());
}

TEST(VideoSource, TruncatedJpegAndConcatenatedJpegs) {
  SKIP_WITHOUT_FFMPEG();
  SKIP_WITHOUT_DATA();
  const quiet_log quiet;
  test::temp_dir dir("vs_jpgcut");
  const std::string bytes = test::read_text(tfjs("hands.jpg"));
  ASSERT_GT(bytes.size(), 1000u);
  // Half a JPEG: FFmpeg decodes what is there (the rest grey) or reports; never crashes.
  test::write_text(dir.file("half.jpg"), bytes.substr(0, bytes.size() / 2));
  {
    video_source src;
    const status st = src.open(dir.file("half.jpg"));
    if (st.ok()) {
      const drained d = drain(src);
      EXPECT_TRUE(d.ended);
      EXPECT_LE(d.times.size(), 1u);
      EXPECT_EQ(d.times.size() + d.errors.size() > 0, true);
    } else {
      EXPECT_NE(st.message().find("half.jpg"), std::string::npos) << st.message();
    }
  }
  // Three JPEGs in one file, the last cut: a still image is its first picture.
  test::write_text(dir.file("three.jpg"), bytes + bytes + bytes.substr(0, bytes.size() / 2));
  video_source src;
  ASSERT_TRUE(src.open(dir.file("three.jpg")).ok());
  const drained d = drain(src);
  EXPECT_TRUE(d.ended);
  EXPECT_EQ(d.times.size(), 1u);
  EXPECT_TRUE(d.errors.empty());
}

TEST(VideoSource, CorruptMp4DecodesWhatItCanAndGoesOn) {
  SKIP_WITHOUT_FFMPEG();
  const quiet_log quiet;
  SKIP_WITHOUT_DATA();
  test::temp_dir dir("vs_corrupt");
  std::string bytes = test::read_text(tfjs("pose_squats.mp4"));
  ASSERT_GT(bytes.size(), 1000u);
  // Random bytes over 40%..60% of the file (inside the media data; the index at the end
  // stays intact), then the media data cut to zeros from 80% on: both corrupt and
  // "truncated" frames.
  std::mt19937 rng(5);
  for (std::size_t i = bytes.size() * 4 / 10; i < bytes.size() * 6 / 10; ++i)
    bytes[i] = static_cast<char>(rng());
  const std::size_t moov = bytes.rfind("moov");
  ASSERT_NE(moov, std::string::npos);
  for (std::size_t i = bytes.size() * 8 / 10; i + 8 < moov; ++i) bytes[i] = 0;
  test::write_text(dir.file("corrupt.mp4"), bytes);
  video_source src;
  ASSERT_TRUE(src.open(dir.file("corrupt.mp4")).ok());
  const drained d = drain(src);
  EXPECT_TRUE(d.ended);
  EXPECT_GE(d.times.size(), 20u);  // the first 40% at least
  EXPECT_LE(d.times.size(), 65u);
  EXPECT_EQ(d.times.size() + d.errors.size(), 65u);  // one error per broken frame here
  for (const auto& e : d.errors) EXPECT_NE(e.find("corrupt.mp4"), std::string::npos) << e;
  for (std::size_t i = 1; i < d.times.size(); ++i) EXPECT_GT(d.times[i], d.times[i - 1]);
}

}  // namespace
}  // namespace avatarmap
