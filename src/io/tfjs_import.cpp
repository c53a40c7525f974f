#include "avatarmap/io/tfjs_import.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "avatarmap/io/landmark_file.hpp"
#include "common/json_text.hpp"

namespace avatarmap {

namespace {

// The recordings are a few MB; the limits (common/json_limits.hpp) keep a hostile file from
// nesting nlohmann's recursion into a stack overflow or reading without bound.
status load_json(const std::string& path, nlohmann::json& out) {
  if (status s = io_detail::read_json_file(path, out); !s) return s;
  if (!out.is_array())
    return status::parse_error(path +
                               ": expected a JSON array of frames (tfjs-models test format), got " +
                               io_detail::json_type_text(out));
  return {};
}

// `d` as a float; beyond the float range it becomes +-inf ("not seen" in a landmark file)
// instead of the undefined behaviour of a plain cast.
float to_float(double d) {
  if (std::fabs(d) > static_cast<double>(std::numeric_limits<float>::max()))
    return d > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  return static_cast<float>(d);
}

// Reads `count` points of 3 numbers from frame `i` of `doc`.
status read_frame(const nlohmann::json& doc, std::size_t i, const std::string& path, int count,
                  double (*out)[3]) {
  const nlohmann::json& f = doc[i];
  if (!f.is_array() || f.size() != static_cast<std::size_t>(count))
    return status::parse_error(path + ": frame " + std::to_string(i) + ": expected an array of " +
                               std::to_string(count) + " points, got " +
                               (f.is_array() ? "an array of " + std::to_string(f.size())
                                             : std::string(io_detail::json_type_text(f))));
  for (int k = 0; k < count; ++k) {
    const nlohmann::json& p = f[static_cast<std::size_t>(k)];
    if (!p.is_array() || p.size() < 3)
      return status::parse_error(path + ": frame " + std::to_string(i) + " point " +
                                 std::to_string(k) + ": expected [x, y, z], got " +
                                 (p.is_array() ? "an array of " + std::to_string(p.size())
                                               : std::string(io_detail::json_type_text(p))));
    for (int c = 0; c < 3; ++c) {
      const nlohmann::json& v = p[static_cast<std::size_t>(c)];
      out[k][c] = v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
    }
  }
  return {};
}

// The recording's part: pose (33 points, image + world) or a hand (21 points).
status import_tfjs(const char* fn, const std::string& image_json, const std::string& world_json,
                   int image_width, int image_height, double fps, frame_part image_part,
                   frame_part world_part, const std::string& out_landmarks_path) {
  const std::string name = fn;
  if (image_width <= 0 || image_height <= 0)
    return status::error(name + ": image_width and image_height must be > 0");
  if (!(fps > 0) || !std::isfinite(fps))
    return status::error(name + ": fps must be a positive finite number, got " +
                         std::to_string(fps));
  nlohmann::json image, world;
  if (status s = load_json(image_json, image); !s) return s;
  if (status s = load_json(world_json, world); !s) return s;
  if (image.size() != world.size())
    return status::parse_error(image_json + " has " + std::to_string(image.size()) +
                               " frames but " + world_json + " has " +
                               std::to_string(world.size()) + " (expected the same number)");
  if (!image.empty() && !std::isfinite(static_cast<double>(image.size() - 1) / fps))
    return status::error(name + ": fps " + std::to_string(fps) +
                         " is too small: the last frame's time would not be finite");

  landmark_file_header header;
  header.present = true;
  header.image_width = image_width;
  header.image_height = image_height;
  header.fps = fps;
  landmark_writer writer;
  if (status s = writer.open(out_landmarks_path, header); !s) return s;
  landmark_frame frame;
  const int count = image_part == frame_part::pose ? k_pose_landmark_count : k_hand_landmark_count;
  double img[k_pose_landmark_count][3], wld[k_pose_landmark_count][3];
  const double w = image_width, h = image_height;
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (status s = read_frame(image, i, image_json, count, img); !s) return s;
    if (status s = read_frame(world, i, world_json, count, wld); !s) return s;
    frame.clear();
    frame.t = static_cast<double>(i) / fps;
    landmark* im = image_part == frame_part::pose        ? frame.pose.data()
                   : image_part == frame_part::left_hand ? frame.left_hand.data()
                                                         : frame.right_hand.data();
    landmark* wo = world_part == frame_part::pose_world        ? frame.pose_world.data()
                   : world_part == frame_part::left_hand_world ? frame.left_hand_world.data()
                                                               : frame.right_hand_world.data();
    for (int k = 0; k < count; ++k) {
      im[k] = landmark{to_float(img[k][0] / w), to_float(img[k][1] / h), to_float(img[k][2] / w),
                       1.f, 1.f};
      wo[k] = landmark{to_float(wld[k][0]), to_float(wld[k][1]), to_float(wld[k][2]), 1.f, 1.f};
    }
    frame.set(image_part, true);
    frame.set(world_part, true);
    if (status s = writer.write(frame); !s) return s;
  }
  return writer.commit();
}

}  // namespace

status import_tfjs_pose(const std::string& image_json, const std::string& world_json,
                        int image_width, int image_height, double fps,
                        const std::string& out_landmarks_path) {
  return import_tfjs("import_tfjs_pose", image_json, world_json, image_width, image_height, fps,
                     frame_part::pose, frame_part::pose_world, out_landmarks_path);
}

status import_tfjs_hand(const std::string& image_json, const std::string& world_json,
                        int image_width, int image_height, double fps, bool left,
                        const std::string& out_landmarks_path) {
  return import_tfjs("import_tfjs_hand", image_json, world_json, image_width, image_height, fps,
                     left ? frame_part::left_hand : frame_part::right_hand,
                     left ? frame_part::left_hand_world : frame_part::right_hand_world,
                     out_landmarks_path);
}

}  // namespace avatarmap
