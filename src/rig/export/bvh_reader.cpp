// Minimal BVH reader: a whitespace tokenizer over the whole file (CRLF accepted), then a
// recursive-descent parse of HIERARCHY and a count-checked read of MOTION.
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <system_error>
#include <vector>

#include "avatarmap/export/bvh.hpp"

namespace avatarmap {
namespace {

// Largest frame_count * channel_count accepted (guards the allocation against a corrupt
// "Frames:" line; 2^28 floats = 1 GiB).
constexpr double k_max_values = 268435456.0;
// Deepest joint nesting accepted (guards the recursion).
constexpr int k_max_depth = 256;
// Largest file read (it is held in memory whole): CMU's clips are a few MB; 2^28 values of
// at least 2 bytes each ("0 ") fit.
constexpr std::uintmax_t k_max_file_bytes = std::uintmax_t{1} << 30;

class parser {
 public:
  parser(const std::string& path, const std::string& text) : path_(path), text_(text) {}

  status parse(bvh_clip& out) {
    bvh_clip clip;
    if (!expect("HIERARCHY")) return error_;
    std::string tok;
    next(tok);
    if (tok != "ROOT") return fail("expected ROOT, got \"" + printable(tok) + "\"");
    while (tok == "ROOT") {
      if (!joint(clip, -1, 0)) return error_;
      if (!next(tok)) return fail("unexpected end of file: no MOTION section");
    }
    if (tok != "MOTION") return fail("expected ROOT or MOTION, got \"" + printable(tok) + "\"");
    if (!expect("Frames:")) return error_;
    double frames = 0.0;
    if (!number(frames) || frames < 0 || frames != std::floor(frames) || frames > k_max_values)
      return fail("Frames: expects a whole number from 0 to 268435456");
    if (!expect("Frame") || !expect("Time:")) return error_;
    if (!number(clip.frame_time) || !(clip.frame_time > 0.0))
      return fail("Frame Time: expects a positive number of seconds");
    clip.frame_count = static_cast<int>(frames);
    if (frames * clip.channel_count > k_max_values)
      return fail("too many motion values (" + std::to_string(clip.frame_count) + " frames x " +
                  std::to_string(clip.channel_count) + " channels; at most 268435456)");
    std::size_t count =
        static_cast<std::size_t>(clip.frame_count) * static_cast<std::size_t>(clip.channel_count);
    // Every value takes at least two bytes ("0 "): a "Frames:" line larger than the rest of the
    // file can hold is refused before the values are allocated.
    const std::size_t room = (text_.size() - pos_ + 1) / 2;
    if (count > room)
      return fail("truncated MOTION: " + std::to_string(clip.frame_count) + " frames x " +
                  std::to_string(clip.channel_count) + " channels need " + std::to_string(count) +
                  " values, but the rest of the file holds at most " + std::to_string(room));
    clip.values.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      double v;
      if (!next(tok))
        return fail("truncated MOTION: expected " + std::to_string(count) + " values (" +
                    std::to_string(clip.frame_count) + " frames x " +
                    std::to_string(clip.channel_count) + " channels), found " + std::to_string(i));
      if (!to_number(tok, v) || !finite_float(v))
        return fail("bad motion value \"" + printable(tok) +
                    "\" (expected a finite number within the float range)");
      clip.values[i] = static_cast<float>(v);
    }
    out = std::move(clip);
    return {};
  }

 private:
  bool next(std::string& tok) {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= text_.size()) {
      tok.clear();
      return false;
    }
    std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    tok.assign(text_, start, pos_ - start);
    return true;
  }
  bool fail_bool(const std::string& what) {
    error_ = status::parse_error(path_ + ":" + std::to_string(line_) + ": " + what);
    return false;
  }
  status fail(const std::string& what) {
    fail_bool(what);
    return error_;
  }
  bool expect(const char* word) {
    std::string tok;
    if (!next(tok)) return fail_bool(std::string("unexpected end of file, expected ") + word);
    if (tok != word)
      return fail_bool(std::string("expected ") + word + ", got \"" + printable(tok) + "\"");
    return true;
  }
  // Values are stored as float: a double beyond its range would overflow the cast.
  static bool finite_float(double v) {
    return std::isfinite(v) && std::fabs(v) <= static_cast<double>(FLT_MAX);
  }
  // A token as quoted in a message: at most 40 bytes, other bytes than printable ASCII as '?'.
  static std::string printable(const std::string& tok) {
    std::string s = tok.substr(0, 40);
    for (char& c : s)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    return tok.size() > 40 ? s + "..." : s;
  }
  static bool to_number(const std::string& tok, double& v) {
    if (tok.empty()) return false;
    char* end = nullptr;
    errno = 0;
    v = std::strtod(tok.c_str(), &end);
    return end == tok.c_str() + tok.size() && errno != ERANGE;
  }
  bool number(double& v) {
    std::string tok;
    if (!next(tok)) return fail_bool("unexpected end of file, expected a number");
    if (!to_number(tok, v) || !finite_float(v))
      return fail_bool("bad number \"" + printable(tok) +
                       "\" (expected a finite number within the float range)");
    return true;
  }
  bool vec3(glm::vec3& v) {
    double x, y, z;
    if (!number(x) || !number(y) || !number(z)) return false;
    v = glm::vec3(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    return true;
  }

  // After ROOT/JOINT: name { OFFSET x y z CHANNELS n ... (JOINT ... | End Site {...})* }
  bool joint(bvh_clip& clip, int parent, int depth) {
    if (depth >= k_max_depth) return fail_bool("joints nested deeper than 256 levels");
    bvh_joint j;
    j.parent = parent;
    std::string tok;
    if (!next(tok)) return fail_bool("unexpected end of file, expected a joint name");
    j.name = tok;
    if (!expect("{") || !expect("OFFSET") || !vec3(j.offset)) return false;
    int self = static_cast<int>(clip.joints.size());
    if (!next(tok)) return fail_bool("unexpected end of file in joint " + printable(j.name));
    if (tok == "CHANNELS") {
      double n;
      if (!number(n) || n < 0 || n > 6 || n != std::floor(n))
        return fail_bool("CHANNELS expects a count from 0 to 6");
      for (int c = 0; c < static_cast<int>(n); ++c) {
        if (!next(tok)) return fail_bool("unexpected end of file in CHANNELS");
        static const char* k_names[] = {"Xposition", "Yposition", "Zposition",
                                        "Xrotation", "Yrotation", "Zrotation"};
        int found = -1;
        for (int k = 0; k < 6; ++k)
          if (tok == k_names[k]) found = k;
        if (found < 0) return fail_bool("unknown channel \"" + printable(tok) + "\"");
        j.channels.push_back(static_cast<bvh_channel>(found));
      }
      if (!next(tok)) return fail_bool("unexpected end of file in joint " + printable(j.name));
    }
    j.first_channel = clip.channel_count;
    clip.channel_count += static_cast<int>(j.channels.size());
    clip.joints.push_back(j);
    while (tok != "}") {
      if (tok == "JOINT") {
        if (!joint(clip, self, depth + 1)) return false;
      } else if (tok == "End") {
        glm::vec3 end;
        if (!expect("Site") || !expect("{") || !expect("OFFSET") || !vec3(end) || !expect("}"))
          return false;
        clip.joints[self].has_end_site = true;
        clip.joints[self].end_site = end;
      } else if (tok.empty()) {
        return fail_bool("unexpected end of file in joint " + printable(clip.joints[self].name) +
                         " (missing })");
      } else {
        return fail_bool("unexpected \"" + printable(tok) + "\" in joint " +
                         printable(clip.joints[self].name));
      }
      next(tok);
    }
    return true;
  }

  const std::string& path_;
  const std::string& text_;
  std::size_t pos_ = 0;
  int line_ = 1;
  status error_;
};

}  // namespace

glm::quat bvh_clip::local_rotation(int frame, int joint) const {
  glm::dquat q(1.0, 0.0, 0.0, 0.0);
  const bvh_joint& j = joints[joint];
  for (int c = 0; c < static_cast<int>(j.channels.size()); ++c) {
    int axis = static_cast<int>(j.channels[c]) - static_cast<int>(bvh_channel::x_rotation);
    if (axis < 0) continue;
    double half = 0.5 * value(frame, joint, c) * (3.14159265358979323846 / 180.0);
    glm::dquat r(std::cos(half), 0.0, 0.0, 0.0);
    r[axis] = std::sin(half);
    q = q * r;
  }
  return glm::quat(static_cast<float>(q.w), static_cast<float>(q.x), static_cast<float>(q.y),
                   static_cast<float>(q.z));
}

glm::vec3 bvh_clip::position(int frame, int joint) const {
  glm::vec3 p(0.f);
  const bvh_joint& j = joints[joint];
  for (int c = 0; c < static_cast<int>(j.channels.size()); ++c) {
    int axis = static_cast<int>(j.channels[c]);
    if (axis <= static_cast<int>(bvh_channel::z_position)) p[axis] = value(frame, joint, c);
  }
  return p;
}

status read_bvh(const std::string& path, bvh_clip& out) {
  try {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (!ec && size > k_max_file_bytes)
      return status::parse_error(path + ": " + std::to_string(size) +
                                 " bytes, more than a BVH file may have here (1 GiB)");
    std::ifstream in(path, std::ios::binary);
    if (!in) return status::io_error(path + ": cannot open the file");
    // Read in blocks up to the limit: a FIFO or a device has no size to check up front.
    std::string text;
    char block[1 << 16];
    while (in.read(block, sizeof block) || in.gcount() > 0) {
      text.append(block, static_cast<std::size_t>(in.gcount()));
      if (text.size() > k_max_file_bytes)
        return status::parse_error(path + ": more than the 1 GiB a BVH file may have here");
    }
    if (in.bad()) return status::io_error(path + ": read error");
    if (text.empty()) return status::parse_error(path + ": empty file (not a BVH)");
    parser p(path, text);
    return p.parse(out);
  } catch (const std::bad_alloc&) {
    return status::out_of_memory(path + ": not enough memory to read the file");
  } catch (const std::exception&) {
    return status::internal(path + ": could not be read (an unexpected failure; please report it)");
  }
}

}  // namespace avatarmap
