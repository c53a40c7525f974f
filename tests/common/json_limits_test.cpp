// The depth/size guard put in front of recursive JSON parsers.
#include "common/json_limits.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

namespace avatarmap::io_detail {
namespace {

std::string nested_arrays(int depth) {
  return std::string(static_cast<std::size_t>(depth), '[') +
         std::string(static_cast<std::size_t>(depth), ']');
}

TEST(json_limits, depth_exactly_at_the_limit_passes_one_more_fails) {
  json_limits limits;
  limits.max_depth = 5;
  EXPECT_TRUE(check_json_limits(nested_arrays(5), "a.json", limits).ok());
  const status s = check_json_limits(nested_arrays(6), "a.json", limits);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("a.json"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("deeper than 5 levels"), std::string::npos) << s.message();
  // The sixth '[' is at byte 5.
  EXPECT_NE(s.message().find("at byte 5"), std::string::npos) << s.message();
}

TEST(json_limits, objects_and_arrays_both_count) {
  json_limits limits;
  limits.max_depth = 2;
  EXPECT_TRUE(check_json_limits(R"({"a":[1,2],"b":{"c":3}})", "x", limits).ok());
  EXPECT_FALSE(check_json_limits(R"({"a":[{"c":3}]})", "x", limits).ok());
  // Siblings do not add up: depth returns after each closer.
  EXPECT_TRUE(check_json_limits(R"([[1],[2],[3],{"a":1}])", "x", limits).ok());
}

TEST(json_limits, brackets_inside_strings_do_not_count) {
  json_limits limits;
  limits.max_depth = 1;
  EXPECT_TRUE(check_json_limits(R"({"name":"[[[[{{{{"})", "x", limits).ok());
  // An escaped quote does not end the string, so the brackets after it are still inside it.
  EXPECT_TRUE(check_json_limits(R"({"name":"a\"[[[[{{"})", "x", limits).ok());
  // An escaped backslash before the quote does end the string: the '[' after it counts.
  EXPECT_FALSE(check_json_limits(R"({"name":"a\\", "b":[1]})", "x", limits).ok());
  EXPECT_TRUE(check_json_limits(R"({"name":"a\\", "b":1})", "x", limits).ok());
}

TEST(json_limits, default_limit_is_128) {
  EXPECT_TRUE(check_json_limits(nested_arrays(128), "x").ok());
  EXPECT_FALSE(check_json_limits(nested_arrays(129), "x").ok());
}

TEST(json_limits, twenty_thousand_levels_fail_fast) {
  const std::string deep = "{\"extras\":" + std::string(20000, '[') + std::string(20000, ']') + "}";
  const auto t0 = std::chrono::steady_clock::now();
  const status s = check_json_limits(deep, "deep.gltf");
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("deep.gltf"), std::string::npos);
  // It stops at the first level past the limit: the object is level 1, so the 128th '['
  // (byte 10 + 127) is level 129.
  EXPECT_NE(s.message().find("at byte 137"), std::string::npos) << s.message();
  EXPECT_LT(ms, 50.0);
}

TEST(json_limits, size_limit) {
  json_limits limits;
  limits.max_bytes = 10;
  EXPECT_TRUE(check_json_limits("[1,2,3,4]", "x", limits).ok());   // 9 bytes
  EXPECT_TRUE(check_json_limits("[1,2,3,45]", "x", limits).ok());  // 10 bytes: at the limit
  const status s = check_json_limits("[1,2,3,456]", "big.json", limits);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("big.json"), std::string::npos);
  EXPECT_NE(s.message().find("11 bytes"), std::string::npos) << s.message();
}

TEST(json_limits, stray_closers_cannot_hide_openers) {
  json_limits limits;
  limits.max_depth = 2;
  // Without clamping, "]]]]" would drive the depth to -4 and let 6 levels through.
  EXPECT_FALSE(check_json_limits("]]]][[[[[[", "x", limits).ok());
}

}  // namespace
}  // namespace avatarmap::io_detail
