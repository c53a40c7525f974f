// Internal: the one atomic file writer behind every output of the library (the *.jsonl
// writers through text_output, .vrma, .bvh, .glb, video/PNG frames) and the registry that
// removes temporary files on SIGINT/SIGTERM/SIGHUP (also used for animate's temporary
// landmark file).
//
// Data goes to a temporary file created beside the target (same file system, so the final
// rename is atomic) with a unique hidden name `DIR/.NAME.tmp.XXXXXX`, created O_CREAT|O_EXCL
// (mkostemp, mode 0600 while written): an existing file of that name is never opened or
// removed, and a symlink placed there is never followed. commit() fsyncs the file, gives it
// the mode (and, when running as root, the owner) of the regular file it replaces, or
// 0644 & ~umask for a new file, renames it over the target and fsyncs the folder. A failed,
// abandoned or interrupted write removes the temporary file and leaves the target as it was.
//
// A symlink at the target path is replaced by the new file, like `mv` and most editors' safe
// save: the file the link points to is never written. An existing target that is not a
// regular file or folder (/dev/null, /dev/stdout, a FIFO) is written in place, not atomically,
// since renaming over it would replace the device node or pipe itself.
//
// Errors carry errno's text and say what to do, e.g.
//   "out/a.glb: cannot write: folder 'out' does not exist; create it first"
//   "out/a.glb: cannot write: folder 'out' is not writable (Permission denied)"
//   "out/a.glb: write failed: No space left on device; the previous file is unchanged"
// Their code is status_code::io (invalid_argument only for an empty path).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "avatarmap/core/status.hpp"

namespace avatarmap::io_detail {

class atomic_file {
 public:
  atomic_file() = default;
  ~atomic_file();  // discard() when not committed
  atomic_file(const atomic_file&) = delete;
  atomic_file& operator=(const atomic_file&) = delete;

  /// Creates the temporary file beside `path`. Fails (message names `path`, the folder and
  /// errno's text) when the folder is missing, not writable, or `path` is a folder.
  status open(const std::string& path);
  bool is_open() const { return fd_ >= 0; }
  /// The open temporary file's descriptor (for writers that hand it to another library), -1
  /// when closed.
  int fd() const { return fd_; }
  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_path_; }

  /// Writes all of `n` bytes (retrying short writes and EINTR); on failure (e.g. ENOSPC, or
  /// EFBIG over RLIMIT_FSIZE) returns an error naming the target and errno's text and discards
  /// the temporary file at once; later write() and commit() calls return the same error.
  status write(const void* data, std::size_t n);
  status write(std::string_view s) { return write(s.data(), s.size()); }

  /// fsync, chmod to the replaced file's mode, close, rename over the target, fsync the
  /// folder (best effort: the new file is in place whatever it returns). Closes the file
  /// whatever the outcome; on failure the temporary file is removed and the target is as it
  /// was.
  status commit();
  /// Closes and removes the temporary file; the target is untouched. Idempotent.
  void discard();

 private:
  status fail(const std::string& what, int err);

  int fd_ = -1;
  int slot_ = -1;         // registry slot of temp_path_ (-1: none)
  bool existed_ = false;  // the target existed at open() (for the error's last words)
  std::string path_;
  std::string temp_path_;  // empty when closed or when writing a special file in place
  std::string error_;      // first failure, repeated by later calls
};

/// Creates an empty temporary file beside `path` as atomic_file::open does (same name rule
/// `DIR/.NAME.tmp.XXXXXX`, same checks and messages; no special-file case) and hands over its
/// descriptor and name: the caller closes the descriptor and either calls commit_temp_file or
/// removes the file, and registers it (temp_file_registration) for removal on a signal. For
/// writers that keep several finished temporary files until one final commit (PNG
/// sequences: frame i's temporary file is `NAME.i`, made with O_CREAT|O_EXCL|O_NOFOLLOW).
status create_temp_file(const std::string& path, int& out_fd, std::string& out_temp_path);

/// Finishes a closed temporary file made by the caller: opens it (O_NOFOLLOW), fsyncs it,
/// gives it the mode of the regular file at `path` (0644 & ~umask when none), renames it over
/// `path` and fsyncs the folder. On failure `temp_path` is left for the caller to remove and
/// `path` is as it was.
status commit_temp_file(const std::string& temp_path, const std::string& path);

/// Writes all `n` bytes to `fd`, retrying short writes and EINTR: 0, or the errno of the
/// failure (ENOSPC when the system accepts nothing).
int write_all(int fd, const void* data, std::size_t n);

/// Writes `bytes` to `path` atomically (open + write + commit).
status write_file_atomically(const std::string& path, std::string_view bytes);

/// Registers a temporary file made elsewhere (e.g. animate's landmark file) for removal by
/// the signal handlers for as long as the object lives; it does not remove the file itself.
/// At most 64 temporary files (atomic_file's included) are registered at once and paths must
/// be shorter than 4096 bytes; beyond that a file is simply not removed on a signal.
/// A relative path is resolved against the working folder at the time of the signal.
class temp_file_registration {
 public:
  explicit temp_file_registration(const std::string& path);
  ~temp_file_registration();
  /// Also removes `PATH.1` .. `PATH.(count-1)` on a signal (a PNG sequence's temporary files,
  /// see create_temp_file). Raise it before creating the next file.
  void set_sequence_count(long long count);
  temp_file_registration(const temp_file_registration&) = delete;
  temp_file_registration& operator=(const temp_file_registration&) = delete;

 private:
  int slot_ = -1;
};

/// Installs SIGINT, SIGTERM and SIGHUP handlers (once; idempotent; thread-safe) that remove
/// every registered temporary file and then re-raise the signal with its default action, so
/// the process still dies "by the signal". A signal that was ignored when this is called
/// (nohup, background jobs) stays ignored. For programs (the CLI); a library user decides
/// about their own signal handling. Without it, temporary files are still removed on every
/// return path, but not when the process is killed.
void install_temp_cleanup_handlers();

}  // namespace avatarmap::io_detail
