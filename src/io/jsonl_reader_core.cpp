#include "io/jsonl_reader_core.hpp"

namespace avatarmap::io_detail {

bool is_blank(std::string_view line) {
  for (char c : line)
    if (c != ' ' && c != '\t' && c != '\r') return false;
  return true;
}

bool looks_like_header(std::string_view line) {
  json_cursor c(line.data(), line.data() + line.size());
  std::string scratch;
  bool found = false;
  for_each_member(c, scratch, [&](std::string_view key) {
    if (key == "format") found = true;
    return c.skip_value();
  });
  return found;
}

status jsonl_reader_core::open_file(const std::string& path, std::string_view& out_header_line,
                                    bool& out_has_header) {
  name_ = path == "-" ? std::string("<stdin>") : path;
  std::string e;
  if (!src_.open_file(path, e)) return status::io_error(name_ + ": " + e);
  return after_open(out_header_line, out_has_header);
}

status jsonl_reader_core::open_memory(const char* data, std::size_t size, const std::string& name,
                                      std::string_view& out_header_line, bool& out_has_header) {
  name_ = name;
  src_.open_memory(data, size);
  return after_open(out_header_line, out_has_header);
}

status jsonl_reader_core::after_open(std::string_view& out_header_line, bool& out_has_header) {
  open_ = true;
  out_has_header = false;
  std::string_view line;
  line_status s = next_line(line);
  if (s == line_status::error) {
    // A bad first line (for example too long) is reported by the first next() instead.
    pending_error_ = true;
    return {};
  }
  if (s == line_status::end) return {};
  if (looks_like_header(line)) {
    out_header_line = line;
    out_has_header = true;
  } else {
    pending_ = line;
    has_pending_ = true;
  }
  return {};
}

line_status jsonl_reader_core::next_line(std::string_view& out_line) {
  if (pending_error_) {
    pending_error_ = false;
    return line_status::error;
  }
  error_.clear();
  if (has_pending_) {
    has_pending_ = false;
    out_line = pending_;
    return line_status::line;
  }
  if (!open_) {
    error_ = "reader is not open (call open() first)";
    error_code_ = status_code::invalid_argument;
    return line_status::error;
  }
  for (;;) {
    std::string e;
    line_status s = src_.next(out_line, e);
    line_ = src_.line_number();
    if (s == line_status::error) {
      set_error(e);
      if (src_.read_failed()) error_code_ = status_code::io;
      return s;
    }
    if (s == line_status::end) return s;
    if (!is_blank(out_line)) return s;
  }
}

bool jsonl_reader_core::set_error(std::string_view message) {
  error_code_ = status_code::parse;
  error_ = name_;
  error_ += ':';
  error_ += std::to_string(line_);
  error_ += ": ";
  error_ += message;
  return false;
}

}  // namespace avatarmap::io_detail
