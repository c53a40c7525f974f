// Known answers for classify_input (src/media/input_spec.hpp): which input texts are paths,
// patterns, devices and URLs, and what name and target each gives.
#include "media/input_spec.hpp"

#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "avatarmap/media/video_source.hpp"  // shown_input

namespace avatarmap {
namespace {

struct expected {
  const char* text;
  bool exists;
  input_kind kind;
  const char* name;
  const char* target;
};

const char* kind_name(input_kind k) {
  switch (k) {
    case input_kind::path:
      return "path";
    case input_kind::pattern:
      return "pattern";
    case input_kind::device:
      return "device";
    case input_kind::url:
      return "url";
  }
  return "?";
}

TEST(input_spec, known_answers) {
  const expected cases[] = {
      // Files and folders, existing or not.
      {"take.mp4", false, input_kind::path, "", "take.mp4"},
      {"/data/take.mp4", true, input_kind::path, "", "/data/take.mp4"},
      {"frames", true, input_kind::path, "", "frames"},
      {"", false, input_kind::path, "", ""},
      // An existing path is that path, whatever it looks like.
      {"v4l2:cam", true, input_kind::path, "", "v4l2:cam"},
      {"udp://x", true, input_kind::path, "", "udp://x"},
      {"a%05d.ppm", true, input_kind::path, "", "a%05d.ppm"},
      // file: is FFmpeg's spelling of a local file.
      {"file:take.mp4", false, input_kind::path, "", "take.mp4"},
      {"file:/abs/v4l2:x", false, input_kind::path, "", "/abs/v4l2:x"},
      {"file:frames/%05d.png", false, input_kind::pattern, "", "frames/%05d.png"},
      // Patterns.
      {"frames/%05d.png", false, input_kind::pattern, "", "frames/%05d.png"},
      {"img%d.jpg", false, input_kind::pattern, "", "img%d.jpg"},
      {"bad%s.png", false, input_kind::pattern, "", "bad%s.png"},  // open() says what is wrong
      // Devices: FORMAT:DEVICE.
      {"v4l2:/dev/video0", false, input_kind::device, "v4l2", "/dev/video0"},
      {"video4linux2:/dev/video1", false, input_kind::device, "video4linux2", "/dev/video1"},
      {"x11grab::0.0", false, input_kind::device, "x11grab", ":0.0"},
      {"lavfi:testsrc=size=64x48:rate=25", false, input_kind::device, "lavfi",
       "testsrc=size=64x48:rate=25"},
      {"lavfi:", false, input_kind::device, "lavfi", ""},
      {"dshow:video=Integrated Camera", false, input_kind::device, "dshow",
       "video=Integrated Camera"},
      {"v4l2:frames/%d.png", false, input_kind::device, "v4l2", "frames/%d.png"},
      // Not devices: a drive letter, a name with other characters, no colon.
      {"C:/videos/take.mp4", false, input_kind::path, "", "C:/videos/take.mp4"},
      {"my-cam:0", false, input_kind::path, "", "my-cam:0"},
      {"./v4l2:x", false, input_kind::path, "", "./v4l2:x"},
      // URLs: SCHEME://, the scheme in lower case.
      {"udp://127.0.0.1:5000", false, input_kind::url, "udp", "udp://127.0.0.1:5000"},
      {"UDP://127.0.0.1:5000", false, input_kind::url, "udp", "udp://127.0.0.1:5000"},
      {"rtsp://cam.local:554/stream1", false, input_kind::url, "rtsp",
       "rtsp://cam.local:554/stream1"},
      {"srt://127.0.0.1:9000?mode=listener", false, input_kind::url, "srt",
       "srt://127.0.0.1:9000?mode=listener"},
      {"https://example.org/a.m3u8", false, input_kind::url, "https", "https://example.org/a.m3u8"},
      {"rtp://239.0.0.1:1234", false, input_kind::url, "rtp", "rtp://239.0.0.1:1234"},
      {"foo+bar.baz-1://x", false, input_kind::url, "foo+bar.baz-1", "foo+bar.baz-1://x"},
      {"foo://", false, input_kind::url, "foo", "foo://"},
      {"http://x/%05d.png", false, input_kind::url, "http", "http://x/%05d.png"},
      // Not URLs: a scheme must start with a letter; "://" must follow it at once.
      {"1udp://x", false, input_kind::device, "1udp", "//x"},
      {"://x", false, input_kind::path, "", "://x"},
      {"u_dp://x", false, input_kind::device, "u_dp", "//x"},
  };
  for (const expected& e : cases) {
    const input_spec s = classify_input(e.text, e.exists);
    EXPECT_EQ(s.kind, e.kind) << e.text << ": got " << kind_name(s.kind);
    EXPECT_EQ(s.name, e.name) << e.text;
    EXPECT_EQ(s.target, e.target) << e.text;
  }
}

}  // namespace
TEST(InputSpec, ShownInputHidesCredentials) {
  const std::pair<const char*, const char*> cases[] = {
      {"rtsp://cam:secret@10.0.0.5:554/live", "rtsp://cam:***@10.0.0.5:554/live"},
      {"http://token@example.org/a.m3u8", "http://***@example.org/a.m3u8"},
      {"srt://u:p:q@host:9000?mode=caller", "srt://u:***@host:9000?mode=caller"},
      {"https://example.org/a@b/c.m3u8", "https://example.org/a@b/c.m3u8"},  // '@' in the path
      {"udp://127.0.0.1:5000", "udp://127.0.0.1:5000"},
      {"take@home.mp4", "take@home.mp4"},
      {"v4l2:/dev/video0", "v4l2:/dev/video0"},
  };
  for (const auto& [in, out] : cases) EXPECT_EQ(shown_input(in), out) << in;
}

}  // namespace avatarmap
