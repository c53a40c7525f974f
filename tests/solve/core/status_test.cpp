// status (include/avatarmap/core/status.hpp): every named constructor carries its code and
// message, the generic error() is invalid_argument, and re-tagging keeps the code.
#include "avatarmap/core/status.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace avatarmap {
namespace {

TEST(status, ok_has_code_ok_and_no_message) {
  const status s;
  EXPECT_TRUE(s.ok());
  EXPECT_TRUE(static_cast<bool>(s));
  EXPECT_EQ(s.code(), status_code::ok);
  EXPECT_EQ(s.message(), "");
  EXPECT_FALSE(s.is_out_of_memory());
}

TEST(status, each_named_constructor_carries_its_code_and_message) {
  struct named {
    status s;
    status_code code;
  };
  const named cases[] = {
      {status::error("m"), status_code::invalid_argument},
      {status::invalid_argument("m"), status_code::invalid_argument},
      {status::io_error("m"), status_code::io},
      {status::parse_error("m"), status_code::parse},
      {status::unsupported("m"), status_code::unsupported},
      {status::out_of_memory("m"), status_code::out_of_memory},
      {status::internal("m"), status_code::internal},
  };
  for (const named& c : cases) {
    EXPECT_FALSE(c.s.ok()) << status_code_name(c.code);
    EXPECT_EQ(c.s.code(), c.code) << status_code_name(c.code);
    EXPECT_EQ(c.s.message(), "m");
    EXPECT_EQ(c.s.is_out_of_memory(), c.code == status_code::out_of_memory);
  }
}

TEST(status, failure_takes_any_code_and_ok_as_internal) {
  for (status_code c :
       {status_code::invalid_argument, status_code::io, status_code::parse,
        status_code::unsupported, status_code::out_of_memory, status_code::internal})
    EXPECT_EQ(status::failure(c, "m").code(), c) << status_code_name(c);
  // A failure must have a kind: "ok" with a message would read as success.
  const status s = status::failure(status_code::ok, "m");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), status_code::internal);
}

TEST(status, prefixed_and_with_message_keep_the_code) {
  const status parse = status::parse_error("line 3: bad");
  const status p = parse.prefixed("a.jsonl:");
  EXPECT_EQ(p.code(), status_code::parse);
  EXPECT_EQ(p.message(), "a.jsonl:line 3: bad");
  const status w = status::io_error("x").with_message("y (hint)");
  EXPECT_EQ(w.code(), status_code::io);
  EXPECT_EQ(w.message(), "y (hint)");
  // Ok stays ok, without a message.
  EXPECT_TRUE(status{}.prefixed("x: ").ok());
  EXPECT_EQ(status{}.prefixed("x: ").message(), "");
  EXPECT_TRUE(status{}.with_message("x").ok());
}

TEST(status, code_names_are_distinct) {
  std::set<std::string> names;
  for (status_code c :
       {status_code::ok, status_code::invalid_argument, status_code::io, status_code::parse,
        status_code::unsupported, status_code::out_of_memory, status_code::internal})
    names.insert(status_code_name(c));
  EXPECT_EQ(names.size(), 7u);
}

}  // namespace
}  // namespace avatarmap
