#include "cli/overlay_output.hpp"

#include <cstring>

#include "avatarmap/capture/overlay.hpp"

namespace avatarmap::cli {

status overlay_output::open(const std::string& path, int width, int height, double fps) {
  return writer_.open(path, width, height, fps);
}

status overlay_output::write(const image_view& image, const landmark_frame& frame,
                             const estimator::people_view& people) {
  if (image.format != pixel_format::rgb8 || image.data == nullptr)
    return status::error("overlay: frames must be RGB8");
  const size_t row = static_cast<size_t>(image.width) * 3;
  const size_t need = row * static_cast<size_t>(image.height);
  if (pixels_.size() < need) pixels_.resize(need);
  for (int y = 0; y < image.height; ++y)
    std::memcpy(pixels_.data() + row * y, image.data + static_cast<size_t>(image.stride_bytes) * y,
                row);
  overlay_job job;
  job.image = {pixels_.data(), image.width, image.height, static_cast<int>(row)};
  if (people.count >= 0) {
    job.people = people.frames;
    job.people_count = static_cast<std::size_t>(people.count);
  } else {
    job.frame = &frame;
  }
  if (!job.run()) return status::error("overlay: the frame could not be drawn on");
  return writer_.write(
      {pixels_.data(), image.width, image.height, static_cast<int>(row), pixel_format::rgb8},
      frame.t);
}

status overlay_output::close() { return writer_.close(); }

}  // namespace avatarmap::cli
