// The internal scanner: its fast float path must agree bit for bit with std::from_chars.
#include "io/json_scan.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "io/line_source.hpp"

namespace avatarmap::io_detail {
namespace {

std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

// Parses `s` with the scanner; checks the whole string was used.
float scan(const std::string& s) {
  json_cursor c(s.data(), s.data() + s.size());
  float f = -12345.f;
  EXPECT_TRUE(c.parse_float(f)) << s << ": " << c.error;
  EXPECT_TRUE(c.at_end()) << s;
  return f;
}

// glibc's strtof: correctly rounded, +-HUGE_VALF on overflow, 0 on underflow (C locale).
float reference(const std::string& s) { return std::strtof(s.c_str(), nullptr); }

TEST(json_scan, shortest_float_text_reads_back_exactly) {
  std::mt19937 rng(123);
  std::uniform_int_distribution<std::uint32_t> any;
  char buf[64];
  for (int i = 0; i < 1000000; ++i) {
    std::uint32_t u = any(rng);
    float f;
    std::memcpy(&f, &u, 4);
    if (!std::isfinite(f)) continue;
    auto r = std::to_chars(buf, buf + sizeof buf, f);
    std::string s(buf, r.ptr);
    ASSERT_EQ(bits(scan(s)), u) << s;
  }
}

TEST(json_scan, fast_path_agrees_with_from_chars_on_random_decimals) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> digit(0, 9), ndig(1, 17), epos(-25, 25), coin(0, 3);
  for (int i = 0; i < 1000000; ++i) {
    std::string s;
    if (coin(rng) == 0) s += '-';
    int n = ndig(rng);
    int point = std::uniform_int_distribution<int>(0, n)(rng);
    std::string d;
    for (int k = 0; k < n; ++k) d += static_cast<char>('0' + digit(rng));
    // JSON: no leading zeros in the integer part.
    std::string ip = point == 0 ? "0" : d.substr(0, static_cast<std::size_t>(point));
    while (ip.size() > 1 && ip[0] == '0') ip.erase(0, 1);
    s += ip;
    if (point < n) s += "." + d.substr(static_cast<std::size_t>(point));
    if (coin(rng) == 0) s += "e" + std::to_string(epos(rng));
    ASSERT_EQ(bits(scan(s)), bits(reference(s))) << s;
  }
}

TEST(json_scan, float_midpoints_round_to_even) {
  // 16777217 = 2^24 + 1 lies exactly halfway between two floats.
  EXPECT_EQ(scan("16777217"), 16777216.f);
  EXPECT_EQ(scan("16777219"), 16777220.f);
  EXPECT_EQ(scan("1.6777217e7"), 16777216.f);
  EXPECT_EQ(bits(scan("-0")), bits(-0.f));
  EXPECT_EQ(bits(scan("-0.0e0")), bits(-0.f));
  EXPECT_EQ(scan("1e-45"), std::numeric_limits<float>::denorm_min());
  EXPECT_EQ(scan("3.4028235e38"), std::numeric_limits<float>::max());
  EXPECT_TRUE(std::isinf(scan("3.5e38")));
  EXPECT_EQ(scan("1e-50"), 0.f);
  EXPECT_EQ(bits(scan("-1e-50")), bits(-0.f));
  EXPECT_TRUE(std::isinf(scan("1e99999999999999999999")));
  EXPECT_EQ(scan("0.0000000000000000000000000000000000000000000000000000001e55"), 1.f);
}

TEST(json_scan, strings_with_escapes) {
  std::string s = R"("a\"b\\c\/d\b\f\n\r\t\u00e9\ud83d\ude00\u0041")";
  json_cursor c(s.data(), s.data() + s.size());
  std::string scratch;
  std::string_view v;
  ASSERT_TRUE(c.parse_string(v, scratch)) << c.error;
  EXPECT_EQ(v,
            "a\"b\\c/d\b\f\n\r\t\xc3\xa9\xf0\x9f\x98\x80"
            "A");
  for (std::string bad : {R"("\x")", R"("\u12")", "\"abc", "\"a\tb\""}) {
    json_cursor b(bad.data(), bad.data() + bad.size());
    EXPECT_FALSE(b.parse_string(v, scratch)) << bad;
    EXPECT_FALSE(b.error.empty());
  }
}

TEST(json_scan, skip_value_skips_any_value) {
  std::string s = R"( {"a":[1,-2.5e3,true,false,null,"x",{"b":{}}],"c":[]} ,)";
  json_cursor c(s.data(), s.data() + s.size());
  ASSERT_TRUE(c.skip_value()) << c.error;
  EXPECT_TRUE(c.eat(','));
  for (std::string bad : {"[1,]", "{\"a\" 1}", "tru", "[", "{\"a\":1,}", "-", "+1", "nul"}) {
    json_cursor b(bad.data(), bad.data() + bad.size());
    EXPECT_FALSE(b.skip_value() && b.at_end()) << bad;
  }
}

// Nesting: the documented limit is 256 levels of arrays/objects (k_max_json_depth); a value
// with exactly 256 passes and 257 fails, whether the innermost container is empty or holds a
// scalar, for arrays, objects and a mix.
TEST(json_scan, nesting_limit_is_exactly_256_levels) {
  auto arrays = [](int levels, const std::string& inner) {
    return std::string(static_cast<std::size_t>(levels), '[') + inner +
           std::string(static_cast<std::size_t>(levels), ']');
  };
  auto objects = [](int levels) {
    std::string s;
    for (int i = 0; i < levels; ++i) s += i + 1 < levels ? "{\"k\":" : "{}";
    return s + std::string(static_cast<std::size_t>(levels - 1), '}');
  };
  auto mixed = [](int levels) {
    std::string open, close;
    for (int i = 0; i < levels; ++i) {
      const bool object = i % 2 == 1;
      open += object ? "{\"k\":" : "[";
      close = std::string(object ? "}" : "]") + close;
    }
    return open + "1" + close;
  };
  ASSERT_EQ(k_max_json_depth, 256);
  for (const std::string& inner : {std::string(), std::string("1"), std::string("\"s\"")}) {
    for (int levels : {1, 255, 256, 257, 300}) {
      const std::string s = arrays(levels, inner);
      json_cursor c(s.data(), s.data() + s.size());
      const bool ok = c.skip_value() && c.at_end();
      EXPECT_EQ(ok, levels <= 256) << levels << " arrays around '" << inner << "'";
      if (levels > 256) EXPECT_NE(c.error.find("nesting too deep"), std::string::npos) << c.error;
    }
  }
  for (int levels : {1, 256, 257}) {
    const std::string o = objects(levels);
    json_cursor c(o.data(), o.data() + o.size());
    EXPECT_EQ(c.skip_value() && c.at_end(), levels <= 256) << levels << " objects";
    const std::string m = mixed(levels);
    json_cursor d(m.data(), m.data() + m.size());
    EXPECT_EQ(d.skip_value() && d.at_end(), levels <= 256) << levels << " mixed";
  }
}

// JSON numbers (RFC 8259): no leading zeros, digits after '.' and after 'e'. std::from_chars,
// which the slow paths use, would accept "00.5" and "1."; the scanner must not.
TEST(json_scan, numbers_follow_the_json_grammar) {
  for (std::string good : {"0", "-0", "0.5", "-0.5e-3", "0e0", "10", "1E+2", "123.456e7", "1e400",
                           "0.0000000000000000000000000000000000000000000001"}) {
    json_cursor f(good.data(), good.data() + good.size());
    float x;
    EXPECT_TRUE(f.parse_float(x) && f.at_end()) << good << ": " << f.error;
    json_cursor d(good.data(), good.data() + good.size());
    double y;
    EXPECT_TRUE(d.parse_double(y) && d.at_end()) << good << ": " << d.error;
    json_cursor v(good.data(), good.data() + good.size());
    EXPECT_TRUE(v.skip_value() && v.at_end()) << good << ": " << v.error;
  }
  for (std::string bad : {"00.5", "00", "01", "-01", "-00.5", "0123456789012345678901234", "1.",
                          "1.e5", "-1.", "1e", "1e+", "1E-", "007e400", "00.5e-400"}) {
    json_cursor f(bad.data(), bad.data() + bad.size());
    float x;
    EXPECT_FALSE(f.parse_float(x) && f.at_end()) << bad;
    json_cursor d(bad.data(), bad.data() + bad.size());
    double y;
    EXPECT_FALSE(d.parse_double(y) && d.at_end()) << bad;
    json_cursor v(bad.data(), bad.data() + bad.size());
    EXPECT_FALSE(v.skip_value() && v.at_end()) << bad;
  }
  const std::string list = "12,";
  EXPECT_EQ(json_number_end(list.data(), list.data() + list.size()), list.data() + 2);
  const std::string lead = "00.5";
  EXPECT_EQ(json_number_end(lead.data(), lead.data() + lead.size()), nullptr);
  json_cursor c(lead.data(), lead.data() + lead.size());
  double y;
  ASSERT_FALSE(c.parse_double(y));
  EXPECT_NE(c.error.find("not a JSON number"), std::string::npos) << c.error;
}

TEST(line_source, lines_across_blocks) {
  std::string text = "a\nbb\r\n\nccc\r\nlast";
  std::vector<std::string> expected = {"a", "bb", "", "ccc", "last"};
  line_source src;
  src.open_memory(text.data(), text.size());
  std::string_view line;
  std::string err;
  for (auto& e : expected) {
    ASSERT_EQ(src.next(line, err), line_status::line);
    EXPECT_EQ(line, e);
  }
  EXPECT_EQ(src.next(line, err), line_status::end);
  EXPECT_EQ(src.line_number(), 5);
}

}  // namespace
}  // namespace avatarmap::io_detail

namespace avatarmap::io_detail {
namespace {

TEST(line_source, memory_and_stream_apply_the_same_line_cap) {
  line_source_limits saved = default_line_source_limits();
  default_line_source_limits() = {3, 8};
  std::string text =
      "\xEF\xBB\xBF"
      "12345\n123456789\n12345678\r\n";
  for (int stream = 0; stream < 2; ++stream) {
    SCOPED_TRACE(stream ? "stream" : "memory");
    line_source src;
    if (stream) {
      src.open_stream(fmemopen(text.data(), text.size(), "rb"), true);
    } else {
      src.open_memory(text.data(), text.size());
    }
    std::string_view line;
    std::string err;
    ASSERT_EQ(src.next(line, err), line_status::line);  // BOM + 5 bytes: within the cap
    EXPECT_EQ(line, "12345");
    ASSERT_EQ(src.next(line, err), line_status::error);
    EXPECT_NE(err.find("longer than 8 bytes"), std::string::npos);
    ASSERT_EQ(src.next(line, err), line_status::error);  // 8 bytes + '\r'
    EXPECT_EQ(src.line_number(), 3);
    EXPECT_EQ(src.next(line, err), line_status::end);
  }
  default_line_source_limits() = saved;
}

// An input that never ends a line (/dev/zero, `solve - < /dev/zero`): the cap is reported
// while reading, after about a cap's worth of bytes, not when the line ends; a caller that goes
// on gets the rest of a long line dropped up to its end, and an endless one given up after
// max_skipped_line bytes (16 caps here), with a last error and then the end.
struct endless_input {
  std::size_t served = 0;
  std::size_t newline_at = static_cast<std::size_t>(-1);  // byte offset of one '\n'
};
ssize_t endless_read(void* cookie, char* buf, std::size_t size) {
  auto* in = static_cast<endless_input*>(cookie);
  for (std::size_t i = 0; i < size; ++i) buf[i] = in->served + i == in->newline_at ? '\n' : 'x';
  in->served += size;
  return static_cast<ssize_t>(size);
}

TEST(line_source, an_endless_line_is_reported_after_the_cap_not_at_its_end) {
  line_source_limits saved = default_line_source_limits();
  default_line_source_limits() = {4096, 100000, 1600000};
  const std::size_t slack = 3 * 4096;
  endless_input in;
  in.newline_at = 350000;  // the first line ends here (3.5 caps); the second never does
  cookie_io_functions_t io{endless_read, nullptr, nullptr, nullptr};
  line_source src;
  src.open_stream(fopencookie(&in, "rb", io), true);
  std::string_view line;
  std::string err;
  ASSERT_EQ(src.next(line, err), line_status::error);
  EXPECT_NE(err.find("longer than 100000 bytes"), std::string::npos) << err;
  EXPECT_EQ(src.line_number(), 1);
  EXPECT_LE(in.served, 100000u + slack);
  // Going on: the rest of line 1 is dropped, then line 2 is over the cap too.
  ASSERT_EQ(src.next(line, err), line_status::error);
  EXPECT_NE(err.find("longer than 100000 bytes"), std::string::npos) << err;
  EXPECT_EQ(src.line_number(), 2);
  EXPECT_LE(in.served, in.newline_at + 100000u + slack);
  // Going on again: line 2 has no end; given up after max_skipped_line, then the end.
  ASSERT_EQ(src.next(line, err), line_status::error);
  EXPECT_NE(err.find("line without an end after"), std::string::npos) << err;
  EXPECT_GE(in.served, in.newline_at + 16 * 100000u);
  EXPECT_LE(in.served, in.newline_at + 16 * 100000u + 100000u + slack);
  const std::size_t served = in.served;
  EXPECT_EQ(src.next(line, err), line_status::end);
  EXPECT_EQ(in.served, served);
  default_line_source_limits() = saved;
}

}  // namespace
}  // namespace avatarmap::io_detail
