// Known-answer tests of the OSC encoder: the expected bytes are worked out by hand from the OSC
// 1.0 rules (big-endian int32/float32, strings NUL-terminated and padded to 4, ',' type tags,
// "#bundle" + 8-byte time tag + size-prefixed elements), not produced by the code under test.
#include "avatarmap/stream/osc_writer.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace avatarmap {
namespace {

using bytes = std::vector<std::uint8_t>;

bytes written(const osc_writer& w) { return bytes(w.data(), w.data() + w.size()); }

TEST(osc_writer, message_with_one_float) {
  std::array<std::uint8_t, 64> buf{};
  osc_writer w(buf.data(), buf.size());
  w.begin_message("/VMC/Ext/T", "f");
  w.add_float32(1.5f);  // 0x3FC00000
  w.end_message();
  ASSERT_TRUE(w.complete());
  const bytes want = {'/',  'V',  'M',  'C', '/', 'E', 'x', 't', '/', 'T', 0, 0,  // 10 + 2 NUL
                      ',',  'f',  0,    0,                                        // 2 + 2 NUL
                      0x3F, 0xC0, 0x00, 0x00};
  EXPECT_EQ(written(w), want);
}

TEST(osc_writer, int_and_string_arguments) {
  std::array<std::uint8_t, 64> buf{};
  osc_writer w(buf.data(), buf.size());
  w.begin_message("/a", "isf");
  w.add_int32(-2);        // FF FF FF FE
  w.add_string("root");   // 4 characters: 4 NUL bytes of padding
  w.add_float32(-0.25f);  // 0xBE800000
  w.end_message();
  ASSERT_TRUE(w.complete());
  const bytes want = {'/',  'a',  0,    0,                 // "/a" + 2 NUL
                      ',',  'i',  's',  'f',  0, 0, 0, 0,  // 4 + 4 NUL
                      0xFF, 0xFF, 0xFF, 0xFE,              // -2
                      'r',  'o',  'o',  't',  0, 0, 0, 0,  // "root" + 4 NUL
                      0xBE, 0x80, 0x00, 0x00};             // -0.25
  EXPECT_EQ(written(w), want);
}

TEST(osc_writer, message_without_arguments_has_a_lone_comma) {
  std::array<std::uint8_t, 64> buf{};
  osc_writer w(buf.data(), buf.size());
  w.begin_message("/VMC/Ext/Blend/Apply", "");  // 20 characters: 4 NUL bytes
  w.end_message();
  ASSERT_TRUE(w.complete());
  bytes want;
  for (char c : std::string("/VMC/Ext/Blend/Apply")) want.push_back(static_cast<std::uint8_t>(c));
  want.insert(want.end(), {0, 0, 0, 0, ',', 0, 0, 0});
  EXPECT_EQ(written(w), want);
}

TEST(osc_writer, bundle_of_two_messages) {
  std::array<std::uint8_t, 128> buf{};
  osc_writer w(buf.data(), buf.size());
  w.begin_bundle();  // time tag 1: immediately
  w.begin_message("/VMC/Ext/OK", "i");
  w.add_int32(1);
  w.end_message();
  w.begin_message("/x", "");
  w.end_message();
  w.end_bundle();
  ASSERT_TRUE(w.complete());
  const bytes want = {'#', 'b', 'u', 'n', 'd', 'l', 'e', 0,                      // "#bundle"
                      0,   0,   0,   0,   0,   0,   0,   1,                      // time tag 1
                      0,   0,   0,   20,                                         // element size
                      '/', 'V', 'M', 'C', '/', 'E', 'x', 't', '/', 'O', 'K', 0,  // 11 + 1 NUL
                      ',', 'i', 0,   0,   0,   0,   0,   1,                      // ",i" 1
                      0,   0,   0,   8,                                          // element size
                      '/', 'x', 0,   0,   ',', 0,   0,   0};                     // "/x" ","
  EXPECT_EQ(written(w), want);
  EXPECT_EQ(w.size(), 52u);
}

TEST(osc_writer, explicit_time_tag_is_big_endian) {
  std::array<std::uint8_t, 32> buf{};
  osc_writer w(buf.data(), buf.size());
  w.begin_bundle(0x0102030405060708ull);
  w.end_bundle();
  ASSERT_TRUE(w.complete());
  const bytes want = {'#', 'b', 'u', 'n', 'd', 'l', 'e', 0, 1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(written(w), want);
}

TEST(osc_writer, string_padding_for_every_length_mod_4) {
  // 1 to 4 NUL bytes: "abc" -> 4, "abcd" -> 8, "abcde" -> 8, "ab" -> 4.
  const std::pair<const char*, std::size_t> cases[] = {
      {"ab", 4}, {"abc", 4}, {"abcd", 8}, {"abcde", 8}, {"", 4}};
  for (const auto& [s, size] : cases) {
    std::array<std::uint8_t, 64> buf{};
    buf.fill(0xAA);
    osc_writer w(buf.data(), buf.size());
    w.begin_message("/s", "s");
    w.add_string(s);
    w.end_message();
    ASSERT_TRUE(w.complete()) << s;
    EXPECT_EQ(w.size(), 4u + 4u + size) << s;
    for (std::size_t i = 8 + std::string(s).size(); i < w.size(); ++i)
      EXPECT_EQ(buf[i], 0) << "padding of '" << s << "' at " << i;
  }
}

TEST(osc_writer, misuse_fails_and_stays_failed) {
  std::array<std::uint8_t, 64> buf{};
  osc_writer w(buf.data(), buf.size());
  auto fresh = [&] { w.clear(); };

  fresh();
  w.begin_message("VMC", "");  // no leading '/'
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_message("/a", "d");  // a type the writer does not write
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_message("/a", "f");
  w.add_int32(1);  // wrong type
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_message("/a", "ff");
  w.add_float32(1.f);
  w.end_message();  // one argument missing
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_message("/a", "");
  w.add_float32(1.f);  // one too many
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_message("/a", "s");
  w.add_string(std::string_view("a\0b", 3));  // NUL inside a string
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_message("/a", "");
  w.end_message();
  w.begin_message("/b", "");  // two messages outside a bundle
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_bundle();
  w.begin_bundle();  // nesting
  EXPECT_FALSE(w.ok());
  fresh();
  w.begin_bundle();
  w.begin_message("/a", "");
  w.end_bundle();  // message still open
  EXPECT_FALSE(w.ok());
  fresh();
  w.add_float32(1.f);  // no message
  EXPECT_FALSE(w.ok());
  // Once failed, nothing is written and the packet is not complete.
  const std::size_t size = w.size();
  w.begin_message("/ok", "");
  w.end_message();
  EXPECT_EQ(w.size(), size);
  EXPECT_FALSE(w.complete());
  // clear() starts over.
  fresh();
  w.begin_message("/ok", "");
  w.end_message();
  EXPECT_TRUE(w.complete());
}

TEST(osc_writer, open_packets_are_not_complete) {
  std::array<std::uint8_t, 64> buf{};
  osc_writer w(buf.data(), buf.size());
  EXPECT_FALSE(w.complete());  // nothing written
  w.begin_bundle();
  EXPECT_FALSE(w.complete());
  w.begin_message("/a", "");
  EXPECT_FALSE(w.complete());
  w.end_message();
  EXPECT_FALSE(w.complete());
  w.end_bundle();
  EXPECT_TRUE(w.complete());
}

TEST(osc_writer, never_writes_past_its_capacity) {
  // The bundle above takes 52 bytes; every smaller buffer must fail without touching the
  // bytes past its end.
  for (std::size_t cap = 0; cap < 52; ++cap) {
    std::array<std::uint8_t, 80> buf{};
    buf.fill(0xAA);
    osc_writer w(buf.data(), cap);
    w.begin_bundle();
    w.begin_message("/VMC/Ext/OK", "i");
    w.add_int32(1);
    w.end_message();
    w.begin_message("/x", "");
    w.end_message();
    w.end_bundle();
    EXPECT_FALSE(w.ok()) << cap;
    EXPECT_LE(w.size(), cap);
    for (std::size_t i = cap; i < buf.size(); ++i) ASSERT_EQ(buf[i], 0xAA) << cap << " " << i;
  }
  std::array<std::uint8_t, 52> exact{};
  osc_writer w(exact.data(), exact.size());
  w.begin_bundle();
  w.begin_message("/VMC/Ext/OK", "i");
  w.add_int32(1);
  w.end_message();
  w.begin_message("/x", "");
  w.end_message();
  w.end_bundle();
  EXPECT_TRUE(w.complete());
}

}  // namespace
}  // namespace avatarmap
