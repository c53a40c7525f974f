// Internal: buffered, atomic text output for the text writers (*.jsonl, .vrma, .bvh). The
// bytes go through atomic_file (atomic_file.hpp: a unique temporary file beside the target,
// fsynced and renamed over PATH by commit(), the replaced file's mode kept, removed on
// failure and on SIGINT/SIGTERM). Destroying an uncommitted output removes the temporary
// file and leaves PATH untouched. "-" writes to standard output (not atomic; commit() only
// flushes). Each buffer written to a file is handed to the disk at once (sync_file_range on
// Linux), so that commit()'s fsync finds little left to write. Numbers are written as the
// shortest text that reads back to the same value (std::to_chars's characters; floats through
// float_text.hpp, which is faster); non-finite numbers are written as null.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "common/atomic_file.hpp"
#include "common/float_text.hpp"

namespace avatarmap::io_detail {

class text_output {
 public:
  text_output() = default;
  ~text_output();
  text_output(const text_output&) = delete;
  text_output& operator=(const text_output&) = delete;

  /// Creates the temporary file (atomic_file::open's errors), or selects standard output
  /// for "-".
  status open(const std::string& path);
  /// True from a successful open() until commit(), also after a failed write (then every
  /// call fails with error()).
  bool is_open() const { return open_; }
  const std::string& path() const { return path_; }

  /// Makes sure `n` bytes fit in the buffer (flushing first if needed); false on a write
  /// error (then error() says why). `n` must be at most k_reserve_max.
  static constexpr std::size_t k_reserve_max = 4096;
  bool reserve(std::size_t n) {
    if (pos_ + n <= capacity()) return true;
    return flush();
  }
  /// Unchecked appends: call reserve() first.
  void put(char c) { buf_[pos_++] = c; }
  void put(std::string_view s) {
    std::char_traits<char>::copy(buf_.data() + pos_, s.data(), s.size());
    pos_ += s.size();
  }
  void put_number(float v) {
    if (!std::isfinite(v)) return put("null");
    // Identity rotations and unused weights are common; skip the shortest-digits search.
    if (v == 0.f && !std::signbit(v)) return put('0');
    if (v == 1.f) return put('1');
    // Writes up to k_shortest_float_room bytes: within the slack after capacity().
    pos_ = static_cast<std::size_t>(write_shortest_float(buf_.data() + pos_, v) - buf_.data());
  }
  void put_number(double v) {
    if (!std::isfinite(v)) return put("null");
    pos_ = static_cast<std::size_t>(
        std::to_chars(buf_.data() + pos_, buf_.data() + buf_.size(), v).ptr - buf_.data());
  }
  void put_number(int v) {
    pos_ = static_cast<std::size_t>(
        std::to_chars(buf_.data() + pos_, buf_.data() + buf_.size(), v).ptr - buf_.data());
  }
  /// Appends any length (checked).
  bool write(std::string_view s);

  /// Writes the buffer out; false on error.
  bool flush();
  /// Flush, fsync, rename over the target (atomic_file::commit). After it, the output is
  /// closed; on failure the target is as it was.
  status commit();
  /// First write error ("PATH: write failed: No space left on device; the previous file is
  /// unchanged").
  const std::string& error() const { return error_; }
  /// error() as a status: a write error is an I/O error (status_code::io).
  status error_status() const { return status::io_error(error_); }

 private:
  void discard();
  /// Bytes reserve() hands out; buf_ has k_slack more, for the fixed-size blocks that
  /// write_shortest_float writes.
  static constexpr std::size_t k_slack = 48;
  static_assert(k_slack >= k_shortest_float_room);
  std::size_t capacity() const { return buf_.size() > k_slack ? buf_.size() - k_slack : 0; }

  atomic_file file_;
  bool open_ = false;
  bool is_stdout_ = false;
  bool failed_ = false;
  std::string path_;
  std::string error_;
  std::vector<char> buf_;
  std::size_t pos_ = 0;
  unsigned long long written_ = 0;  // bytes flushed to the file so far
};

}  // namespace avatarmap::io_detail
