#include "common/json_text.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <new>
#include <system_error>

namespace avatarmap::io_detail {

namespace {

using json = nlohmann::json;

// A SAX consumer that accepts every value and keeps only the first error: where it is (the
// count of bytes read when the parser stopped), the token it stopped on and the error's kind.
// Run on a text the DOM parser already refused, to say where and why in our words.
class error_finder final : public nlohmann::json_sax<json> {
 public:
  std::size_t position = 0;
  std::string token;
  int id = 0;

  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t pos, const std::string& last_token,
                   const json::exception& ex) override {
    position = pos;
    token = last_token;
    id = ex.id;
    return false;
  }
};

// The token as shown in a message: at most 40 bytes, control bytes as \xNN.
std::string printable(const std::string& token) {
  std::string s;
  for (std::size_t i = 0; i < token.size() && s.size() < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      s += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      s += buf;
    }
  }
  if (token.size() > 40) s += "...";
  return s;
}

// 1-based line and column of byte offset `pos` (clamped to the text).
void line_and_column(std::string_view text, std::size_t pos, long& line, long& column) {
  pos = std::min(pos, text.size());
  line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < pos; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  column = static_cast<long>(pos - line_start) + 1;
}

// A whole string literal ("...") or number: a token nlohmann read completely, so that the
// error is about the token's place, not its content.
bool complete_token(const std::string& t) {
  if (t.size() >= 2 && t.front() == '"' && t.back() == '"') return true;
  if (t.empty() || !(t[0] == '-' || (t[0] >= '0' && t[0] <= '9'))) return false;
  for (char c : t)
    if (!((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E'))
      return false;
  return true;
}

// Why the text is not valid JSON, in our words. nlohmann reports the number of bytes read when
// it stopped (one past the end when the text ended early), the token it was reading and an id
// (documented in its exception list): 101 a syntax error, 102 and 103 a \u escape or code point
// it cannot convert, 406 a number too large for a double.
std::string describe(std::string_view text, const error_finder& f) {
  const bool at_end = f.position > text.size();
  const bool whole = complete_token(f.token) && f.position >= f.token.size();
  // The offending byte, or the first byte of a complete token.
  std::size_t at = f.position > 0 ? f.position - 1 : 0;
  if (whole && f.id != 406) at = f.position - f.token.size();
  if (f.id == 406 && f.position >= f.token.size()) at = f.position - f.token.size();
  long line = 0, column = 0;
  line_and_column(text, at, line, column);
  const std::string where =
      "invalid JSON at line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
  if (f.id == 406)
    return where + "the number " + printable(f.token) +
           " is too large (JSON numbers here must fit a double, up to about 1.8e308)";
  if (at_end)
    return where +
           "the text ends too early (an unclosed string, array or object, or an empty file)";
  if (f.id == 102 || f.id == 103 ||
      (!f.token.empty() && f.token[0] == '"' && f.token.find("\\u") != std::string::npos))
    return where +
           "a bad \\u escape in a string (\\u must be followed by 4 hex digits of a "
           "valid code point)";
  if (!f.token.empty() && f.token[0] == '"' && !whole)
    return where +
           "a bad character or escape in a string (control characters must be written "
           "as \\uXXXX; the escapes are \\\" \\\\ \\/ \\b \\f \\n \\r \\t \\u)";
  const std::string found =
      whole ? printable(f.token)
            : "'" + printable(std::string(1, text[std::min(at, text.size() - 1)])) + "'";
  return where + "unexpected " + found +
         " (check for a missing or extra comma, colon, quote or bracket, or a misspelt true, "
         "false or null, just before it)";
}

}  // namespace

const char* json_type_text(const nlohmann::json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "true or false";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return "a number";
    default:
      return "a value of another kind";
  }
}

status parse_json_text(std::string_view text, const std::string& what, nlohmann::json& out,
                       const json_limits& limits) {
  out = nullptr;
  if (status s = check_json_limits(text, what, limits); !s) return s;
  try {
    out = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
    if (!out.is_discarded()) return {};
    out = nullptr;
    error_finder finder;
    json::sax_parse(text.begin(), text.end(), &finder);
    return status::parse_error(what + ": " + describe(text, finder));
  } catch (const std::bad_alloc&) {
    out = nullptr;
    return status::out_of_memory(what + ": not enough memory to read " +
                                 std::to_string(text.size()) + " bytes of JSON");
  } catch (const std::exception&) {
    // Not expected with allow_exceptions off; kept so that no library text reaches a user.
    out = nullptr;
    return status::parse_error(what + ": could not be read as JSON");
  }
}

status read_json_file(const std::string& path, nlohmann::json& out, const json_limits& limits) {
  out = nullptr;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > limits.max_bytes)
    return status::parse_error(path + ": " + std::to_string(size) + " bytes, more than the " +
                               std::to_string(limits.max_bytes) +
                               " bytes a JSON file may have here; is it the right file?");
  std::ifstream in(path, std::ios::binary);
  if (!in) return status::io_error(path + ": cannot read the file");
  // Read in blocks up to the limit: a FIFO or a device has no size to check up front.
  std::string text;
  try {
    char block[1 << 16];
    while (in.read(block, sizeof block) || in.gcount() > 0) {
      text.append(block, static_cast<std::size_t>(in.gcount()));
      if (text.size() > limits.max_bytes)
        return status::parse_error(path + ": more than the " + std::to_string(limits.max_bytes) +
                                   " bytes a JSON file may have here; is it the right file?");
    }
  } catch (const std::bad_alloc&) {
    return status::out_of_memory(path + ": not enough memory to read the file");
  }
  if (in.bad()) return status::io_error(path + ": read error");
  return parse_json_text(text, path, out, limits);
}

}  // namespace avatarmap::io_detail
