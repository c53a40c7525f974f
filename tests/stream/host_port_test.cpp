#include "avatarmap/stream/host_port.hpp"

#include <gtest/gtest.h>

#include <string>

namespace avatarmap {
namespace {

TEST(host_port, accepted_forms) {
  struct row {
    const char* text;
    const char* host;
    int port;
  };
  const row rows[] = {
      {"127.0.0.1:39540", "127.0.0.1", 39540},
      {"127.0.0.1", "127.0.0.1", 39539},
      {"localhost", "localhost", 39539},
      {"my-pc.local:9000", "my-pc.local", 9000},
      {"[::1]:39540", "::1", 39540},
      {"[::1]", "::1", 39539},
      {"::1", "::1", 39539},
      {"fe80::1:2", "fe80::1:2", 39539},  // several colons: an IPv6 address, no port
      {"h:1", "h", 1},
      {"h:65535", "h", 65535},
  };
  for (const row& r : rows) {
    host_port hp;
    const status st = parse_host_port(r.text, 39539, hp);
    ASSERT_TRUE(st.ok()) << r.text << ": " << st.message();
    EXPECT_EQ(hp.host, r.host) << r.text;
    EXPECT_EQ(hp.port, r.port) << r.text;
  }
}

TEST(host_port, malformed_forms_are_refused_with_the_text_quoted) {
  const char* bad[] = {"",           ":39539",   "host:",       "host:abc",   "host:0",
                       "host:65536", "host:-1",  "host:123456", "[::1",       "[::1]x",
                       "[]:5",       "[::1]:",   "[host]:5",    "ho st",      "host:12:34",
                       "a]b",        "host:\t1", "host:1 ",     "[::1]:99999"};
  for (const char* text : bad) {
    host_port hp;
    hp.host = "stale";
    const status st = parse_host_port(text, 39539, hp);
    EXPECT_FALSE(st.ok()) << "accepted '" << text << "'";
    EXPECT_NE(st.message().find("'" + std::string(text) + "'"), std::string::npos) << st.message();
    EXPECT_NE(st.message().find("HOST:PORT"), std::string::npos) << st.message();
    EXPECT_TRUE(hp.host.empty());
  }
  host_port hp;
  EXPECT_FALSE(parse_host_port(std::string("a\0b", 3), 39539, hp).ok());
  EXPECT_FALSE(parse_host_port("host", 0, hp).ok());  // a bad default port
}

}  // namespace
}  // namespace avatarmap
