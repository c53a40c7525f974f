#include "io/line_source.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace avatarmap::io_detail {

line_source_limits& default_line_source_limits() {
  static line_source_limits limits;
  return limits;
}

line_source::~line_source() {
  if (file_ && owns_file_) std::fclose(file_);
}

bool line_source::open_file(const std::string& path, std::string& out_error) {
  const line_source_limits& lim = default_line_source_limits();
  block_size_ = lim.block_size > 0 ? lim.block_size : 1;
  max_line_ = lim.max_line;
  max_skipped_ = std::max(lim.max_skipped_line, lim.max_line * 16);
  if (path == "-") {
    file_ = stdin;
    owns_file_ = false;
  } else {
    file_ = std::fopen(path.c_str(), "rb");
    if (!file_) {
      out_error = std::string("cannot open for reading: ") + std::strerror(errno);
      return false;
    }
    owns_file_ = true;
    // We read in large blocks ourselves; stdio's own buffer would only add a copy.
    std::setvbuf(file_, nullptr, _IONBF, 0);
  }
  buf_.resize(block_size_);
  return true;
}

void line_source::open_stream(std::FILE* file, bool owns) {
  const line_source_limits& lim = default_line_source_limits();
  block_size_ = lim.block_size > 0 ? lim.block_size : 1;
  max_line_ = lim.max_line;
  max_skipped_ = std::max(lim.max_skipped_line, lim.max_line * 16);
  file_ = file;
  owns_file_ = owns;
  buf_.resize(block_size_);
}

void line_source::open_memory(const char* data, std::size_t size) {
  max_line_ = default_line_source_limits().max_line;
  memory_mode_ = true;
  mem_ = data;
  mem_size_ = size;
  mem_pos_ = 0;
}

bool line_source::fill(std::string& out_error) {
  // Make room: move unread data to the front, then grow if the buffer is still full.
  if (begin_ > 0) {
    std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (end_ + block_size_ / 2 > buf_.size() || end_ == buf_.size()) {
    buf_.resize(buf_.size() + block_size_);
  }
  std::size_t n = std::fread(buf_.data() + end_, 1, buf_.size() - end_, file_);
  end_ += n;
  if (n == 0) {
    if (std::ferror(file_)) {
      out_error = std::string("read error: ") + std::strerror(errno);
      eof_ = true;
      read_failed_ = true;
      return false;
    }
    eof_ = true;
  }
  return true;
}

line_status line_source::next(std::string_view& out_line, std::string& out_error) {
  if (memory_mode_) {
    if (mem_pos_ >= mem_size_) return line_status::end;
    const char* b = mem_ + mem_pos_;
    std::size_t left = mem_size_ - mem_pos_;
    const char* nl = static_cast<const char*>(std::memchr(b, '\n', left));
    std::size_t len = nl ? static_cast<std::size_t>(nl - b) : left;
    mem_pos_ += nl ? len + 1 : len;
    ++line_;
    bool first = first_;
    first_ = false;
    if (len > max_line_) {
      out_error = "line longer than " + std::to_string(max_line_) + " bytes (the limit)";
      return line_status::error;
    }
    if (first && len >= 3 && std::memcmp(b, "\xEF\xBB\xBF", 3) == 0) {
      b += 3;
      len -= 3;
    }
    if (len > 0 && b[len - 1] == '\r') --len;
    out_line = std::string_view(b, len);
    return line_status::line;
  }

  if (!file_) return line_status::end;
  if (skipping_) {
    // The rest of a line already reported as over the cap is dropped up to its line end, but
    // not forever: past max_skipped_ bytes (an endless line: /dev/zero, a stream with no line
    // end) the input is given up with a last error, so that a caller that goes on after
    // errors (--skip-bad-lines) still ends.
    for (;;) {
      const char* base = buf_.data() + begin_;
      const std::size_t avail = end_ - begin_;
      const char* nl = static_cast<const char*>(std::memchr(base, '\n', avail));
      if (nl) {
        begin_ += static_cast<std::size_t>(nl - base) + 1;
        scanned_ = 0;
        skipping_ = false;
        break;
      }
      skipped_ += avail;
      begin_ = end_ = scanned_ = 0;
      if (eof_) {
        skipping_ = false;
        return line_status::end;
      }
      if (skipped_ > max_skipped_) {
        skipping_ = false;
        eof_ = true;  // given up: the next call ends
        out_error = "line without an end after " + std::to_string(skipped_) +
                    " bytes: the rest of the input is not read";
        return line_status::error;
      }
      if (!fill(out_error)) return line_status::error;
    }
  }
  for (;;) {
    const char* base = buf_.data() + begin_;
    std::size_t avail = end_ - begin_;
    const char* nl =
        scanned_ < avail
            ? static_cast<const char*>(std::memchr(base + scanned_, '\n', avail - scanned_))
            : nullptr;
    if (nl || (eof_ && avail > 0)) {
      std::size_t len = nl ? static_cast<std::size_t>(nl - base) : avail;
      begin_ += nl ? len + 1 : len;
      scanned_ = 0;
      ++line_;
      if (len > max_line_) {
        first_ = false;
        out_error = "line longer than " + std::to_string(max_line_) + " bytes (the limit)";
        return line_status::error;
      }
      if (first_) {
        first_ = false;
        if (len >= 3 && std::memcmp(base, "\xEF\xBB\xBF", 3) == 0) {
          base += 3;
          len -= 3;
        }
      }
      if (len > 0 && base[len - 1] == '\r') --len;
      out_line = std::string_view(base, len);
      return line_status::line;
    }
    if (eof_) return line_status::end;
    scanned_ = avail;
    if (avail > max_line_) {
      // Reported now, while reading, not when the line ends (it may never end); the rest of
      // the line is dropped by the next call. Memory stays bounded by the cap.
      ++line_;
      first_ = false;
      skipping_ = true;
      skipped_ = avail;
      begin_ = end_ = scanned_ = 0;
      out_error = "line longer than " + std::to_string(max_line_) + " bytes (the limit)";
      return line_status::error;
    }
    if (!fill(out_error)) {
      ++line_;
      return line_status::error;
    }
  }
}

}  // namespace avatarmap::io_detail
