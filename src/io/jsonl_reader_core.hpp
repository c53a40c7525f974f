// Internal: what the *.landmarks.jsonl and *.pose.jsonl readers share: the line source,
// blank-line skipping, recognising the optional header line and "FILE:LINE: " messages.
#pragma once

#include <string>
#include <string_view>

#include "avatarmap/core/status.hpp"
#include "io/json_scan.hpp"
#include "io/line_source.hpp"

namespace avatarmap::io_detail {

class jsonl_reader_core {
 public:
  /// Opens the file (or memory) and reads up to the first non-blank line. If that line is a
  /// header (a JSON object with a top-level "format" key) `out_header_line` views it and
  /// `out_has_header` is true; otherwise the line is kept for the first next_line().
  status open_file(const std::string& path, std::string_view& out_header_line,
                   bool& out_has_header);
  status open_memory(const char* data, std::size_t size, const std::string& name,
                     std::string_view& out_header_line, bool& out_has_header);

  /// Next non-blank line. On error() the message is already set (with prefix) and
  /// error_code() says its kind.
  line_status next_line(std::string_view& out_line);

  /// Sets the error to "NAME:LINE: message" (a malformed line: status_code::parse) and
  /// returns false.
  bool set_error(std::string_view message);
  status error_status(std::string_view message) {
    set_error(message);
    return status::parse_error(error_);
  }

  const std::string& error() const { return error_; }
  /// The kind of the last error: parse (a malformed or over-long line), io (reading the file
  /// failed), invalid_argument (not open).
  status_code error_code() const { return error_code_; }
  long line() const { return line_; }
  const std::string& name() const { return name_; }
  bool is_open() const { return open_; }

 private:
  status after_open(std::string_view& out_header_line, bool& out_has_header);

  line_source src_;
  std::string name_;
  std::string error_;
  status_code error_code_ = status_code::parse;
  std::string_view pending_;
  bool has_pending_ = false;
  bool pending_error_ = false;
  bool open_ = false;
  long line_ = 0;
};

/// True for blank lines (only spaces and tabs).
bool is_blank(std::string_view line);
/// True when `line` is a JSON object with a top-level "format" key.
bool looks_like_header(std::string_view line);

}  // namespace avatarmap::io_detail
