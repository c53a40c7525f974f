#include "io/text_output.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace avatarmap::io_detail {

namespace {
constexpr std::size_t k_buffer_size = std::size_t{1} << 20;
}

text_output::~text_output() { discard(); }

void text_output::discard() {
  if (fd_ >= 0 && !is_stdout_) {
    ::close(fd_);
    if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
  }
  fd_ = -1;
  temp_path_.clear();
}

status text_output::open(const std::string& path) {
  discard();
  path_ = path;
  failed_ = false;
  error_.clear();
  pos_ = 0;
  buf_.assign(k_buffer_size, '\0');
  if (path == "-") {
    fd_ = STDOUT_FILENO;
    is_stdout_ = true;
    return {};
  }
  is_stdout_ = false;
  std::string tmpl = path + ".tmp.XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  int fd = ::mkstemp(name.data());
  if (fd < 0)
    return status::error(path +
                         ": cannot create a temporary file beside it: " + std::strerror(errno));
  // mkstemp creates the file 0600; give the result the mode of the file it replaces, or
  // the usual 0644 for a new file.
  struct stat st;
  mode_t mode = ::stat(path.c_str(), &st) == 0 ? (st.st_mode & 07777) : 0644;
  ::fchmod(fd, mode);
  fd_ = fd;
  temp_path_.assign(name.data());
  return {};
}

bool text_output::flush() {
  if (failed_) return false;
  if (fd_ < 0) {
    failed_ = true;
    error_ = path_ + ": write after close";
    return false;
  }
  std::size_t done = 0;
  while (done < pos_) {
    ssize_t n = ::write(fd_, buf_.data() + done, pos_ - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      failed_ = true;
      error_ = path_ + ": write failed: " + std::strerror(errno);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  pos_ = 0;
  return true;
}

bool text_output::write(std::string_view s) {
  while (!s.empty()) {
    if (pos_ == buf_.size() && !flush()) return false;
    std::size_t n = std::min(s.size(), buf_.size() - pos_);
    put(s.substr(0, n));
    s.remove_prefix(n);
  }
  return true;
}

status text_output::commit() {
  if (fd_ < 0) return status::error(path_ + ": commit without an open file");
  if (!flush()) {
    std::string e = error_;
    discard();
    return status::error(e);
  }
  if (is_stdout_) {
    fd_ = -1;
    return {};
  }
  if (::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS) {
    std::string e = path_ + ": fsync failed: " + std::strerror(errno);
    discard();
    return status::error(e);
  }
  if (::close(fd_) != 0) {
    std::string e = path_ + ": close failed: " + std::strerror(errno);
    fd_ = -1;
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
    return status::error(e);
  }
  fd_ = -1;
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    std::string e = path_ + ": cannot rename " + temp_path_ + " over it: " + std::strerror(errno);
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
    return status::error(e);
  }
  temp_path_.clear();
  return {};
}

}  // namespace avatarmap::io_detail
