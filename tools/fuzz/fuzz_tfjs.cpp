// libFuzzer target: the tfjs-models importer (io/tfjs_import.hpp: import_tfjs_pose). The input
// is the image-points JSON, then (after a line "===") the world-points JSON; without the
// separator both files get the same bytes. Both are written to a private scratch folder with
// an existing output file beside them. Checks that nothing crashes or throws; that a failure
// names a file and leaves the existing output untouched and no other file behind (the writer
// is atomic); and that on success the output loads back with the landmark reader, one frame
// per input frame at t = i / fps, each point the input's divided by the image size (or
// missing where the input has no finite number).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/tfjs_import.hpp"
#include "fuzz_support.hpp"

using namespace avatarmap;
using avatarmap::fuzz::check;

namespace {

constexpr int k_width = 640;
constexpr int k_height = 480;
constexpr double k_fps = 30.0;
constexpr std::string_view k_separator = "\n===\n";
constexpr std::string_view k_previous = "an existing output file\n";

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Point k of frame i of a tfjs document, coordinate c, as the importer must read it: a number
// (converted to double) or missing.
bool number_at(const nlohmann::json& doc, std::size_t i, int k, int c, double& out) {
  const nlohmann::json& v = doc[i][static_cast<std::size_t>(k)][static_cast<std::size_t>(c)];
  if (!v.is_number()) return false;
  out = v.get<double>();
  return true;
}

// The landmark the file must hold for `value` (x scaled by `scale`): the same float, or a
// missing (non-finite) one.
bool same(float got, bool present, double value, double scale) {
  if (!present) return !std::isfinite(got);
  const float want = static_cast<float>(value / scale);
  if (!std::isfinite(want)) return !std::isfinite(got);
  return got == want;
}

void check_output(const std::string& out_path, const std::string& image_text,
                  const std::string& world_text) {
  const nlohmann::json image = nlohmann::json::parse(image_text, nullptr, false);
  const nlohmann::json world = nlohmann::json::parse(world_text, nullptr, false);
  check(image.is_array() && world.is_array() && image.size() == world.size(),
        "an import that succeeds had two arrays of the same length");
  const std::string text = read_all(out_path);
  landmark_reader reader;
  check(reader.open_memory(text.data(), text.size(), "out").ok(), "the output's header reads");
  check(reader.header().present && reader.header().image_width == k_width &&
            reader.header().image_height == k_height && reader.header().fps == k_fps,
        "the header holds the image size and the fps");
  landmark_frame f;
  std::size_t i = 0;
  for (;; ++i) {
    const read_result r = reader.next(f);
    if (r == read_result::end) break;
    if (r == read_result::error) std::fprintf(stderr, "%s\n", reader.error().c_str());
    check(r == read_result::frame, "every line of the output reads back");
    check(i < image.size(), "no more frames than the input");
    check(f.t == static_cast<double>(i) / k_fps, "frame i at t = i / fps");
    check(f.has(frame_part::pose) && f.has(frame_part::pose_world), "pose and world present");
    for (int k = 0; k < k_pose_landmark_count; ++k) {
      const landmark& p = f.pose[static_cast<std::size_t>(k)];
      const landmark& w = f.pose_world[static_cast<std::size_t>(k)];
      double v = 0.0;
      bool present = number_at(image, i, k, 0, v);
      check(same(p.x, present, v, k_width), "image x / width");
      present = number_at(image, i, k, 1, v);
      check(same(p.y, present, v, k_height), "image y / height");
      present = number_at(image, i, k, 2, v);
      check(same(p.z, present, v, k_width), "image z / width");
      present = number_at(world, i, k, 1, v);
      check(same(w.y, present, v, 1.0), "world y as given");
    }
  }
  check(i == image.size(), "one output frame per input frame");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t cut = all.find(k_separator);
  const std::string image_text(all.substr(0, cut));
  const std::string world_text(
      cut == std::string_view::npos ? all : all.substr(cut + k_separator.size()));
  fuzz::clear_scratch();
  const std::string image = fuzz::write_scratch(
      "image.json", reinterpret_cast<const std::uint8_t*>(image_text.data()), image_text.size());
  const std::string world = fuzz::write_scratch(
      "world.json", reinterpret_cast<const std::uint8_t*>(world_text.data()), world_text.size());
  const std::string out = fuzz::write_scratch(
      "out.landmarks.jsonl", reinterpret_cast<const std::uint8_t*>(k_previous.data()),
      k_previous.size());

  status s = import_tfjs_pose(image, world, k_width, k_height, k_fps, out);
  check(fuzz::scratch_entries() == 3, "no temporary file is left behind");
  if (!s) {
    check(s.message().rfind(image, 0) == 0 || s.message().rfind(world, 0) == 0 ||
              s.message().rfind(out, 0) == 0,
          "errors start with the path of the file at fault");
    check(read_all(out) == k_previous, "a failed import leaves the existing output untouched");
    return 0;
  }
  check_output(out, image_text, world_text);
  return 0;
}
