// *.landmarks.jsonl reader and writer. The frame parser is a hand-written scanner
// (io/json_scan.hpp) with std::from_chars numbers; see docs/file-formats.md for the rules.
#include "avatarmap/io/landmark_file.hpp"

#include <cmath>
#include <cstring>
#include <string_view>

#include "common/text_output.hpp"
#include "io/json_scan.hpp"
#include "io/jsonl_reader_core.hpp"

#if AVATARMAP_HAVE_SIMDJSON
#include <simdjson.h>

#include <vector>
#endif

namespace avatarmap {

using io_detail::json_cursor;
using io_detail::line_status;

namespace {

constexpr std::string_view k_landmark_format = "avatarmap.landmarks";
constexpr int k_supported_version = 2;

// Part from its JSON key, or -1.
int part_from_key(std::string_view key) {
  switch (key.size()) {
    case 4:
      if (key == "pose") return static_cast<int>(frame_part::pose);
      if (key == "face") return static_cast<int>(frame_part::face);
      break;
    case 9:
      if (key == "left_hand") return static_cast<int>(frame_part::left_hand);
      break;
    case 10:
      if (key == "pose_world") return static_cast<int>(frame_part::pose_world);
      if (key == "right_hand") return static_cast<int>(frame_part::right_hand);
      break;
    case 15:
      if (key == "left_hand_world") return static_cast<int>(frame_part::left_hand_world);
      break;
    case 16:
      if (key == "right_hand_world") return static_cast<int>(frame_part::right_hand_world);
      break;
    default:
      break;
  }
  return -1;
}

// Points of part `p` (const or not) and their capacity.
template <class Frame>
auto part_storage(Frame& f, frame_part p, int& out_capacity) -> decltype(f.pose.data()) {
  out_capacity = frame_part_capacity(p);
  return f.points(p);
}

// Prefixes a cursor error with where in the frame it happened.
struct frame_context {
  std::string_view key;
  int point = -1;
};

// Reads one point [x, y, z (, visibility (, presence))] into `out`.
bool parse_point(json_cursor& c, landmark& out) {
  if (!c.eat('[')) return c.fail_expected("'[' starting a point [x, y, z, visibility, presence]");
  float v[5];
  int n = 0;
  if (!c.eat(']')) {
    for (;;) {
      if (n == 5)
        return c.fail("more than 5 values (expected 3 to 5: x, y, z, visibility, presence)");
      if (!c.parse_float(v[n])) return false;
      ++n;
      if (c.eat(',')) continue;
      if (c.eat(']')) break;
      return c.fail_expected("',' or ']' in a point");
    }
  }
  if (n < 3) {
    return c.fail(std::to_string(n) + " values (expected 3 to 5: x, y, z, visibility, presence)");
  }
  out.x = v[0];
  out.y = v[1];
  out.z = v[2];
  out.visibility = n > 3 ? v[3] : 1.f;
  out.presence = n > 4 ? v[4] : 1.f;
  return true;
}

// Points in the compact form the writers produce, "[x,y,z],[x,y,z,v,p],..." without white
// space and with plain decimals (json_number.hpp), read from c.p (a point's '[') into
// storage[count...] (`overflow` beyond `capacity`). Returns true after consuming the
// array's closing ']'; false, with c.p at the start of the first point it could not read
// this way (and `count` its index), when the text differs in any way: parse_point then
// reads that point, so the values and the error messages do not depend on which path ran.
//
// The delimiters (',' ']' '}') of 64 bytes at a time are found first, as a bit mask; each
// value then lies between two of them. The position of the next value so depends on one
// bit operation, not on the digits before it, and the processor reads several numbers at
// once.
bool read_compact_points(json_cursor& c, landmark* storage, int capacity, landmark& overflow,
                         int& count) {
#if AVATARMAP_JSON_SSE2
  using io_detail::number_detail::delimiter_mask64;
  using io_detail::number_detail::lowest_bit;
  using io_detail::number_detail::plain_decimal;
  // Blocks of 64 bytes are read while 64 bytes are left on the line; plain_decimal reads
  // the 16 bytes before a token's end, so the first point must start 16 bytes into it.
  const char* point = c.p;
  if (point - c.begin < io_detail::k_float_scan_lookback || c.end - point < 64 ||
      !io_detail::json_vector_path())
    return false;
  const char* block = point;
  std::uint64_t bits = delimiter_mask64(block);  // delimiters in [block, block + 64) not used yet
  // The next delimiter, or nullptr near the end of the line.
  auto next_delimiter = [&]() -> const char* {
    while (bits == 0) {
      block += 64;
      if (c.end - block < 64) return nullptr;
      bits = delimiter_mask64(block);
    }
    const char* d = block + lowest_bit(bits);
    bits &= bits - 1;
    return d;
  };
  while (point < c.end && *point == '[') {
    float v[5];
    int n = 0;
    const char* value = point + 1;
    const char* d = nullptr;
    bool closed = false;
    for (;;) {
      d = next_delimiter();
      if (d == nullptr || d == value || d - value > 15 || !plain_decimal(value, d, v[n])) break;
      ++n;
      if (*d == ']') {
        closed = true;
        break;
      }
      if (*d != ',' || n == 5) break;
      value = d + 1;
    }
    if (!closed || n < 3) break;
    // The point is good; it counts when ',' or the array's ']' follows at once.
    const char* after = next_delimiter();
    if (after != d + 1 || *after == '}') break;
    landmark& out = count < capacity ? storage[count] : overflow;
    out.x = v[0];
    out.y = v[1];
    out.z = v[2];
    out.visibility = n > 3 ? v[3] : 1.f;
    out.presence = n > 4 ? v[4] : 1.f;
    ++count;
    if (*after == ']') {
      c.p = after + 1;
      return true;
    }
    point = after + 1;
  }
  c.p = point;
#else
  (void)c;
  (void)storage;
  (void)capacity;
  (void)overflow;
  (void)count;
#endif
  return false;
}

bool parse_points(json_cursor& c, landmark* storage, int capacity, frame_context& ctx,
                  int& out_count) {
  out_count = 0;
  ctx.point = -1;
  if (!c.eat('[')) return c.fail_expected("'[' starting an array of points");
  if (c.eat(']')) return true;
  landmark overflow;
  for (;;) {
    if (read_compact_points(c, storage, capacity, overflow, out_count)) break;
    ctx.point = out_count;
    if (!parse_point(c, out_count < capacity ? storage[out_count] : overflow)) return false;
    ++out_count;
    if (c.eat(',')) continue;
    if (c.eat(']')) break;
    return c.fail_expected("',' or ']' after a point");
  }
  ctx.point = -1;
  return true;
}

std::string context_message(const frame_context& ctx, const std::string& error) {
  if (ctx.key.empty()) return error;
  std::string m = "in \"";
  m += ctx.key;
  m += '"';
  if (ctx.point >= 0) {
    m += " point ";
    m += std::to_string(ctx.point);
  }
  m += ": ";
  m += error;
  return m;
}

}  // namespace

// ---- reader --------------------------------------------------------------------------------

struct landmark_reader::impl {
  io_detail::jsonl_reader_core core;
  landmark_file_header header;
  long frame_index = 0;  // frame lines seen (good or bad), for t = index / fps
  int person = -1;       // set_person: only this person's lines (-1: every line)
  std::string scratch;
#if AVATARMAP_HAVE_SIMDJSON
  simdjson::ondemand::parser simd_parser;
  std::vector<char> padded;  // the line and simdjson's padding after it

  // The frame with simdjson's on-demand API. False, with `out` in any state, when the line
  // must go to the own scanner instead: whatever simdjson rejects, and whatever the scanner
  // reads differently or reports (unknown and header keys, null values, counts out of
  // range, numbers outside the normal float range or halfway between two floats).
  bool parse_frame_simdjson(std::string_view line, landmark_frame& out, bool& has_t) {
    namespace od = simdjson::ondemand;
    // Room for twice the longest line so far: lines of a recording differ in length, and
    // growing by the exact amount would allocate again and again.
    if (line.size() > simd_parser.capacity() &&
        simd_parser.allocate(2 * line.size()) != simdjson::SUCCESS)
      return false;
    if (padded.size() < line.size() + simdjson::SIMDJSON_PADDING)
      padded.resize(2 * line.size() + simdjson::SIMDJSON_PADDING);
    std::memcpy(padded.data(), line.data(), line.size());
    od::document doc;
    od::object object;
    if (simd_parser.iterate(padded.data(), line.size(), padded.size()).get(doc) ||
        doc.get_object().get(object))
      return false;
    for (auto member : object) {
      std::string_view key;
      od::value value;
      if (member.unescaped_key().get(key) || member.value().get(value)) return false;
      if (key == "t") {
        if (value.get_double().get(out.t) || !std::isfinite(out.t)) return false;
        has_t = true;
        continue;
      }
      if (key == "person") {
        std::int64_t id = 0;
        if (value.get_int64().get(id) || id < 0 || id > k_max_person_id) return false;
        out.person = static_cast<int>(id);
        continue;
      }
      const int part = part_from_key(key);
      if (part < 0) return false;
      const auto fp = static_cast<frame_part>(part);
      bool is_null = false;
      if (value.is_null().get(is_null)) return false;
      if (is_null) {
        out.set(fp, false);
        continue;
      }
      int capacity = 0;
      landmark* storage = part_storage(out, fp, capacity);
      int count = 0;
      od::array points;
      if (value.get_array().get(points)) return false;
      for (auto item : points) {
        od::array point;
        if (item.get_array().get(point) || count == capacity) return false;
        float v[5];
        int n = 0;
        for (auto x : point) {
          double d = 0.0;
          if (n == 5 || x.get_double().get(d)) return false;
          // The correctly rounded double rounds to the correctly rounded float unless it
          // lies halfway between two floats; subnormal and out-of-range results are the
          // scanner's.
          std::uint64_t b;
          std::memcpy(&b, &d, sizeof b);
          if ((d != 0.0 &&
               !(std::abs(d) >= 1.1754943508222875e-38 && std::abs(d) <= 3.4028234663852886e38)) ||
              (b & 0x1fffffffu) == 0x10000000u)
            return false;
          v[n++] = static_cast<float>(d);
        }
        if (n < 3) return false;
        landmark& p = storage[count++];
        p.x = v[0];
        p.y = v[1];
        p.z = v[2];
        p.visibility = n > 3 ? v[3] : 1.f;
        p.presence = n > 4 ? v[4] : 1.f;
      }
      if (fp == frame_part::face) {
        if (count != k_face_mesh_count && count != k_face_mesh_iris_count) return false;
        out.face_count = count;
      } else if (count != capacity) {
        return false;
      }
      out.set(fp, true);
    }
    // Nothing after the object (white space is no token).
    return doc.current_location().error() == simdjson::OUT_OF_BOUNDS;
  }
#endif

  status parse_header(std::string_view line) {
    json_cursor c(line.data(), line.data() + line.size());
    bool format_ok = false;
    std::string problem;
    bool ok = io_detail::for_each_member(c, scratch, [&](std::string_view key) {
      if (key == "format") {
        std::string_view v;
        std::string s2;
        if (!c.parse_string(v, s2)) return false;
        if (v != k_landmark_format) {
          problem = "wrong format \"" + std::string(v) + "\" (expected \"" +
                    std::string(k_landmark_format) + "\")";
          return false;
        }
        format_ok = true;
        return true;
      }
      if (key == "version") {
        double v = 0;
        if (!c.parse_double(v) || !(v >= 1) || v != std::floor(v)) {
          problem = "\"version\" must be a positive integer (expected 1 or 2)";
          return false;
        }
        if (v > k_supported_version) {
          problem = "version " + std::to_string(static_cast<long long>(std::min(v, 1e18))) +
                    " is newer than this reader supports (expected 1 or 2); update avatarmap";
          return false;
        }
        header.version = static_cast<int>(v);
        return true;
      }
      if (key == "image_size") {
        double w = 0, h = 0;
        if (!c.eat('[') || !c.parse_double(w) || !c.eat(',') || !c.parse_double(h) || !c.eat(']') ||
            !(w >= 1 && w <= 1e6 && h >= 1 && h <= 1e6) || w != std::floor(w) ||
            h != std::floor(h)) {
          problem = "\"image_size\" must be [width, height] in pixels (positive integers)";
          return false;
        }
        header.image_width = static_cast<int>(w);
        header.image_height = static_cast<int>(h);
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
    if (!ok) {
      return core.error_status("bad header line: " + (problem.empty() ? c.error : problem));
    }
    if (!format_ok) return core.error_status("bad header line (expected \"format\")");
    header.present = true;
    return {};
  }

  status after_open(const status& s, std::string_view header_line, bool has_header) {
    if (!s) return s;
    if (has_header) return parse_header(header_line);
    return {};
  }

  read_result parse_frame(std::string_view line, landmark_frame& out) {
    out.clear();
    long index = frame_index++;
    json_cursor c(line.data(), line.data() + line.size());
    frame_context ctx;
    bool has_t = false;
#if AVATARMAP_HAVE_SIMDJSON
    const bool simd_ok = io_detail::json_vector_path() && parse_frame_simdjson(line, out, has_t);
    if (!simd_ok) {
      out.clear();
      has_t = false;
    }
#else
    const bool simd_ok = false;
#endif
    bool ok = simd_ok || [&]() {
      if (!c.eat('{')) return c.fail_expected("'{' (each line must be one JSON object: a frame)");
      if (c.eat('}')) return true;
      for (;;) {
        std::string_view key;
        if (!c.parse_string(key, scratch)) return false;
        if (!c.eat(':')) return c.fail_expected("':'");
        int part = part_from_key(key);
        if (part >= 0) {
          ctx.key = frame_part_key(static_cast<frame_part>(part));
          auto fp = static_cast<frame_part>(part);
          if (c.eat_null()) {
            out.set(fp, false);  // null part = not seen, like an absent key
          } else {
            int capacity = 0;
            landmark* storage = part_storage(out, fp, capacity);
            int count = 0;
            if (!parse_points(c, storage, capacity, ctx, count)) return false;
            if (fp == frame_part::face) {
              if (count != k_face_mesh_count && count != k_face_mesh_iris_count)
                return c.fail("has " + std::to_string(count) + " points (expected 468 or 478)");
              out.face_count = count;
            } else if (count != capacity) {
              return c.fail("has " + std::to_string(count) + " points (expected " +
                            std::to_string(capacity) + ")");
            }
            out.set(fp, true);
          }
          ctx.key = {};
        } else if (key == "t") {
          ctx.key = "t";
          bool was_null = false;
          if (!c.parse_double(out.t, &was_null)) return false;
          if (!std::isfinite(out.t)) return c.fail("not a finite number (expected seconds)");
          has_t = true;
          ctx.key = {};
        } else if (key == "person") {
          ctx.key = "person";
          double id = 0;
          bool was_null = false;
          if (!c.parse_double(id, &was_null)) return false;
          if (was_null || !(id >= 0 && id <= k_max_person_id) || id != std::floor(id))
            return c.fail("must be a person id, an integer in [0, " +
                          std::to_string(k_max_person_id) + "]");
          out.person = static_cast<int>(id);
          ctx.key = {};
        } else if (key == "format" || key == "version") {
          return c.fail("header key \"" + std::string(key) +
                        "\" in a frame (a header is only allowed as the first line)");
        } else {
          if (!c.skip_value()) return false;
        }
        if (c.eat(',')) continue;
        if (c.eat('}')) return true;
        return c.fail_expected("',' or '}' after a member of the frame");
      }
    }();
    if (ok && !simd_ok) {
      c.skip_ws();
      if (!c.at_end()) ok = c.fail("unexpected text after the frame object (expected end of line)");
    }
    if (ok && !has_t) {
      if (header.version >= 2) {
        // Several people share a time: a line's place does not tell it.
        core.set_error(
            "missing \"t\" (a version-2 file, several people, gives every line its time)");
        out.clear();
        return read_result::error;
      }
      if (header.fps > 0) {
        out.t = static_cast<double>(index) / header.fps;
        if (!std::isfinite(out.t)) {
          // A subnormal "fps" such as 1e-310 overflows index / fps.
          core.set_error(
              "the frame time (line index / the header's \"fps\") is not finite: \"fps\" is "
              "too small; give each frame a \"t\" or the real frame rate");
          out.clear();
          return read_result::error;
        }
      } else {
        core.set_error(
            "missing \"t\" (expected the frame time in seconds; it may only be "
            "omitted when the header gives \"fps\")");
        out.clear();
        return read_result::error;
      }
    }
    if (!ok) {
      core.set_error(context_message(ctx, c.error));
      out.clear();
      return read_result::error;
    }
    return read_result::frame;
  }
};

landmark_reader::landmark_reader() : impl_(std::make_unique<impl>()) {}
landmark_reader::~landmark_reader() = default;

status landmark_reader::open(const std::string& path) {
  impl_ = std::make_unique<impl>();
  std::string_view header_line;
  bool has_header = false;
  status s = impl_->core.open_file(path, header_line, has_header);
  return impl_->after_open(s, header_line, has_header);
}

status landmark_reader::open_memory(const char* data, std::size_t size, const std::string& name) {
  impl_ = std::make_unique<impl>();
  std::string_view header_line;
  bool has_header = false;
  status s = impl_->core.open_memory(data, size, name, header_line, has_header);
  return impl_->after_open(s, header_line, has_header);
}

const landmark_file_header& landmark_reader::header() const { return impl_->header; }

read_result landmark_reader::next(landmark_frame& out) {
  for (;;) {
    std::string_view line;
    switch (impl_->core.next_line(line)) {
      case line_status::end:
        out.clear();
        return read_result::end;
      case line_status::error:
        out.clear();
        return read_result::error;
      case line_status::line:
        break;
    }
    const read_result r = impl_->parse_frame(line, out);
    if (r != read_result::frame || impl_->person < 0 || out.person == impl_->person) return r;
  }
}

void landmark_reader::set_person(int person) { impl_->person = person < 0 ? -1 : person; }

status people_in_file(const std::string& path, std::vector<int>& ids) {
  ids.clear();
  landmark_reader reader;
  if (status s = reader.open(path); !s) return s;
  auto frame = std::make_unique<landmark_frame>();
  std::vector<bool> seen;
  for (;;) {
    const read_result r = reader.next(*frame);
    if (r == read_result::end) break;
    if (r == read_result::error) return status::failure(reader.error_code(), reader.error());
    const auto at = static_cast<std::size_t>(frame->person);
    if (at >= seen.size()) seen.resize(at + 1, false);
    seen[at] = true;
  }
  for (std::size_t i = 0; i < seen.size(); ++i)
    if (seen[i]) ids.push_back(static_cast<int>(i));
  return {};
}

const std::string& landmark_reader::error() const { return impl_->core.error(); }
status_code landmark_reader::error_code() const { return impl_->core.error_code(); }
long landmark_reader::line() const { return impl_->core.line(); }

// ---- writer --------------------------------------------------------------------------------

struct landmark_writer::impl {
  io_detail::text_output out;
  int version = 1;

  bool put_points(const landmark* pts, int count, bool always_five) {
    for (int i = 0; i < count; ++i) {
      if (!out.reserve(5 * 32 + 8)) return false;
      const landmark& p = pts[i];
      out.put(i == 0 ? "[[" : ",[");
      out.put_number(p.x);
      out.put(',');
      out.put_number(p.y);
      out.put(',');
      out.put_number(p.z);
      // Hand and face points are [x, y, z]; visibility/presence are written only when they
      // differ from the implied 1 so that reading back gives the same frame.
      if (always_five || p.visibility != 1.f || p.presence != 1.f) {
        out.put(',');
        out.put_number(p.visibility);
        out.put(',');
        out.put_number(p.presence);
      }
      out.put(']');
    }
    if (!out.reserve(4)) return false;
    out.put(count == 0 ? "[]" : "]");
    return true;
  }
};

landmark_writer::landmark_writer() : impl_(std::make_unique<impl>()) {}
landmark_writer::~landmark_writer() = default;

status landmark_writer::open(const std::string& path, const landmark_file_header& header) {
  status s = impl_->out.open(path);
  if (!s) return s;
  auto& o = impl_->out;
  o.reserve(256);
  impl_->version = header.version >= 2 ? 2 : 1;
  o.put(impl_->version == 2 ? "{\"format\":\"avatarmap.landmarks\",\"version\":2"
                            : "{\"format\":\"avatarmap.landmarks\",\"version\":1");
  if (header.image_width > 0 && header.image_height > 0) {
    o.put(",\"image_size\":[");
    o.put_number(header.image_width);
    o.put(',');
    o.put_number(header.image_height);
    o.put(']');
  }
  if (header.fps > 0 && std::isfinite(header.fps)) {
    o.put(",\"fps\":");
    o.put_number(header.fps);
  }
  o.put("}\n");
  return {};
}

status landmark_writer::write(const landmark_frame& frame) {
  auto& o = impl_->out;
  if (!o.is_open()) return status::error(o.path() + ": write() on a writer that is not open");
  if (!o.reserve(64)) return o.error_status();
  o.put("{\"t\":");
  o.put_number(frame.t);
  if (impl_->version >= 2) {
    o.put(",\"person\":");
    o.put_number(frame.person);
  }
  for (int p = 0; p < k_frame_part_count; ++p) {
    auto fp = static_cast<frame_part>(p);
    if (!frame.has(fp)) continue;
    int capacity = 0;
    const landmark* pts = part_storage(frame, fp, capacity);
    int count = capacity;
    if (fp == frame_part::face) {
      count = frame.face_count == k_face_mesh_count ? k_face_mesh_count : k_face_mesh_iris_count;
    }
    if (!o.reserve(32)) return o.error_status();
    o.put(",\"");
    o.put(frame_part_key(fp));
    o.put("\":");
    bool five = fp == frame_part::pose || fp == frame_part::pose_world;
    if (!impl_->put_points(pts, count, five)) return o.error_status();
  }
  if (!o.reserve(2)) return o.error_status();
  o.put("}\n");
  return {};
}

status landmark_writer::commit() { return impl_->out.commit(); }

}  // namespace avatarmap
