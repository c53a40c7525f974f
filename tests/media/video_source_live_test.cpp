// Live inputs of video_source (devices and URLs): FFmpeg's lavfi test patterns stand in for a
// camera; a TCP server in the test sends a video the test wrote (known frames), then holds
// the connection open (a stall) or closes it (an end); what cannot be opened gives a message
// that names it and lists what this build has. Skips with a message where this FFmpeg lacks
// lavfi or a protocol.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/media/video_source.hpp"
#include "avatarmap/media/video_writer.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

bool has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

#define SKIP_WITHOUT_FFMPEG() \
  if (!video_source_available()) GTEST_SKIP() << "built without FFmpeg"

#define SKIP_WITHOUT_DEVICE(name)                                  \
  SKIP_WITHOUT_FFMPEG();                                           \
  if (!has(video_source_supported_inputs().devices, name))         \
  GTEST_SKIP() << "this FFmpeg has no '" name                      \
                  "' input device (libavdevice missing, or built " \
                  "without it)"

#define SKIP_WITHOUT_SCHEME(name)                              \
  SKIP_WITHOUT_FFMPEG();                                       \
  if (!has(video_source_supported_inputs().url_schemes, name)) \
  GTEST_SKIP() << "this FFmpeg has no '" name "' protocol"

struct quiet_log {
  quiet_log() { video_source_quiet_log(true); }
  ~quiet_log() { video_source_quiet_log(false); }
};

// A frame as the test keeps it: its time and its mean colour.
struct seen {
  double t;
  double rgb[3];
};

// next() until end (at most `limit` calls); read errors fail the test.
std::vector<seen> drain(video_source& src, int limit = 1000) {
  std::vector<seen> r;
  for (int i = 0; i < limit; ++i) {
    image_view v;
    double t = 0;
    const read_result res = src.next(v, t);
    if (res == read_result::end) break;
    if (res == read_result::error) {
      ADD_FAILURE() << "read error: " << src.error();
      continue;
    }
    seen s{t, {0, 0, 0}};
    for (int y = 0; y < v.height; ++y)
      for (int x = 0; x < v.width; ++x)
        for (int c = 0; c < 3; ++c) s.rgb[c] += v.data[y * v.stride_bytes + x * 3 + c];
    for (double& c : s.rgb) c /= static_cast<double>(v.width) * v.height;
    r.push_back(s);
  }
  return r;
}

// A free local port of the given socket type (bound, read back, released).
int free_port(int type) {
  const int fd = ::socket(AF_INET, type, 0);
  if (fd < 0) return 0;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0)
    port = ntohs(a.sin_port);
  ::close(fd);
  return port;
}

// A TCP server on 127.0.0.1: sends `bytes` to the first client, then either closes the
// connection (an end) or holds it open without sending (a stall) until release() or the
// destructor. Waits at most 30 s for the client.
class tcp_sender {
 public:
  tcp_sender(std::string bytes, bool hold) : bytes_(std::move(bytes)), hold_(hold) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    const int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (listen_fd_ >= 0 && ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
        ::listen(listen_fd_, 1) == 0 &&
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len) == 0)
      port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~tcp_sender() {
    release();
    thread_.join();
    if (listen_fd_ >= 0) ::close(listen_fd_);
  }
  int port() const { return port_; }
  std::string url() const { return "tcp://127.0.0.1:" + std::to_string(port_); }
  void release() {
    std::lock_guard<std::mutex> lock(m_);
    released_ = true;
    cv_.notify_all();
  }

 private:
  void serve() {
    if (port_ == 0) return;
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, 30000) != 1) return;
    const int fd = ::accept(listen_fd_, nullptr, nullptr);
    if (fd < 0) return;
    for (std::size_t sent = 0; sent < bytes_.size();) {
      const ssize_t n = ::send(fd, bytes_.data() + sent, bytes_.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;
      sent += static_cast<std::size_t>(n);
    }
    if (hold_) {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait_for(lock, std::chrono::seconds(60), [&] { return released_; });
    }
    ::close(fd);
  }

  std::string bytes_;
  bool hold_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::mutex m_;
  std::condition_variable cv_;
  bool released_ = false;
  std::thread thread_;
};

constexpr int k_frames = 12;
constexpr double k_fps = 10.0;

// Frame i of the test video: one grey level, 40 + 15 i.
int level(int i) { return 40 + 15 * i; }

// Writes the test video (Matroska: readable from a stream) and returns its bytes; "" with a
// failure recorded when it cannot.
std::string test_video(const test::temp_dir& dir) {
  video_writer w;
  const std::string path = dir.file("clip.mkv");
  status st = w.open(path, 64, 48, k_fps);
  if (!st) {
    ADD_FAILURE() << st.message();
    return "";
  }
  std::vector<std::uint8_t> px(64 * 48 * 3);
  for (int i = 0; i < k_frames && st; ++i) {
    std::fill(px.begin(), px.end(), static_cast<std::uint8_t>(level(i)));
    st = w.write({px.data(), 64, 48, 64 * 3, pixel_format::rgb8}, i / k_fps);
  }
  if (st) st = w.close();
  if (!st) {
    ADD_FAILURE() << st.message();
    return "";
  }
  return test::read_text(path);
}

void expect_test_frames(const std::vector<seen>& frames) {
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(k_frames));
  for (int i = 0; i < k_frames; ++i) {
    EXPECT_NEAR(frames[i].t, i / k_fps, 1e-3) << "frame " << i;
    for (double c : frames[i].rgb) EXPECT_NEAR(c, level(i), 6.0) << "frame " << i;
  }
}

// ---- what this build reads ----------------------------------------------------------------

TEST(VideoSourceLive, SupportedInputsAreNetworkProtocolsOnly) {
  SKIP_WITHOUT_FFMPEG();
  const video_source_inputs in = video_source_supported_inputs();
  EXPECT_TRUE(std::is_sorted(in.url_schemes.begin(), in.url_schemes.end()));
  for (const char* s : {"udp", "tcp", "rtp", "http"})
    EXPECT_TRUE(has(in.url_schemes, s)) << s << " (every FFmpeg with networking has it)";
  // Local protocols and helpers are never offered: a URL cannot name a local file.
  for (const char* s : {"file", "pipe", "fd", "concat", "concatf", "subfile", "data", "unix",
                        "cache", "async", "crypto", "httpproxy"})
    EXPECT_FALSE(has(in.url_schemes, s)) << s;
  if (has(in.devices, "v4l2")) EXPECT_TRUE(has(in.devices, "video4linux2")) << "both names";
}

// ---- devices ------------------------------------------------------------------------------

TEST(VideoSourceLive, LavfiTestPatternIsADevice) {
  SKIP_WITHOUT_DEVICE("lavfi");
  video_source src;
  const status st = src.open("lavfi:testsrc=size=64x48:rate=25:duration=1");
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(src.info().kind, video_source_kind::camera);
  EXPECT_EQ(src.info().width, 64);
  EXPECT_EQ(src.info().height, 48);
  EXPECT_DOUBLE_EQ(src.info().fps, 25.0);
  const std::vector<seen> frames = drain(src);
  ASSERT_EQ(frames.size(), 25u) << "1 s at 25 frames/s";
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_NEAR(frames[i].t, i / 25.0, 1e-9);
  EXPECT_TRUE(contains(src.end_reason(), "the device ended")) << src.end_reason();
}

TEST(VideoSourceLive, LavfiColourArrivesAsGiven) {
  SKIP_WITHOUT_DEVICE("lavfi");
  video_source src;
  const status st = src.open("lavfi:color=c=0x3060C0:size=16x16:rate=10:duration=0.5");
  ASSERT_TRUE(st.ok()) << st.message();
  const std::vector<seen> frames = drain(src);
  ASSERT_EQ(frames.size(), 5u);
  for (const seen& f : frames) {
    EXPECT_NEAR(f.rgb[0], 0x30, 4.0);
    EXPECT_NEAR(f.rgb[1], 0x60, 4.0);
    EXPECT_NEAR(f.rgb[2], 0xC0, 4.0);
  }
}

TEST(VideoSourceLive, DeviceOptionsAreCheckedAgainstTheDevice) {
  SKIP_WITHOUT_DEVICE("lavfi");
  video_source src;
  video_source_options o;
  o.video_size = "320x240";
  status st = src.open("lavfi:testsrc", o);
  EXPECT_TRUE(contains(st.message(), "'lavfi' takes no video size (--video-size)")) << st.message();
  o = {};
  o.framerate = 30;
  st = src.open("lavfi:testsrc", o);
  EXPECT_TRUE(contains(st.message(), "takes no frame rate")) << st.message();
  // Device options for a file or URL.
  test::temp_dir dir("vsl_opts");
  test::write_text(dir.file("a.ppm"), "P6\n1 1\n255\nabc");
  o = {};
  o.input_format = "mjpeg";
  st = src.open(dir.file("a.ppm"), o);
  EXPECT_TRUE(contains(st.message(), "is for devices")) << st.message();
  st = src.open("udp://127.0.0.1:9", o);
  EXPECT_TRUE(contains(st.message(), "is for devices")) << st.message();
  // Malformed values.
  o = {};
  o.video_size = "640-480";
  EXPECT_TRUE(contains(src.open("lavfi:testsrc", o).message(), "video_size"));
  o = {};
  o.input_format = "mjpeg;rm";
  EXPECT_TRUE(contains(src.open("lavfi:testsrc", o).message(), "input_format"));
  o = {};
  o.stall_timeout_seconds = 0;
  EXPECT_TRUE(contains(src.open("lavfi:testsrc", o).message(), "stall_timeout_seconds"));
  EXPECT_FALSE(src.is_open());
}

TEST(VideoSourceLive, MissingCameraAndUnknownDeviceAreNamed) {
  SKIP_WITHOUT_FFMPEG();
  const video_source_inputs in = video_source_supported_inputs();
  video_source src;
  status st = src.open("nosuchdevice:0");
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.message(), "nosuchdevice:0: no such file, and ")) << st.message();
  if (has(in.devices, "lavfi")) {
    EXPECT_TRUE(contains(st.message(), "'nosuchdevice' is not a video input device"))
        << st.message();
    EXPECT_TRUE(contains(st.message(), "lavfi")) << "lists the devices: " << st.message();
  } else {
    EXPECT_TRUE(contains(st.message(), "built without libavdevice")) << st.message();
  }
  if (!has(in.devices, "v4l2")) GTEST_SKIP() << "no v4l2 device in this FFmpeg";
  st = src.open("v4l2:/dev/video99");
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.message(), "v4l2:/dev/video99: cannot open the device")) << st.message();
  EXPECT_TRUE(contains(st.message(), "no camera at /dev/video99 (cameras here: ")) << st.message();
}

// ---- URLs ---------------------------------------------------------------------------------

TEST(VideoSourceLive, UnknownAndLocalSchemesAreRefusedWithTheList) {
  SKIP_WITHOUT_FFMPEG();
  video_source src;
  for (const char* url : {"foo://x", "pipe://0", "concat://a.mp4|b.mp4", "subfile://x", "data://x",
                          "unix:///tmp/s"}) {
    const status st = src.open(url);
    ASSERT_FALSE(st.ok()) << url;
    EXPECT_TRUE(contains(st.message(), "unknown URL scheme")) << st.message();
    EXPECT_TRUE(contains(st.message(), "udp")) << "lists what this build reads: " << st.message();
  }
}

// A playlist from the network that names a local file: refused (the protocol whitelist), and
// the message says so instead of "not a stream FFmpeg can read".
TEST(VideoSourceLive, AStreamThatNamesALocalFileIsRefusedAndSaysSo) {
  SKIP_WITHOUT_SCHEME("http");
  const quiet_log quiet;
  test::temp_dir dir("vsl_hls");
  const std::string local = dir.file("secret.ts");
  test::write_text(local, "not to be read");
  // (A bare path is relative to the playlist's URL: another HTTP request, not a local file.)
  for (const std::string& segment : std::vector<std::string>{"file:" + local, "file://" + local}) {
    SCOPED_TRACE(segment);
    const std::string playlist =
        "#EXTM3U\n#EXT-X-VERSION:3\n#EXT-X-TARGETDURATION:1\n"
        "#EXTINF:1.0,\n" +
        segment + "\n#EXT-X-ENDLIST\n";
    tcp_sender server(
        "HTTP/1.0 200 OK\r\nContent-Type: application/vnd.apple.mpegurl\r\n"
        "Content-Length: " +
            std::to_string(playlist.size()) + "\r\n\r\n" + playlist,
        false);
    ASSERT_GT(server.port(), 0);
    video_source src;
    video_source_options o;
    o.open_timeout_seconds = 5;
    const std::string url = "http://127.0.0.1:" + std::to_string(server.port()) + "/x.m3u8";
    const status st = src.open(url, o);
    ASSERT_FALSE(st.ok());
    EXPECT_TRUE(contains(st.message(), "refuses for network inputs")) << st.message();
    EXPECT_FALSE(contains(st.message(), "not a stream FFmpeg can read")) << st.message();
  }
}

// Credentials in a URL never reach a message.
TEST(VideoSourceLive, MessagesHideAUrlsCredentials) {
  SKIP_WITHOUT_SCHEME("rtsp");
  const quiet_log quiet;
  video_source src;
  const int port = free_port(SOCK_STREAM);
  ASSERT_GT(port, 0);
  const status st = src.open("rtsp://cam:s3cret@127.0.0.1:" + std::to_string(port) + "/x");
  ASSERT_FALSE(st.ok());
  EXPECT_FALSE(contains(st.message(), "s3cret")) << st.message();
  EXPECT_TRUE(contains(st.message(), "rtsp://cam:***@127.0.0.1:")) << st.message();
}

TEST(VideoSourceLive, UnreachableStreamsSayWhy) {
  SKIP_WITHOUT_SCHEME("rtsp");
  const quiet_log quiet;
  video_source src;
  const int port = free_port(SOCK_STREAM);
  ASSERT_GT(port, 0);
  status st = src.open("rtsp://127.0.0.1:" + std::to_string(port) + "/x");
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.message(), "no server at this address and port")) << st.message();
  // UDP has no connection: nothing arrives, and open() gives up after the open time-out.
  video_source_options o;
  o.open_timeout_seconds = 0.3;
  const std::string udp = "udp://127.0.0.1:" + std::to_string(free_port(SOCK_DGRAM));
  st = src.open(udp, o);
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.message(), udp + ": nothing came within 0.3 s (--open-seconds)"))
      << st.message();
}

TEST(VideoSourceLive, TcpStreamGivesEveryFrameThenEnds) {
  SKIP_WITHOUT_SCHEME("tcp");
  test::temp_dir dir("vsl_tcp");
  const std::string bytes = test_video(dir);
  ASSERT_FALSE(bytes.empty());
  tcp_sender server(bytes, false);
  ASSERT_GT(server.port(), 0);
  video_source src;
  const status st = src.open(server.url());
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(src.info().kind, video_source_kind::stream);
  EXPECT_EQ(src.info().width, 64);
  expect_test_frames(drain(src));
  EXPECT_EQ(src.end_reason(), server.url() + ": the stream ended");
}

TEST(VideoSourceLive, StalledStreamEndsAfterTheStallTime) {
  SKIP_WITHOUT_SCHEME("tcp");
  test::temp_dir dir("vsl_stall");
  const std::string bytes = test_video(dir);
  ASSERT_FALSE(bytes.empty());
  tcp_sender server(bytes, true);  // sends, then keeps the connection silent
  video_source src;
  video_source_options o;
  o.stall_timeout_seconds = 0.5;
  const status st = src.open(server.url(), o);
  ASSERT_TRUE(st.ok()) << st.message();
  expect_test_frames(drain(src));  // the decoder's last frames come out after the stall
  EXPECT_EQ(src.end_reason(),
            "no frame from " + server.url() + " for 0.5 s: the stream stalled or ended");
  image_view v;
  double t = 0;
  EXPECT_EQ(src.next(v, t), read_result::end) << "and on every later call";
}

TEST(VideoSourceLive, InterruptEndsABlockedNext) {
  SKIP_WITHOUT_SCHEME("tcp");
  test::temp_dir dir("vsl_int");
  const std::string bytes = test_video(dir);
  ASSERT_FALSE(bytes.empty());
  tcp_sender server(bytes, true);
  video_source src;
  video_source_options o;
  o.stall_timeout_seconds = 60;  // only interrupt() can end it within the test's time
  // Probing a Matroska stream (no decoding times) waits for more frames than the 12 sent:
  // it stops at the open time-out with what it has, and reading goes on.
  o.open_timeout_seconds = 1;
  ASSERT_TRUE(src.open(server.url(), o).ok());
  std::atomic<bool> done{false};
  std::atomic<int> frames{0};
  std::thread reader([&] {
    image_view v;
    double t = 0;
    for (int i = 0; i < 1000; ++i) {
      const read_result r = src.next(v, t);
      if (r == read_result::end) break;
      if (r == read_result::frame) ++frames;
    }
    done = true;
  });
  // Wait (up to 20 s) for the frames that need no more data, then interrupt the blocked read.
  for (int i = 0; i < 200 && !done && frames < 5; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  src.interrupt();
  reader.join();
  EXPECT_TRUE(done.load());
  EXPECT_EQ(frames.load(), k_frames) << "the decoder's last frames are drained after it";
  EXPECT_EQ(src.end_reason(), "") << "an interrupt is the caller's own stop";
}

}  // namespace
}  // namespace avatarmap
