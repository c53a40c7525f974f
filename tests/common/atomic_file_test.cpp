// The one atomic writer behind every output: temporary names, modes, symlinks, failures,
// special files and removal of temporary files on SIGINT/SIGTERM.
#include "common/atomic_file.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/text_output.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap::io_detail {
namespace {

namespace fs = std::filesystem;
using test::read_text;
using test::temp_dir;
using test::write_text;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

mode_t mode_of(const std::string& path) {
  struct stat st;
  EXPECT_EQ(::lstat(path.c_str(), &st), 0) << path;
  return st.st_mode & 07777;
}

std::vector<std::string> sorted_entries(const temp_dir& dir) {
  std::vector<std::string> e = dir.entries();
  std::sort(e.begin(), e.end());
  return e;
}

// Sets the process umask for one test and restores it.
class scoped_umask {
 public:
  explicit scoped_umask(mode_t mask) : old_(::umask(mask)) {}
  ~scoped_umask() { ::umask(old_); }

 private:
  mode_t old_;
};

TEST(atomic_file, new_file_gets_0644_less_the_umask) {
  temp_dir dir("af_mode_new");
  {
    scoped_umask m(022);
    ASSERT_TRUE(write_file_atomically(dir.file("a.txt"), "hello").ok());
    EXPECT_EQ(mode_of(dir.file("a.txt")), 0644u);
  }
  {
    scoped_umask m(077);
    ASSERT_TRUE(write_file_atomically(dir.file("b.txt"), "hello").ok());
    EXPECT_EQ(mode_of(dir.file("b.txt")), 0600u);
  }
  {
    scoped_umask m(0);
    ASSERT_TRUE(write_file_atomically(dir.file("c.txt"), "hello").ok());
    EXPECT_EQ(mode_of(dir.file("c.txt")), 0644u);
  }
  EXPECT_EQ(read_text(dir.file("a.txt")), "hello");
  EXPECT_EQ(sorted_entries(dir), (std::vector<std::string>{"a.txt", "b.txt", "c.txt"}));
}

TEST(atomic_file, replaced_file_keeps_its_mode) {
  temp_dir dir("af_mode_keep");
  scoped_umask m(022);
  for (const mode_t mode : {0600u, 0755u, 0640u, 0444u}) {
    const std::string p = dir.file("out_" + std::to_string(mode));
    write_text(p, "old");
    ASSERT_EQ(::chmod(p.c_str(), mode), 0);
    const status s = write_file_atomically(p, "new content");
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(read_text(p), "new content");
    EXPECT_EQ(mode_of(p), mode) << std::oct << mode;
  }
}

TEST(atomic_file, replaced_file_keeps_its_owner_when_root) {
  if (::geteuid() != 0) GTEST_SKIP() << "only root can give a file to another owner";
  temp_dir dir("af_owner");
  const std::string p = dir.file("owned.txt");
  write_text(p, "old");
  ASSERT_EQ(::chown(p.c_str(), 4321, 4322), 0);
  ASSERT_TRUE(write_file_atomically(p, "new").ok());
  struct stat st;
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_uid, 4321u);
  EXPECT_EQ(st.st_gid, 4322u);
}

TEST(atomic_file, temporary_file_is_hidden_beside_the_target_and_private) {
  temp_dir dir("af_name");
  atomic_file f;
  ASSERT_TRUE(f.open(dir.file("x.vrma")).ok());
  const std::string t = f.temp_path();
  EXPECT_EQ(fs::path(t).parent_path(), dir.path());
  const std::string name = fs::path(t).filename().string();
  ASSERT_EQ(name.size(), std::string(".x.vrma.tmp.").size() + 6) << name;
  EXPECT_EQ(name.rfind(".x.vrma.tmp.", 0), 0u) << name;
  EXPECT_EQ(mode_of(t), 0600u);  // nobody else can open the data while it is written
  EXPECT_FALSE(fs::exists(dir.file("x.vrma")));
  ASSERT_TRUE(f.write("abc").ok());
  ASSERT_TRUE(f.commit().ok());
  EXPECT_FALSE(fs::exists(t));
  EXPECT_EQ(read_text(dir.file("x.vrma")), "abc");
}

TEST(atomic_file, users_files_with_temporary_looking_names_are_untouched) {
  temp_dir dir("af_user_tmp");
  const std::vector<std::string> theirs = {"out.glb.tmp", ".out.glb.tmp.XXXXXX",
                                           ".out.glb.tmp.abc123", "out.glb.tmp.abc123"};
  for (const std::string& n : theirs) write_text(dir.file(n), "user data " + n);
  write_text(dir.file("out.glb"), "previous");
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(write_file_atomically(dir.file("out.glb"), "GLB").ok());
  // A failed write cleans up only its own temporary file, too.
  {
    atomic_file f;
    ASSERT_TRUE(f.open(dir.file("out.glb")).ok());
    f.discard();
  }
  for (const std::string& n : theirs) EXPECT_EQ(read_text(dir.file(n)), "user data " + n) << n;
  std::vector<std::string> expected = theirs;
  expected.push_back("out.glb");
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(sorted_entries(dir), expected);
  EXPECT_EQ(read_text(dir.file("out.glb")), "GLB");
}

TEST(atomic_file, symlinks_at_guessable_temporary_names_are_not_followed) {
  temp_dir dir("af_symlink_tmp");
  temp_dir elsewhere("af_symlink_victim");
  const std::string victim = elsewhere.file("victim.txt");
  write_text(victim, "precious");
  // The old fixed name and the template's literal name, as an attacker would guess them.
  for (const std::string& n : {"out.glb.tmp", ".out.glb.tmp.XXXXXX"})
    ASSERT_EQ(::symlink(victim.c_str(), dir.file(n).c_str()), 0);
  ASSERT_TRUE(write_file_atomically(dir.file("out.glb"), "GLB DATA").ok());
  EXPECT_EQ(read_text(victim), "precious");
  EXPECT_EQ(read_text(dir.file("out.glb")), "GLB DATA");
  EXPECT_TRUE(fs::is_symlink(dir.file("out.glb.tmp")));
  EXPECT_TRUE(fs::is_symlink(dir.file(".out.glb.tmp.XXXXXX")));
}

TEST(atomic_file, temporary_file_swapped_for_a_symlink_is_not_committed) {
  // commit_temp_file (PNG sequences) reopens the temporary file by name: O_NOFOLLOW.
  temp_dir dir("af_swap");
  temp_dir elsewhere("af_swap_victim");
  const std::string victim = elsewhere.file("victim.txt");
  write_text(victim, "precious");
  ASSERT_EQ(::chmod(victim.c_str(), 0600), 0);
  int fd = -1;
  std::string temp;
  ASSERT_TRUE(create_temp_file(dir.file("frame.png"), fd, temp).ok());
  ::close(fd);
  ASSERT_EQ(::unlink(temp.c_str()), 0);
  ASSERT_EQ(::symlink(victim.c_str(), temp.c_str()), 0);
  const status s = commit_temp_file(temp, dir.file("frame.png"));
  EXPECT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "frame.png")) << s.message();
  EXPECT_EQ(read_text(victim), "precious");
  EXPECT_EQ(mode_of(victim), 0600u);
  EXPECT_FALSE(fs::exists(dir.file("frame.png")));
}

TEST(atomic_file, symlink_at_the_target_is_replaced_and_its_file_never_written) {
  temp_dir dir("af_symlink_target");
  const std::string pointed = dir.file("real.txt");
  write_text(pointed, "the linked file");
  ASSERT_EQ(::chmod(pointed.c_str(), 0600), 0);
  const std::string link = dir.file("out.txt");
  ASSERT_EQ(::symlink(pointed.c_str(), link.c_str()), 0);
  scoped_umask m(022);
  ASSERT_TRUE(write_file_atomically(link, "new").ok());
  EXPECT_FALSE(fs::is_symlink(link));
  EXPECT_EQ(read_text(link), "new");
  EXPECT_EQ(mode_of(link), 0644u);  // a new file, not the link target's mode
  EXPECT_EQ(read_text(pointed), "the linked file");
}

// Limits the size of files this process may write (EFBIG, as on a full disk) for one scope.
class scoped_file_size_limit {
 public:
  explicit scoped_file_size_limit(rlim_t bytes) {
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    ::getrlimit(RLIMIT_FSIZE, &old_);
    struct rlimit r = old_;
    r.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &r) == 0;
  }
  ~scoped_file_size_limit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  bool ok() const { return ok_; }

 private:
  struct rlimit old_;
  void (*old_handler_)(int);
  bool ok_ = false;
};

TEST(atomic_file, failed_write_keeps_the_previous_file_and_leaves_no_temporary_file) {
  temp_dir dir("af_efbig");
  const std::string p = dir.file("out.glb");
  write_text(p, "previous content");
  const std::string big(64 * 1024, 'x');
  status w, c;
  {
    scoped_file_size_limit limit(4096);
    ASSERT_TRUE(limit.ok());
    atomic_file f;
    ASSERT_TRUE(f.open(p).ok());
    w = f.write(big);
    c = f.commit();
  }
  ASSERT_FALSE(w.ok());
  EXPECT_TRUE(contains(w.message(), p)) << w.message();
  EXPECT_TRUE(contains(w.message(), std::strerror(EFBIG))) << w.message();
  EXPECT_TRUE(contains(w.message(), "the previous file is unchanged")) << w.message();
  EXPECT_FALSE(c.ok());  // commit after a failed write repeats the error
  EXPECT_EQ(c.message(), w.message());
  EXPECT_EQ(read_text(p), "previous content");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.glb"});

  // write_file_atomically on a new name: nothing is made.
  status n;
  {
    scoped_file_size_limit limit(4096);
    n = write_file_atomically(dir.file("new.glb"), big);
  }
  EXPECT_FALSE(n.ok());
  EXPECT_TRUE(contains(n.message(), "no file was written")) << n.message();
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.glb"});
}

TEST(atomic_file, text_output_failed_write_keeps_the_previous_file) {
  temp_dir dir("af_text_efbig");
  const std::string p = dir.file("out.pose.jsonl");
  write_text(p, "previous\n");
  ASSERT_EQ(::chmod(p.c_str(), 0640), 0);
  status s;
  {
    scoped_file_size_limit limit(100000);
    ASSERT_TRUE(limit.ok());
    text_output out;
    ASSERT_TRUE(out.open(p).ok());
    const std::string line(1000, 'y');
    bool all_written = true;  // the 1 MB buffer flushes (and fails) part-way through
    for (int i = 0; i < 3000; ++i) all_written = out.write(line) && all_written;
    EXPECT_FALSE(all_written);
    EXPECT_TRUE(contains(out.error(), std::strerror(EFBIG))) << out.error();
    s = out.commit();
  }
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), std::strerror(EFBIG))) << s.message();
  EXPECT_EQ(read_text(p), "previous\n");
  EXPECT_EQ(mode_of(p), 0640u);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.pose.jsonl"});

  // And a good run replaces it, keeping the mode.
  text_output out;
  ASSERT_TRUE(out.open(p).ok());
  ASSERT_TRUE(out.write("new\n"));
  ASSERT_TRUE(out.commit().ok());
  EXPECT_EQ(read_text(p), "new\n");
  EXPECT_EQ(mode_of(p), 0640u);
}

TEST(atomic_file, missing_folder_file_as_folder_and_folder_as_target_say_why) {
  temp_dir dir("af_errors");
  atomic_file f;
  const std::string missing = dir.file("no/such/folder/out.bvh");
  status s = f.open(missing);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), missing)) << s.message();
  EXPECT_TRUE(contains(s.message(), "folder '" + dir.file("no/such/folder") + "' does not exist"))
      << s.message();

  write_text(dir.file("plain.txt"), "x");
  s = f.open(dir.file("plain.txt/out.bvh"));
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "is not a folder")) << s.message();
  EXPECT_TRUE(contains(s.message(), std::strerror(ENOTDIR))) << s.message();

  fs::create_directory(dir.file("sub"));
  s = f.open(dir.file("sub"));
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "it is a folder")) << s.message();
  s = f.open(dir.file("sub/"));
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "it is a folder")) << s.message();
  s = f.open("");
  EXPECT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "empty")) << s.message();

  EXPECT_FALSE(f.is_open());
  EXPECT_FALSE(f.write("x").ok());
  EXPECT_FALSE(f.commit().ok());
  EXPECT_EQ(sorted_entries(dir), (std::vector<std::string>{"plain.txt", "sub"}));
}

TEST(atomic_file, read_only_folder_says_not_writable) {
  std::string folder;
  std::unique_ptr<temp_dir> own;
  if (::geteuid() != 0) {
    own = std::make_unique<temp_dir>("af_readonly");
    folder = own->path().string();
    ASSERT_EQ(::chmod(folder.c_str(), 0555), 0);
  } else {
    // Permissions do not stop root; sysfs refuses new files to everyone (EACCES), and a
    // read-only mount would give EROFS.
    struct stat st;
    if (::stat("/sys", &st) != 0 || !S_ISDIR(st.st_mode))
      GTEST_SKIP() << "running as root and no read-only folder (/sys) to try";
    folder = "/sys";
  }
  atomic_file f;
  const status s = f.open(folder + "/out.vrma");
  if (own) ::chmod(folder.c_str(), 0755);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "folder '" + folder + "' is not writable (")) << s.message();
  EXPECT_TRUE(contains(s.message(), std::strerror(EACCES)) ||
              contains(s.message(), std::strerror(EROFS)) ||
              contains(s.message(), std::strerror(EPERM)))
      << s.message();
}

TEST(atomic_file, discard_and_destructor_remove_the_temporary_file) {
  temp_dir dir("af_discard");
  write_text(dir.file("keep.txt"), "old");
  {
    atomic_file f;
    ASSERT_TRUE(f.open(dir.file("keep.txt")).ok());
    ASSERT_TRUE(f.write("half").ok());
    EXPECT_EQ(dir.entries().size(), 2u);
    f.discard();
    EXPECT_FALSE(f.is_open());
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
    f.discard();  // idempotent
  }
  {
    atomic_file f;
    ASSERT_TRUE(f.open(dir.file("keep.txt")).ok());
    ASSERT_TRUE(f.write("half").ok());
  }  // abandoned
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
  EXPECT_EQ(read_text(dir.file("keep.txt")), "old");
  {
    text_output out;
    ASSERT_TRUE(out.open(dir.file("keep.txt")).ok());
    ASSERT_TRUE(out.write("half"));
  }
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
  EXPECT_EQ(read_text(dir.file("keep.txt")), "old");
}

TEST(atomic_file, long_names_get_a_shortened_temporary_name) {
  temp_dir dir("af_long");
  const std::string name = std::string(250, 'n') + ".bvh";  // 254 bytes: NAME_MAX is 255
  ASSERT_TRUE(write_file_atomically(dir.file(name), "HIERARCHY").ok());
  EXPECT_EQ(read_text(dir.file(name)), "HIERARCHY");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{name});
}

TEST(atomic_file, special_files_are_written_in_place_not_replaced) {
  // A FIFO stands for /dev/null and /dev/stdout: renaming over it would replace the node.
  temp_dir dir("af_fifo");
  const std::string fifo = dir.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  const status s = write_file_atomically(fifo, "through the pipe");
  ASSERT_TRUE(s.ok()) << s.message();
  char buf[64] = {};
  const ssize_t n = ::read(reader, buf, sizeof buf);
  ::close(reader);
  EXPECT_EQ(std::string(buf, n > 0 ? static_cast<std::size_t>(n) : 0), "through the pipe");
  struct stat st;
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"pipe"});
}

// Runs `body` in a child process and returns its wait status.
template <class F>
int in_child(F body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    body();
    ::_exit(0);  // not reached when the body kills itself
  }
  int ws = 0;
  ::waitpid(pid, &ws, 0);
  return ws;
}

TEST(atomic_file, sigterm_removes_temporary_files_and_the_process_dies_by_it) {
  temp_dir dir("af_sigterm");
  write_text(dir.file("old.vrma"), "old");
  const int ws = in_child([&] {
    install_temp_cleanup_handlers();
    install_temp_cleanup_handlers();  // idempotent
    // One committed output stays; two open ones (a new file and a replacement) vanish.
    if (!write_file_atomically(dir.file("done.bvh"), "done").ok()) ::_exit(3);
    atomic_file a, b;
    if (!a.open(dir.file("new.glb")).ok() || !a.write("partial").ok()) ::_exit(4);
    if (!b.open(dir.file("old.vrma")).ok() || !b.write("partial").ok()) ::_exit(5);
    ::kill(::getpid(), SIGTERM);
    ::_exit(6);  // the handler re-raises with the default action: never here
  });
  ASSERT_TRUE(WIFSIGNALED(ws)) << "exit status " << (WIFEXITED(ws) ? WEXITSTATUS(ws) : -1);
  EXPECT_EQ(WTERMSIG(ws), SIGTERM);
  EXPECT_EQ(sorted_entries(dir), (std::vector<std::string>{"done.bvh", "old.vrma"}));
  EXPECT_EQ(read_text(dir.file("old.vrma")), "old");
  EXPECT_EQ(read_text(dir.file("done.bvh")), "done");
}

TEST(atomic_file, sigint_removes_registered_files_and_numbered_sequences) {
  temp_dir dir("af_sigint");
  const int ws = in_child([&] {
    install_temp_cleanup_handlers();
    // A file made elsewhere (animate's landmarks) and a PNG sequence's temporary files.
    write_text(dir.file("landmarks.tmp"), "x");
    temp_file_registration one(dir.file("landmarks.tmp"));
    int fd = -1;
    std::string base;
    if (!create_temp_file(dir.file("f_00001.png"), fd, base).ok()) ::_exit(3);
    ::close(fd);
    temp_file_registration seq(base);
    for (int i = 1; i < 12; ++i) {
      seq.set_sequence_count(i + 1);
      write_text(base + "." + std::to_string(i), "png");
    }
    ::kill(::getpid(), SIGINT);
    ::_exit(6);
  });
  ASSERT_TRUE(WIFSIGNALED(ws)) << "exit status " << (WIFEXITED(ws) ? WEXITSTATUS(ws) : -1);
  EXPECT_EQ(WTERMSIG(ws), SIGINT);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{});
}

TEST(atomic_file, ignored_signals_stay_ignored) {
  temp_dir dir("af_sigign");
  const int ws = in_child([&] {
    std::signal(SIGHUP, SIG_IGN);  // as nohup does
    install_temp_cleanup_handlers();
    atomic_file a;
    if (!a.open(dir.file("out.bvh")).ok()) ::_exit(3);
    ::kill(::getpid(), SIGHUP);  // ignored: carries on
    if (!a.write("after").ok() || !a.commit().ok()) ::_exit(4);
    ::_exit(0);
  });
  ASSERT_TRUE(WIFEXITED(ws));
  EXPECT_EQ(WEXITSTATUS(ws), 0);
  EXPECT_EQ(read_text(dir.file("out.bvh")), "after");
}

TEST(atomic_file, registry_slots_are_freed_by_commit_and_discard) {
  temp_dir dir("af_sig_slots");
  const int ws = in_child([&] {
    install_temp_cleanup_handlers();
    // Many more files than the registry's 64 slots, committed or abandoned one after another.
    for (int i = 0; i < 200; ++i) {
      if (!write_file_atomically(dir.file("o" + std::to_string(i % 3)), "v").ok()) ::_exit(3);
      atomic_file abandoned;
      if (!abandoned.open(dir.file("x")).ok()) ::_exit(4);
    }
    // Still registered, so still removed by the signal.
    atomic_file last;
    if (!last.open(dir.file("last.glb")).ok()) ::_exit(5);
    ::kill(::getpid(), SIGTERM);
    ::_exit(6);
  });
  ASSERT_TRUE(WIFSIGNALED(ws)) << "exit status " << (WIFEXITED(ws) ? WEXITSTATUS(ws) : -1);
  EXPECT_EQ(sorted_entries(dir), (std::vector<std::string>{"o0", "o1", "o2"}));
}

}  // namespace
}  // namespace avatarmap::io_detail
