// *.pose.jsonl reader and writer (docs/file-formats.md).
#include "avatarmap/io/pose_file.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "avatarmap/core/rotation.hpp"
#include "common/pose_text.hpp"
#include "common/text_output.hpp"
#include "io/json_scan.hpp"
#include "io/jsonl_reader_core.hpp"

namespace avatarmap {

using io_detail::json_cursor;
using io_detail::line_status;

namespace {

constexpr std::string_view k_pose_format = "avatarmap.pose";
constexpr int k_supported_version = 1;

std::string quoted(std::string_view s) {
  std::string r = "\"";
  // Names in messages are cut short so that a huge bogus key cannot flood a log.
  if (s.size() > 64) {
    r.append(s.substr(0, 64));
    r += "...";
  } else {
    r.append(s);
  }
  r += '"';
  return r;
}

// Reads exactly `n` finite numbers in an array into `out`. `what` names the value.
bool parse_fixed_array(json_cursor& c, float* out, int n, const std::string& what,
                       const char* expected) {
  if (!c.eat('[')) return c.fail_expected("'[' starting " + what + " " + expected);
  for (int i = 0; i < n; ++i) {
    if (i > 0 && !c.eat(','))
      return c.fail(what + " has " + std::to_string(i) + " values (expected " + expected + ")");
    bool was_null = false;
    if (!c.parse_float(out[i], &was_null)) return false;
    if (!std::isfinite(out[i]))
      return c.fail(what + " has a " + (was_null ? "null" : "non-finite") + " value (expected " +
                    expected + ")");
  }
  if (!c.eat(']')) return c.fail(what + " has too many values (expected " + expected + ")");
  return true;
}

bool parse_finite(json_cursor& c, float& out, const std::string& what, const char* expected) {
  bool was_null = false;
  if (!c.parse_float(out, &was_null)) return false;
  if (!std::isfinite(out))
    return c.fail(what + " is " + (was_null ? "null" : "not finite") + " (expected " + expected +
                  ")");
  return true;
}

}  // namespace

// ---- reader --------------------------------------------------------------------------------

struct pose_reader::impl {
  io_detail::jsonl_reader_core core;
  pose_file_header header;
  long frame_index = 0;
  std::string scratch, scratch2;

  status parse_header(std::string_view line) {
    json_cursor c(line.data(), line.data() + line.size());
    bool format_ok = false;
    std::string problem;
    bool ok = io_detail::for_each_member(c, scratch, [&](std::string_view key) {
      if (key == "format") {
        std::string_view v;
        if (!c.parse_string(v, scratch2)) return false;
        if (v != k_pose_format) {
          problem =
              "wrong format " + quoted(v) + " (expected \"" + std::string(k_pose_format) + "\")";
          return false;
        }
        format_ok = true;
        return true;
      }
      if (key == "version") {
        double v = 0;
        if (!c.parse_double(v) || !(v >= 1) || v != std::floor(v)) {
          problem = "\"version\" must be a positive integer (expected 1)";
          return false;
        }
        if (v > k_supported_version) {
          problem = "version " + std::to_string(static_cast<long long>(std::min(v, 1e18))) +
                    " is newer than this reader supports (expected 1); update avatarmap";
          return false;
        }
        header.version = static_cast<int>(v);
        return true;
      }
      if (key == "fps") {
        double f = 0;
        bool was_null = false;
        if (!c.parse_double(f, &was_null) || was_null || !(f >= 0) || !std::isfinite(f)) {
          problem = "\"fps\" must be a number >= 0 (0 = not given)";
          return false;
        }
        header.fps = f;
        return true;
      }
      return c.skip_value();
    });
    if (ok) {
      c.skip_ws();
      if (!c.at_end())
        ok = c.fail("unexpected text after the header object (expected end of line)");
    }
    if (!ok) return core.error_status("bad header line: " + (problem.empty() ? c.error : problem));
    if (!format_ok) return core.error_status("bad header line (expected \"format\")");
    header.present = true;
    return {};
  }

  status after_open(const status& s, std::string_view header_line, bool has_header) {
    if (!s) return s;
    if (has_header) return parse_header(header_line);
    return {};
  }

  bool parse_bones(json_cursor& c, proxy_pose& out) {
    return io_detail::for_each_member(c, scratch2, [&](std::string_view name) {
      auto b = bone_from_name(name);
      if (!b)
        return c.fail("unknown bone " + quoted(name) +
                      " in \"bones\" (expected a VRM 1.0 humanoid bone name such as "
                      "\"hips\" or \"leftUpperArm\"; see docs/file-formats.md)");
      std::string what = "bone \"" + std::string(bone_name(*b)) + "\"";
      float v[4];
      if (!parse_fixed_array(c, v, 4, what, "4 finite numbers [x, y, z, w]")) return false;
      double n2 =
          double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2] + double(v[3]) * v[3];
      if (!(n2 > 1e-24))
        return c.fail(what +
                      " is a zero quaternion (expected a rotation [x, y, z, w] of "
                      "non-zero length)");
      // A quaternion already unit to float precision is kept bit for bit, so that a file
      // written by pose_writer reads back exactly.
      if (std::abs(n2 - 1.0) > 4.0 * std::numeric_limits<float>::epsilon()) {
        double inv = 1.0 / std::sqrt(n2);
        for (float& x : v) x = static_cast<float>(x * inv);
      }
      out[*b] = load_xyzw(v);
      return true;
    });
  }

  bool parse_blendshapes(json_cursor& c, proxy_pose& out) {
    return io_detail::for_each_member(c, scratch2, [&](std::string_view name) {
      auto s = blendshape_from_name(name);
      if (!s)
        return c.fail("unknown blendshape " + quoted(name) +
                      " in \"blendshapes\" (expected one of ARKit's 52 names such as "
                      "\"eyeBlinkLeft\" or \"jawOpen\"; see docs/file-formats.md)");
      return parse_finite(c, out.blendshapes[idx(*s)],
                          "blendshape \"" + std::string(blendshape_name(*s)) + "\"",
                          "a weight in [0, 1]");
    });
  }

  bool parse_weights(json_cursor& c, proxy_pose& out, bool confidence) {
    return io_detail::for_each_member(c, scratch2, [&](std::string_view name) {
      if (confidence) {
        auto b = bone_from_name(name);
        if (!b)
          return c.fail("unknown bone " + quoted(name) +
                        " in \"confidence\" (expected a VRM 1.0 humanoid bone name; see "
                        "docs/file-formats.md)");
        return parse_finite(c, out.confidence[idx(*b)],
                            "confidence of \"" + std::string(bone_name(*b)) + "\"",
                            "a number in [0, 1]");
      }
      auto e = expression_from_name(name);
      if (!e)
        return c.fail("unknown expression " + quoted(name) +
                      " (expected a VRM 1.0 expression name such as \"blink\", \"aa\" or "
                      "\"happy\", or one of avatarmap's browUpLeft/browUpRight/browDownLeft/"
                      "browDownRight; see docs/file-formats.md)");
      return parse_finite(c, out.expressions[idx(*e)],
                          "expression \"" + std::string(expression_name(*e)) + "\"",
                          "a weight in [0, 1]");
    });
  }

  read_result parse_frame(std::string_view line, proxy_pose& out) {
    out.set_rest();
    out.t = 0.0;
    long index = frame_index++;
    json_cursor c(line.data(), line.data() + line.size());
    bool has_t = false;
    bool ok = [&]() {
      if (!c.eat('{')) return c.fail_expected("'{' (each line must be one JSON object: a pose)");
      if (c.eat('}')) return true;
      for (;;) {
        std::string_view key;
        if (!c.parse_string(key, scratch)) return false;
        if (!c.eat(':')) return c.fail_expected("':'");
        if (key == "t") {
          bool was_null = false;
          if (!c.parse_double(out.t, &was_null)) return false;
          if (!std::isfinite(out.t))
            return c.fail("\"t\" is not a finite number (expected seconds)");
          has_t = true;
        } else if (key == "hips_position") {
          float v[3];
          if (!parse_fixed_array(c, v, 3, "\"hips_position\"", "3 finite numbers [x, y, z]"))
            return false;
          out.hips_position = glm::vec3(v[0], v[1], v[2]);
        } else if (key == "foot_contact") {
          float v[2];
          if (!parse_fixed_array(c, v, 2, "\"foot_contact\"",
                                 "2 finite numbers [left, right], 0 = free .. 1 = planted"))
            return false;
          // Outside [0, 1] means nothing more than its end: clamped, as the resampler does.
          for (int f = 0; f < 2; ++f) out.foot_contact[f] = std::clamp(v[f], 0.f, 1.f);
        } else if (key == "bones") {
          if (!parse_bones(c, out)) return false;
        } else if (key == "expressions") {
          if (!parse_weights(c, out, false)) return false;
        } else if (key == "blendshapes") {
          if (!parse_blendshapes(c, out)) return false;
        } else if (key == "confidence") {
          if (!parse_weights(c, out, true)) return false;
        } else if (key == "format" || key == "version") {
          return c.fail("header key \"" + std::string(key) +
                        "\" in a frame (a header is only allowed as the first line)");
        } else {
          if (!c.skip_value()) return false;
        }
        if (c.eat(',')) continue;
        if (c.eat('}')) return true;
        return c.fail_expected("',' or '}' after a member of the pose");
      }
    }();
    if (ok) {
      c.skip_ws();
      if (!c.at_end()) ok = c.fail("unexpected text after the pose object (expected end of line)");
    }
    if (!ok) {
      core.set_error(c.error);
      out.set_rest();
      return read_result::error;
    }
    if (!has_t) {
      if (header.fps > 0) {
        out.t = static_cast<double>(index) / header.fps;
        if (!std::isfinite(out.t)) {
          // A subnormal "fps" such as 1e-310 overflows index / fps.
          core.set_error(
              "the frame time (line index / the header's \"fps\") is not finite: \"fps\" is "
              "too small; give each frame a \"t\" or the real frame rate");
          out.set_rest();
          return read_result::error;
        }
      } else {
        core.set_error(
            "missing \"t\" (expected the frame time in seconds; it may only be "
            "omitted when the header gives \"fps\")");
        out.set_rest();
        return read_result::error;
      }
    }
    return read_result::frame;
  }
};

pose_reader::pose_reader() : impl_(std::make_unique<impl>()) {}
pose_reader::~pose_reader() = default;

status pose_reader::open(const std::string& path) {
  impl_ = std::make_unique<impl>();
  std::string_view header_line;
  bool has_header = false;
  status s = impl_->core.open_file(path, header_line, has_header);
  return impl_->after_open(s, header_line, has_header);
}

status pose_reader::open_memory(const char* data, std::size_t size, const std::string& name) {
  impl_ = std::make_unique<impl>();
  std::string_view header_line;
  bool has_header = false;
  status s = impl_->core.open_memory(data, size, name, header_line, has_header);
  return impl_->after_open(s, header_line, has_header);
}

const pose_file_header& pose_reader::header() const { return impl_->header; }

read_result pose_reader::next(proxy_pose& out) {
  std::string_view line;
  switch (impl_->core.next_line(line)) {
    case line_status::end:
      out.set_rest();
      return read_result::end;
    case line_status::error:
      out.set_rest();
      return read_result::error;
    case line_status::line:
      break;
  }
  return impl_->parse_frame(line, out);
}

const std::string& pose_reader::error() const { return impl_->core.error(); }
status_code pose_reader::error_code() const { return impl_->core.error_code(); }
long pose_reader::line() const { return impl_->core.line(); }

// ---- writer --------------------------------------------------------------------------------

struct pose_writer::impl {
  io_detail::text_output out;
  pose_write_options options;
};

pose_writer::pose_writer() : impl_(std::make_unique<impl>()) {}
pose_writer::~pose_writer() = default;

status pose_writer::open(const std::string& path, const pose_file_header& header,
                         const pose_write_options& options) {
  impl_->options = options;
  status s = impl_->out.open(path);
  if (!s) return s;
  auto& o = impl_->out;
  o.reserve(128);
  o.put("{\"format\":\"avatarmap.pose\",\"version\":1");
  if (header.fps > 0 && std::isfinite(header.fps)) {
    o.put(",\"fps\":");
    o.put_number(header.fps);
  }
  o.put("}\n");
  return {};
}

status pose_writer::write(const proxy_pose& pose) {
  auto& o = impl_->out;
  if (!o.is_open()) return status::error(o.path() + ": write() on a writer that is not open");
  if (!io_detail::put_pose_line(o, pose, impl_->options)) return o.error_status();
  return {};
}

status pose_writer::commit() { return impl_->out.commit(); }

}  // namespace avatarmap
