// The kinds of failure (status_code) of the shared internals every reader and writer goes
// through: the JSON reader (io when the file cannot be read, parse when its text is
// malformed or over a limit) and the atomic writer (io; invalid_argument for an empty path).
#include <gtest/gtest.h>

#include <string>

#include "common/atomic_file.hpp"
#include "common/json_limits.hpp"
#include "common/json_text.hpp"
#include "common/text_output.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

TEST(common_error_codes, json_file_missing_is_io_malformed_or_over_a_limit_is_parse) {
  test::temp_dir dir("common_codes");
  nlohmann::json doc;
  const std::string missing = dir.file("none.json");
  const status a = io_detail::read_json_file(missing, doc);
  EXPECT_EQ(a.code(), status_code::io) << a.message();
  EXPECT_EQ(a.message(), missing + ": cannot read the file");

  const std::string broken = dir.file("broken.json");
  test::write_text(broken, "{\"a\": [1, 2,}");
  const status b = io_detail::read_json_file(broken, doc);
  EXPECT_EQ(b.code(), status_code::parse) << b.message();
  EXPECT_NE(b.message().find("line 1"), std::string::npos) << b.message();

  const std::string deep = dir.file("deep.json");
  test::write_text(deep, std::string(200, '[') + std::string(200, ']'));
  const status c = io_detail::read_json_file(deep, doc);
  EXPECT_EQ(c.code(), status_code::parse) << c.message();

  io_detail::json_limits small;
  small.max_bytes = 4;
  const std::string big = dir.file("big.json");
  test::write_text(big, "[1, 2, 3]");
  const status d = io_detail::read_json_file(big, doc, small);
  EXPECT_EQ(d.code(), status_code::parse) << d.message();
  EXPECT_EQ(io_detail::check_json_limits("[1, 2, 3]", "text", small).code(), status_code::parse);
}

TEST(common_error_codes, atomic_writer_failures_are_io_and_an_empty_path_invalid) {
  test::temp_dir dir("common_codes");
  io_detail::atomic_file f;
  const status a = f.open(dir.file("no-such-folder/x.bin"));
  EXPECT_EQ(a.code(), status_code::io) << a.message();
  const status b = f.open(dir.path().string());  // a folder as the target
  EXPECT_EQ(b.code(), status_code::io) << b.message();
  const status c = f.open("");
  EXPECT_EQ(c.code(), status_code::invalid_argument) << c.message();
  io_detail::text_output t;
  const status d = t.open(dir.file("no-such-folder/x.txt"));
  EXPECT_EQ(d.code(), status_code::io) << d.message();
  const status e = io_detail::write_file_atomically(dir.file("no-such-folder/y.txt"), "y");
  EXPECT_EQ(e.code(), status_code::io) << e.message();
}

}  // namespace
}  // namespace avatarmap
