#include "common/text_output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace avatarmap::io_detail {

namespace {
constexpr std::size_t k_buffer_size = std::size_t{1} << 20;

// Asks the kernel to start writing `n` bytes at `offset` of `fd` to the disk now, without
// waiting (Linux; elsewhere nothing): commit()'s fsync then waits for the last buffer rather
// than for the whole file (~30 ms for a 67 MB pose file), and the disk works while the
// command computes. Advisory: a failure (a pipe, a file system without it) is ignored; write
// errors still surface at write() or fsync.
void start_writeback(int fd, unsigned long long offset, std::size_t n) {
#if defined(__linux__)
  (void)::sync_file_range(fd, static_cast<off_t>(offset), static_cast<off_t>(n),
                          SYNC_FILE_RANGE_WRITE);
#else
  (void)fd;
  (void)offset;
  (void)n;
#endif
}
}  // namespace

text_output::~text_output() { discard(); }

void text_output::discard() {
  file_.discard();
  open_ = false;
  is_stdout_ = false;
}

status text_output::open(const std::string& path) {
  discard();
  path_ = path;
  failed_ = false;
  error_.clear();
  pos_ = 0;
  written_ = 0;
  if (path == "-") {
    is_stdout_ = true;
  } else if (status s = file_.open(path); !s) {
    return s;
  }
  buf_.assign(k_buffer_size + k_slack, '\0');
  open_ = true;
  return {};
}

bool text_output::flush() {
  if (failed_) return false;
  if (!open_) {
    failed_ = true;
    error_ = path_ + ": write after close";
    return false;
  }
  if (is_stdout_) {
    if (const int e = write_all(STDOUT_FILENO, buf_.data(), pos_); e != 0) {
      failed_ = true;
      error_ = "standard output: write failed: " + std::string(std::strerror(e));
      return false;
    }
  } else if (status s = file_.write(buf_.data(), pos_); !s) {
    failed_ = true;  // file_ has removed its temporary file already
    error_ = s.message();
    return false;
  } else {
    start_writeback(file_.fd(), written_, pos_);
    written_ += pos_;
  }
  pos_ = 0;
  return true;
}

bool text_output::write(std::string_view s) {
  while (!s.empty()) {
    if (pos_ == capacity() && !flush()) return false;
    const std::size_t n = std::min(s.size(), capacity() - pos_);
    put(s.substr(0, n));
    s.remove_prefix(n);
  }
  return true;
}

status text_output::commit() {
  if (!open_) return status::io_error(path_ + ": commit without an open file");
  if (!flush()) {
    const std::string e = error_;
    discard();
    return status::io_error(e);
  }
  open_ = false;
  if (is_stdout_) {
    is_stdout_ = false;
    return {};
  }
  return file_.commit();
}

}  // namespace avatarmap::io_detail
