#include "io/json_scan.hpp"

#include <cstring>
#include <limits>

namespace avatarmap::io_detail {

namespace {

bool starts_with(const char* p, const char* end, std::string_view word) {
  return static_cast<std::size_t>(end - p) >= word.size() &&
         std::memcmp(p, word.data(), word.size()) == 0;
}

// After from_chars reported result_out_of_range for [b, e): +-inf when the magnitude is
// too large, +-0 when too small. Decided from the decimal exponent so that no locale-
// dependent strtod is involved.
double out_of_range_value(const char* b, const char* e) {
  bool negative = b < e && *b == '-';
  if (negative) ++b;
  long lead = 0;  // decimal exponent of the first non-zero digit
  bool seen_nonzero = false, in_fraction = false;
  long int_digits = 0, frac_zeros = 0;
  for (; b < e; ++b) {
    char c = *b;
    if (c == '.') {
      in_fraction = true;
    } else if (c >= '0' && c <= '9') {
      if (!seen_nonzero && c != '0') seen_nonzero = true;
      if (!in_fraction) {
        if (seen_nonzero) ++int_digits;
      } else if (!seen_nonzero) {
        ++frac_zeros;
      }
    } else {
      break;
    }
  }
  lead = int_digits > 0 ? int_digits - 1 : -(frac_zeros + 1);
  long exp = 0;
  if (b < e && (*b == 'e' || *b == 'E')) {
    ++b;
    bool eneg = false;
    if (b < e && (*b == '+' || *b == '-')) eneg = *b++ == '-';
    for (; b < e && *b >= '0' && *b <= '9'; ++b)
      if (exp < 100000000) exp = exp * 10 + (*b - '0');
    if (eneg) exp = -exp;
  }
  double mag = lead + exp > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  return negative ? -mag : mag;
}

}  // namespace

std::string describe_char(const char* p, const char* end) {
  if (p >= end) return "end of line";
  unsigned char c = static_cast<unsigned char>(*p);
  if (c >= 0x20 && c < 0x7f) return std::string("'") + static_cast<char>(c) + "'";
  static const char k_hex[] = "0123456789abcdef";
  std::string s = "byte 0x";
  s += k_hex[c >> 4];
  s += k_hex[c & 15];
  return s;
}

const char* json_number_end(const char* p, const char* end) {
  auto digit = [end](const char* q) { return q < end && *q >= '0' && *q <= '9'; };
  if (p < end && *p == '-') ++p;
  if (!digit(p)) return nullptr;
  if (*p == '0') {
    ++p;
    if (digit(p)) return nullptr;  // a leading zero: "00.5", "01"
  } else {
    while (digit(p)) ++p;
  }
  if (p < end && *p == '.') {
    ++p;
    if (!digit(p)) return nullptr;  // "1." and "1.e5"
    while (digit(p)) ++p;
  }
  if (p < end && (*p == 'e' || *p == 'E')) {
    ++p;
    if (p < end && (*p == '+' || *p == '-')) ++p;
    if (!digit(p)) return nullptr;  // "1e", "1e+"
    while (digit(p)) ++p;
  }
  return p;
}

bool json_cursor::fail(std::string_view message) {
  if (error.empty()) {
    error.assign(message);
    error += " at column ";
    error += std::to_string(column());
  }
  return false;
}

bool json_cursor::fail_expected(std::string_view what) {
  std::string m = "expected ";
  m += what;
  m += ", found ";
  m += describe_char(p, end);
  return fail(m);
}

bool json_cursor::eat_null() {
  skip_ws();
  if (starts_with(p, end, "null")) {
    p += 4;
    return true;
  }
  return false;
}

bool json_cursor::parse_special(double& out, bool* was_null, bool as_float) {
  skip_ws();
  if (was_null) *was_null = false;
  if (starts_with(p, end, "null")) {
    p += 4;
    if (was_null) *was_null = true;
    out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  // Python's json module writes these for non-finite floats; read them as "not seen".
  if (starts_with(p, end, "NaN")) {
    p += 3;
    out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (starts_with(p, end, "Infinity")) {
    p += 8;
    out = std::numeric_limits<double>::infinity();
    return true;
  }
  if (starts_with(p, end, "-Infinity")) {
    p += 9;
    out = -std::numeric_limits<double>::infinity();
    return true;
  }
  if (p < end &&
      ((*p >= '0' && *p <= '9') || (*p == '-' && p + 1 < end && p[1] >= '0' && p[1] <= '9'))) {
    // from_chars accepts more than JSON ("00.5", "1.", "1.e5"): the token must be a JSON
    // number, read in full.
    const char* token_end = json_number_end(p, end);
    if (token_end == nullptr)
      return fail("not a JSON number (no leading zeros; digits must follow '.' and 'e')");
    std::from_chars_result r;
    if (as_float) {
      float f = 0.f;
      r = std::from_chars(p, token_end, f);
      out = f;
    } else {
      r = std::from_chars(p, token_end, out);
    }
    if (r.ec == std::errc() && r.ptr != token_end)
      return fail("not a JSON number (no leading zeros; digits must follow '.' and 'e')");
    if (r.ec == std::errc::result_out_of_range) {
      out = out_of_range_value(p, r.ptr);
      p = r.ptr;
      return true;
    }
    if (r.ec == std::errc()) {
      p = r.ptr;
      return true;
    }
  }
  return fail_expected("a number or null");
}

bool json_cursor::parse_float_slow(float& out, bool* was_null) {
  double d = 0.0;
  if (!parse_special(d, was_null, true)) return false;
  out = static_cast<float>(d);  // exact: d is a float, +-inf, +-0 or NaN here
  return true;
}

bool json_cursor::parse_double_slow(double& out, bool* was_null) {
  return parse_special(out, was_null, false);
}

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

void append_utf8(std::string& s, unsigned cp) {
  if (cp < 0x80) {
    s += static_cast<char>(cp);
  } else if (cp < 0x800) {
    s += static_cast<char>(0xc0 | (cp >> 6));
    s += static_cast<char>(0x80 | (cp & 0x3f));
  } else if (cp < 0x10000) {
    s += static_cast<char>(0xe0 | (cp >> 12));
    s += static_cast<char>(0x80 | ((cp >> 6) & 0x3f));
    s += static_cast<char>(0x80 | (cp & 0x3f));
  } else {
    s += static_cast<char>(0xf0 | (cp >> 18));
    s += static_cast<char>(0x80 | ((cp >> 12) & 0x3f));
    s += static_cast<char>(0x80 | ((cp >> 6) & 0x3f));
    s += static_cast<char>(0x80 | (cp & 0x3f));
  }
}

}  // namespace

bool json_cursor::parse_string(std::string_view& out, std::string& scratch) {
  skip_ws();
  if (p >= end || *p != '"') return fail_expected("a string");
  ++p;
  const char* start = p;
  while (p < end && *p != '"' && *p != '\\' && static_cast<unsigned char>(*p) >= 0x20) ++p;
  if (p < end && *p == '"') {
    out = std::string_view(start, static_cast<std::size_t>(p - start));
    ++p;
    return true;
  }
  // Slow path: escapes (or an error).
  scratch.assign(start, p);
  while (p < end) {
    char c = *p;
    if (c == '"') {
      ++p;
      out = scratch;
      return true;
    }
    if (static_cast<unsigned char>(c) < 0x20) return fail("control character in a string");
    if (c != '\\') {
      scratch += c;
      ++p;
      continue;
    }
    if (++p >= end) break;
    char e = *p++;
    switch (e) {
      case '"':
        scratch += '"';
        break;
      case '\\':
        scratch += '\\';
        break;
      case '/':
        scratch += '/';
        break;
      case 'b':
        scratch += '\b';
        break;
      case 'f':
        scratch += '\f';
        break;
      case 'n':
        scratch += '\n';
        break;
      case 'r':
        scratch += '\r';
        break;
      case 't':
        scratch += '\t';
        break;
      case 'u': {
        auto read4 = [this](unsigned& v) {
          if (end - p < 4) return false;
          v = 0;
          for (int i = 0; i < 4; ++i) {
            int h = hex_value(p[i]);
            if (h < 0) return false;
            v = v * 16 + static_cast<unsigned>(h);
          }
          p += 4;
          return true;
        };
        unsigned cp = 0;
        if (!read4(cp)) return fail("bad \\u escape in a string (expected 4 hex digits)");
        if (cp >= 0xd800 && cp < 0xdc00 && end - p >= 6 && p[0] == '\\' && p[1] == 'u') {
          const char* save = p;
          p += 2;
          unsigned lo = 0;
          if (read4(lo) && lo >= 0xdc00 && lo < 0xe000) {
            cp = 0x10000 + ((cp - 0xd800) << 10) + (lo - 0xdc00);
          } else {
            p = save;
          }
        }
        append_utf8(scratch, cp);
        break;
      }
      default:
        --p;
        return fail(
            "bad escape in a string (expected one of \\\" \\\\ \\/ \\b \\f \\n \\r \\t \\u)");
    }
  }
  return fail("unterminated string (expected '\"' before the end of the line)");
}

bool json_cursor::skip_value(int depth) {
  char c = peek();
  // `depth` containers are open around this value; opening one more must stay within the
  // limit (a scalar inside the deepest allowed array is fine).
  if ((c == '{' || c == '[') && depth >= k_max_json_depth)
    return fail("nesting too deep (at most 256 levels of arrays and objects)");
  switch (c) {
    case '"': {
      std::string_view s;
      std::string scratch;
      return parse_string(s, scratch);
    }
    case '{': {
      ++p;
      if (eat('}')) return true;
      for (;;) {
        std::string_view key;
        std::string scratch;
        if (!parse_string(key, scratch)) return false;
        if (!eat(':')) return fail_expected("':'");
        if (!skip_value(depth + 1)) return false;
        if (eat(',')) continue;
        if (eat('}')) return true;
        return fail_expected("',' or '}'");
      }
    }
    case '[': {
      ++p;
      if (eat(']')) return true;
      for (;;) {
        if (!skip_value(depth + 1)) return false;
        if (eat(',')) continue;
        if (eat(']')) return true;
        return fail_expected("',' or ']'");
      }
    }
    case 't':
      if (starts_with(p, end, "true")) {
        p += 4;
        return true;
      }
      break;
    case 'f':
      if (starts_with(p, end, "false")) {
        p += 5;
        return true;
      }
      break;
    default: {
      double d;
      return parse_double(d);
    }
  }
  return fail_expected("a JSON value");
}

}  // namespace avatarmap::io_detail
