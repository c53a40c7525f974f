#include "common/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <vector>

namespace avatarmap::io_detail {

// ---- registry of live temporary files (read by the signal handler) -------------------------
//
// The handler may run at any instruction of any thread, so it reads only lock-free atomics and
// fixed char buffers, and calls only unlink(), signal() and raise() (all async-signal-safe).
// A slot goes free -> claimed (being filled) -> live (visible to the handler) -> free.
namespace {

constexpr int k_slot_free = 0;
constexpr int k_slot_claimed = 1;
constexpr int k_slot_live = 2;
constexpr int k_slot_count = 64;           // temporary files open at once; more are not cleaned
constexpr std::size_t k_slot_path = 4096;  // PATH_MAX on Linux; longer names are not cleaned

struct temp_slot {
  std::atomic<int> state{k_slot_free};
  std::atomic<long long> count{1};  // also PATH.1 .. PATH.(count-1) (set_sequence_count)
  char path[k_slot_path];
};
temp_slot g_slots[k_slot_count];
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<long long>::is_always_lock_free,
              "the signal handler needs lock-free atomics");

int register_path(const std::string& path) {
  if (path.size() >= k_slot_path) return -1;
  for (int i = 0; i < k_slot_count; ++i) {
    int expected = k_slot_free;
    if (!g_slots[i].state.compare_exchange_strong(expected, k_slot_claimed)) continue;
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    g_slots[i].count.store(1);
    g_slots[i].state.store(k_slot_live);
    return i;
  }
  return -1;
}

void unregister_path(int slot) {
  if (slot >= 0 && slot < k_slot_count) g_slots[slot].state.store(k_slot_free);
}

// Removes PATH.1 .. PATH.(count-1); only async-signal-safe operations.
void unlink_numbered(const char* path, long long count) {
  char name[k_slot_path + 24];
  std::size_t len = 0;
  while (path[len] != '\0' && len < k_slot_path) {
    name[len] = path[len];
    ++len;
  }
  name[len] = '.';
  for (long long i = 1; i < count; ++i) {
    char digits[24];
    int n = 0;
    for (long long v = i; v > 0; v /= 10) digits[n++] = static_cast<char>('0' + v % 10);
    std::size_t at = len + 1;
    while (n > 0) name[at++] = digits[--n];
    name[at] = '\0';
    ::unlink(name);
  }
}

extern "C" void remove_temp_files_and_reraise(int sig) {
  const int saved_errno = errno;
  for (auto& slot : g_slots) {
    if (slot.state.load() != k_slot_live) continue;
    ::unlink(slot.path);
    unlink_numbered(slot.path, slot.count.load());
  }
  // Default action (terminate) on the re-raised signal, so the parent sees "killed by SIGx".
  // The signal is blocked while the handler runs; it is delivered when the handler returns.
  std::signal(sig, SIG_DFL);
  std::raise(sig);
  errno = saved_errno;
}

// Parent folder of `path` as given ("." when it has none) and the last component.
void split_path(const std::string& path, std::string& out_dir, std::string& out_base) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) {
    out_dir = ".";
    out_base = path;
  } else {
    out_dir = slash == 0 ? "/" : path.substr(0, slash);
    out_base = path.substr(slash + 1);
  }
}

// The process umask without changing it where the system tells it (Linux >= 4.7); otherwise
// by setting and restoring it, which another thread calling umask() could race with.
mode_t current_umask() {
  if (std::FILE* f = std::fopen("/proc/self/status", "re")) {
    char line[256];
    unsigned value = 0;
    bool found = false;
    while (std::fgets(line, sizeof line, f))
      if (std::sscanf(line, "Umask: %o", &value) == 1) {
        found = true;
        break;
      }
    std::fclose(f);
    if (found) return static_cast<mode_t>(value);
  }
  static std::mutex m;
  std::lock_guard<std::mutex> lock(m);
  const mode_t mask = ::umask(022);
  ::umask(mask);
  return mask;
}

std::string errno_text(int e) { return std::strerror(e); }

// The last words of a failed write's message.
const char* outcome(bool existed) {
  return existed ? "; the previous file is unchanged" : "; no file was written";
}

// Gives the open temporary file `fd` the mode (and, where allowed, the owner) of the regular
// file at `path`, or 0644 & ~umask when there is none. A symlink at `path` is replaced by the
// rename (the file it points to is never written), so it counts as no file.
bool adopt_target_mode(int fd, const std::string& path) {
  struct stat st;
  mode_t mode;
  if (::lstat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
    // fchown before fchmod: a change of owner clears set-user-ID bits. Only root may give a
    // file away; everyone else keeps their own, as with any new file.
    if (st.st_uid != ::geteuid() || st.st_gid != ::getegid())
      (void)!::fchown(fd, st.st_uid, st.st_gid);
    mode = st.st_mode & 07777;
  } else {
    mode = 0644 & ~current_umask();
  }
  return ::fchmod(fd, mode) == 0;
}

// Makes the rename durable. Best effort: the new file is in place whatever happens here, so
// a failure is not reported as a failed write.
void sync_folder_of(const std::string& path) {
  std::string dir, base;
  split_path(path, dir, base);
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

// fsync; EINVAL means the file system cannot sync (some FUSE and special setups): nothing to
// wait for.
bool sync_file(int fd) { return ::fsync(fd) == 0 || errno == EINVAL; }

}  // namespace

status create_temp_file(const std::string& path, int& out_fd, std::string& out_temp_path) {
  out_fd = -1;
  out_temp_path.clear();
  if (path.empty()) return status::invalid_argument("cannot write: the output path is empty");
  std::string dir, base;
  split_path(path, dir, base);
  struct stat st;
  if (base.empty() || base == "." || base == ".." ||
      (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)))
    return status::io_error(path + ": cannot write: it is a folder (" + errno_text(EISDIR) +
                            "); give a file name");
  if (::stat(dir.c_str(), &st) != 0) {
    const int e = errno;
    if (e == ENOENT)
      return status::io_error(path + ": cannot write: folder '" + dir +
                              "' does not exist; create it first");
    return status::io_error(path + ": cannot write: folder '" + dir + "': " + errno_text(e));
  }
  if (!S_ISDIR(st.st_mode))
    return status::io_error(path + ": cannot write: '" + dir + "' is not a folder (" +
                            errno_text(ENOTDIR) + ")");

  // `.BASE.tmp.XXXXXX`: hidden, and never a name a user or another tool would pick. The base
  // is shortened (at a UTF-8 character boundary) so that the name stays within NAME_MAX
  // (255) with room for a sequence number (create_temp_file's callers may append ".N").
  constexpr std::size_t k_base_max = 200;
  if (base.size() > k_base_max) {
    std::size_t cut = k_base_max;
    while (cut > 0 && (static_cast<unsigned char>(base[cut]) & 0xC0) == 0x80) --cut;
    base.resize(cut);
  }
  const std::string tmpl = (dir == "/" ? "/" : dir + "/") + "." + base + ".tmp.XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  // mkostemp creates with O_CREAT|O_EXCL and mode 0600: an existing name (a user's file or a
  // symlink, even a dangling one) is never opened, so nothing is followed or overwritten, and
  // nobody else can open the data while it is written.
  const int fd = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    if (e == EACCES || e == EPERM || e == EROFS)
      return status::io_error(path + ": cannot write: folder '" + dir + "' is not writable (" +
                              errno_text(e) + ")");
    return status::io_error(path + ": cannot create a temporary file in folder '" + dir +
                            "': " + errno_text(e));
  }
  out_fd = fd;
  out_temp_path.assign(name.data());
  return {};
}

status commit_temp_file(const std::string& temp_path, const std::string& path) {
  struct stat st;
  const bool existed = ::lstat(path.c_str(), &st) == 0;
  const int fd = ::open(temp_path.c_str(), O_WRONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0)
    return status::io_error(path + ": cannot reopen " + temp_path + ": " + errno_text(errno) +
                            outcome(existed));
  if (!sync_file(fd) || !adopt_target_mode(fd, path)) {
    const int e = errno;
    ::close(fd);
    return status::io_error(path + ": cannot finish " + temp_path + ": " + errno_text(e) +
                            outcome(existed));
  }
  ::close(fd);
  if (std::rename(temp_path.c_str(), path.c_str()) != 0)
    return status::io_error(path + ": cannot replace it: " + errno_text(errno) + outcome(existed));
  sync_folder_of(path);
  return {};
}

// ---- atomic_file ------------------------------------------------------------------------

atomic_file::~atomic_file() { discard(); }

status atomic_file::open(const std::string& path) {
  discard();
  path_ = path;
  error_.clear();
  existed_ = false;

  // An existing special file (/dev/null, /dev/stdout, a FIFO) is written in place: renaming
  // a regular file over it would replace the device node or pipe itself.
  struct stat st;
  if (!path.empty() && ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) &&
      !S_ISDIR(st.st_mode)) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) return status::io_error(path + ": cannot open for writing: " + errno_text(errno));
    fd_ = fd;
    return {};
  }

  if (status s = create_temp_file(path, fd_, temp_path_); !s) return s;
  slot_ = register_path(temp_path_);
  existed_ = ::lstat(path.c_str(), &st) == 0;
  return {};
}

status atomic_file::fail(const std::string& what, int err) {
  error_ = path_ + ": " + what + ": " + errno_text(err) + outcome(existed_);
  discard();
  return status::io_error(error_);
}

status atomic_file::write(const void* data, std::size_t n) {
  if (fd_ < 0)
    return status::io_error(error_.empty() ? path_ + ": write to a file that is not open" : error_);
  if (const int e = write_all(fd_, data, n); e != 0) return fail("write failed", e);
  return {};
}

int write_all(int fd, const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (w == 0) return ENOSPC;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return 0;
}

status atomic_file::commit() {
  if (fd_ < 0)
    return status::io_error(error_.empty() ? path_ + ": commit of a file that is not open"
                                           : error_);
  if (temp_path_.empty()) {  // a special file written in place
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0 && errno != EINTR)
      return status::io_error(path_ + ": close failed: " + errno_text(errno));
    return {};
  }
  struct stat st;
  existed_ = ::lstat(path_.c_str(), &st) == 0;
  if (!sync_file(fd_)) return fail("write failed (fsync)", errno);
  if (!adopt_target_mode(fd_, path_)) return fail("cannot set the file mode", errno);
  // Linux closes the descriptor even when close() reports an error (e.g. EIO on NFS).
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0 && errno != EINTR) return fail("write failed (close)", errno);
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) return fail("cannot replace it", errno);
  // The temporary name is now the target's: forget it before anything could remove it.
  unregister_path(slot_);
  slot_ = -1;
  temp_path_.clear();
  sync_folder_of(path_);
  return {};
}

void atomic_file::discard() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!temp_path_.empty()) {
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
  }
  unregister_path(slot_);
  slot_ = -1;
}

status write_file_atomically(const std::string& path, std::string_view bytes) {
  atomic_file f;
  if (status s = f.open(path); !s) return s;
  if (status s = f.write(bytes); !s) return s;
  return f.commit();
}

// ---- temp_file_registration ---------------------------------------------------------------

temp_file_registration::temp_file_registration(const std::string& path)
    : slot_(register_path(path)) {}

temp_file_registration::~temp_file_registration() { unregister_path(slot_); }

void temp_file_registration::set_sequence_count(long long count) {
  if (slot_ >= 0) g_slots[slot_].count.store(count < 1 ? 1 : count);
}

// ---- signal handlers ----------------------------------------------------------------------

void install_temp_cleanup_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old;
      // A signal the parent made us ignore (nohup, a background job's SIGINT) stays ignored.
      if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
      struct sigaction sa;
      std::memset(&sa, 0, sizeof sa);
      sa.sa_handler = remove_temp_files_and_reraise;
      sigemptyset(&sa.sa_mask);
      // Block the other cleanup signals while one is handled, so the list is walked once.
      sigaddset(&sa.sa_mask, SIGINT);
      sigaddset(&sa.sa_mask, SIGTERM);
      sigaddset(&sa.sa_mask, SIGHUP);
      sa.sa_flags = 0;
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

}  // namespace avatarmap::io_detail
