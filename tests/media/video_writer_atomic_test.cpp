// The video writer's outputs go through io/atomic_file: modes of replaced files kept,
// temporary files hidden and removed when the process is killed mid-write.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <string>
#include <vector>

#include "avatarmap/media/video_source.hpp"
#include "avatarmap/media/video_writer.hpp"
#include "common/atomic_file.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

#define SKIP_WITHOUT_ENCODER() \
  if (!video_writer_available()) GTEST_SKIP() << "built without FFmpeg: no video writer"

std::vector<std::uint8_t> grey_frame(int w, int h, int i) {
  return std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3,
                                   static_cast<std::uint8_t>(20 + 10 * i));
}

mode_t mode_of(const std::string& path) {
  struct stat st;
  EXPECT_EQ(::stat(path.c_str(), &st), 0) << path;
  return st.st_mode & 07777;
}

// Opens `path`, writes `frames` frames and kills itself with `sig` before close(); returns the
// child's wait status.
int killed_while_writing(const std::string& path, int frames, int sig) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    io_detail::install_temp_cleanup_handlers();
    video_writer wr;
    if (!wr.open(path, 32, 32, 30.0).ok()) ::_exit(3);
    for (int i = 0; i < frames; ++i) {
      const std::vector<std::uint8_t> px = grey_frame(32, 32, i);
      if (!wr.write({px.data(), 32, 32, 96, pixel_format::rgb8}, i / 30.0).ok()) ::_exit(4);
    }
    ::kill(::getpid(), sig);
    ::_exit(5);
  }
  int ws = 0;
  ::waitpid(pid, &ws, 0);
  return ws;
}

TEST(video_writer_atomic, killed_png_sequence_leaves_no_temporary_file) {
  SKIP_WITHOUT_ENCODER();
  test::temp_dir dir("vwa_png");
  test::write_text(dir.file("f_00002.png"), "an older frame");
  const int ws = killed_while_writing(dir.file("f_%05d.png"), 7, SIGTERM);
  ASSERT_TRUE(WIFSIGNALED(ws)) << "exit status " << (WIFEXITED(ws) ? WEXITSTATUS(ws) : -1);
  EXPECT_EQ(WTERMSIG(ws), SIGTERM);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"f_00002.png"});
  EXPECT_EQ(test::read_text(dir.file("f_00002.png")), "an older frame");
}

TEST(video_writer_atomic, killed_video_leaves_no_temporary_file) {
  SKIP_WITHOUT_ENCODER();
  test::temp_dir dir("vwa_mp4");
  test::write_text(dir.file("out.mp4"), "old");
  const int ws = killed_while_writing(dir.file("out.mp4"), 5, SIGINT);
  ASSERT_TRUE(WIFSIGNALED(ws)) << "exit status " << (WIFEXITED(ws) ? WEXITSTATUS(ws) : -1);
  EXPECT_EQ(WTERMSIG(ws), SIGINT);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.mp4"});
  EXPECT_EQ(test::read_text(dir.file("out.mp4")), "old");
}

TEST(video_writer_atomic, replaced_outputs_keep_their_mode_new_ones_are_not_private) {
  SKIP_WITHOUT_ENCODER();
  test::temp_dir dir("vwa_mode");
  const mode_t old_mask = ::umask(022);
  for (const std::string name : {"a.mp4", "b_%03d.png", "c.png"}) {
    const bool numbered = name.find('%') != std::string::npos;
    const std::string first = dir.file(numbered ? "b_000.png" : name);
    const std::string second = dir.file(numbered ? "b_001.png" : name + ".unused");
    test::write_text(first, "old");
    ASSERT_EQ(::chmod(first.c_str(), 0600), 0);
    video_writer wr;
    ASSERT_TRUE(wr.open(dir.file(name), 32, 32, 30.0).ok()) << name;
    for (int i = 0; i < 2; ++i) {
      const std::vector<std::uint8_t> px = grey_frame(32, 32, i);
      ASSERT_TRUE(wr.write({px.data(), 32, 32, 96, pixel_format::rgb8}, i / 30.0).ok());
    }
    ASSERT_TRUE(wr.close().ok()) << name;
    EXPECT_NE(test::read_text(first), "old") << name;
    EXPECT_EQ(mode_of(first), 0600u) << name;
    if (numbered) EXPECT_EQ(mode_of(second), 0644u) << name;  // new: 0644 less the umask
  }
  ::umask(old_mask);
  std::vector<std::string> e = dir.entries();
  std::sort(e.begin(), e.end());
  EXPECT_EQ(e, (std::vector<std::string>{"a.mp4", "b_000.png", "b_001.png", "c.png"}));
}

}  // namespace
}  // namespace avatarmap
