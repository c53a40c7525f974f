// Internal: reads a text file (or standard input, or a memory buffer) one line at a time in
// constant memory. The file is read in blocks (1 MiB by default); a line that does not fit
// in a block grows the buffer, up to a cap (64 MiB by default). A line over the cap is
// reported as an error as soon as the cap is passed (not when the line ends, which an endless
// input never reaches); a call after it drops the rest of that line, but gives up the input
// with a last error once the line has passed 1 GiB (or 16 caps, if more) without an end, so
// that no call reads without bound. Line ends are "\n" or "\r\n"; a last line without a line
// end is still a line. A UTF-8 byte-order mark at the start is skipped.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace avatarmap::io_detail {

inline constexpr std::size_t k_default_block_size = std::size_t{1} << 20;
inline constexpr std::size_t k_default_max_line = std::size_t{64} << 20;
/// A line over the cap is dropped up to its end while it stays within this many bytes (and
/// 16 caps); a longer one gives the input up.
inline constexpr std::size_t k_default_max_skipped_line = std::size_t{1} << 30;

/// Block size and line cap used by readers opened afterwards. Tests shrink them to exercise
/// lines that span blocks; not thread-safe, not for production use.
struct line_source_limits {
  std::size_t block_size = k_default_block_size;
  std::size_t max_line = k_default_max_line;
  std::size_t max_skipped_line = k_default_max_skipped_line;
};
line_source_limits& default_line_source_limits();

enum class line_status { line, end, error };

class line_source {
 public:
  line_source() = default;
  ~line_source();
  line_source(const line_source&) = delete;
  line_source& operator=(const line_source&) = delete;

  /// Opens `path` ("-" = standard input). On failure returns false and sets `out_error`.
  bool open_file(const std::string& path, std::string& out_error);
  /// Reads from an open stream (closed by the destructor when `owns`). For fuzzing.
  void open_stream(std::FILE* file, bool owns);
  /// Reads from memory (not copied).
  void open_memory(const char* data, std::size_t size);

  /// Next line without its line end. The view stays valid until the next call. On error
  /// (read failure, line over the cap) sets `out_error` (without file/line prefix).
  line_status next(std::string_view& out_line, std::string& out_error);
  /// 1-based number of the line last returned (or that failed).
  long line_number() const { return line_; }
  /// True once reading the file failed (a read error, not a line over the cap).
  bool read_failed() const { return read_failed_; }

 private:
  bool fill(std::string& out_error);  // reads more data after end_; false on read error

  std::FILE* file_ = nullptr;
  bool owns_file_ = false;
  bool eof_ = false;
  bool read_failed_ = false;
  bool first_ = true;
  bool skipping_ = false;      // the rest of a line over the cap is still to be dropped
  std::size_t skipped_ = 0;    // bytes of that line seen so far
  const char* mem_ = nullptr;  // memory mode when non-null (or size 0)
  bool memory_mode_ = false;
  std::size_t mem_size_ = 0;
  std::size_t mem_pos_ = 0;
  std::vector<char> buf_;
  std::size_t begin_ = 0;  // unread data is buf_[begin_, end_)
  std::size_t end_ = 0;
  std::size_t scanned_ = 0;  // bytes after begin_ already known to hold no '\n'
  std::size_t block_size_ = k_default_block_size;
  std::size_t max_line_ = k_default_max_line;
  std::size_t max_skipped_ = k_default_max_skipped_line;
  long line_ = 0;
};

}  // namespace avatarmap::io_detail
