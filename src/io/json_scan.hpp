// Internal: a minimal, allocation-free JSON scanner over one line of text, used by the
// *.landmarks.jsonl and *.pose.jsonl readers. It is not a general JSON parser: it offers
// exactly the steps those readers need (strings, numbers, skipping any value) and reports
// the first problem as a short message. No stability promise.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "io/json_number.hpp"

namespace avatarmap::io_detail {

/// Deepest nesting of arrays and objects skip_value() accepts in an unknown key's value: a
/// value of 256 nested arrays passes, 257 fail ("[]" is one level).
inline constexpr int k_max_json_depth = 256;

/// End of the JSON number token starting at `p` (RFC 8259 grammar: optional '-', no leading
/// zeros, digits after '.' and after 'e'), or nullptr when the text there is not one. Digits
/// that follow a valid token (the "1" of "01") make it invalid.
const char* json_number_end(const char* p, const char* end);

struct json_cursor {
  const char* p = nullptr;
  const char* begin = nullptr;  // start of the line (for columns)
  const char* end = nullptr;
  std::string error;  // set by the first failing call; empty while all went well

  json_cursor(const char* b, const char* e) : p(b), begin(b), end(e) {}

  bool at_end() const { return p >= end; }
  long column() const { return static_cast<long>(p - begin) + 1; }

  void skip_ws() {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
  }
  /// Skips white space and consumes `c` if it is next.
  bool eat(char c) {
    skip_ws();
    if (p < end && *p == c) {
      ++p;
      return true;
    }
    return false;
  }
  /// Skips white space and returns the next character (or '\0' at the end; not consumed).
  char peek() {
    skip_ws();
    return p < end ? *p : '\0';
  }

  /// Sets `error` (if not set yet) to "MESSAGE at column N" and returns false.
  bool fail(std::string_view message);
  /// Fails with "expected WHAT, found X" describing the current character.
  bool fail_expected(std::string_view what);

  /// Reads a string. `out` views the line when the string has no escapes, else `scratch`.
  bool parse_string(std::string_view& out, std::string& scratch);
  /// Reads a number or a non-finite token into `out`. `null`, `NaN`, `Infinity` and
  /// `-Infinity` give a non-finite value and set `was_null` for `null`. Out-of-range
  /// magnitudes give +-inf (overflow) or 0/subnormal (underflow), as strtof/strtod do.
  bool parse_float(float& out, bool* was_null = nullptr) {
    skip_ws();
    if (const char* q = json_scan_float(begin, p, end, out)) {
      p = q;
      if (was_null) *was_null = false;
      return true;
    }
    // Otherwise a JSON number that std::from_chars reads correctly rounded (from_chars alone
    // would also take "00.5" or "1.": the token is checked against JSON's grammar first).
    if (p < end &&
        ((*p >= '0' && *p <= '9') || (*p == '-' && p + 1 < end && p[1] >= '0' && p[1] <= '9'))) {
      const char* token_end = json_number_end(p, end);
      auto r = token_end ? std::from_chars(p, token_end, out)
                         : std::from_chars_result{p, std::errc::invalid_argument};
      if (r.ec == std::errc() && r.ptr == token_end) {
        p = r.ptr;
        if (was_null) *was_null = false;
        return true;
      }
    }
    return parse_float_slow(out, was_null);
  }
  bool parse_double(double& out, bool* was_null = nullptr) {
    skip_ws();
    if (p < end &&
        ((*p >= '0' && *p <= '9') || (*p == '-' && p + 1 < end && p[1] >= '0' && p[1] <= '9'))) {
      const char* token_end = json_number_end(p, end);
      auto r = token_end ? std::from_chars(p, token_end, out)
                         : std::from_chars_result{p, std::errc::invalid_argument};
      if (r.ec == std::errc() && r.ptr == token_end) {
        p = r.ptr;
        if (was_null) *was_null = false;
        return true;
      }
    }
    return parse_double_slow(out, was_null);
  }
  /// Skips any JSON value (nested up to k_max_json_depth levels).
  bool skip_value(int depth = 0);
  /// True when the next token is the literal `null` (consumed).
  bool eat_null();

 private:
  bool parse_float_slow(float& out, bool* was_null);
  bool parse_double_slow(double& out, bool* was_null);
  /// Reads a non-finite token or an out-of-range number as a double (shared slow path).
  bool parse_special(double& out, bool* was_null, bool as_float);
};

/// Reads the members of an object: '{', then for each member the key and ':', calls
/// `on_member(key)` which must consume the value (returning false on error), then ',' or '}'.
template <class F>
bool for_each_member(json_cursor& c, std::string& scratch, F&& on_member) {
  if (!c.eat('{')) return c.fail_expected("'{'");
  if (c.eat('}')) return true;
  for (;;) {
    std::string_view key;
    if (!c.parse_string(key, scratch)) return false;
    if (!c.eat(':')) return c.fail_expected("':'");
    if (!on_member(key)) return false;
    if (c.eat(',')) continue;
    if (c.eat('}')) return true;
    return c.fail_expected("',' or '}'");
  }
}

/// Short printable description of a character for error messages ("'x'", "end of line").
std::string describe_char(const char* p, const char* end);

}  // namespace avatarmap::io_detail
