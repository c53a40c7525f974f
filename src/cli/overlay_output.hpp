// `--overlay PATH` of the capture commands: each frame copied, its landmarks drawn on the
// copy (capture/overlay.hpp) and the copy written (capture/video_writer.hpp). The copy buffer
// is allocated with the first frame and reused.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/media/video_writer.hpp"

namespace avatarmap::cli {

class overlay_output {
 public:
  status open(const std::string& path, int width, int height, double fps);
  /// Draws `frame` on a copy of `image` (RGB8) and writes it at frame.t. With several people
  /// (people.count >= 0, estimator::last_people()) draws each of them instead, in its own
  /// colour with its id (overlay_job::people); count -1 draws `frame` as one person.
  status write(const image_view& image, const landmark_frame& frame,
               const estimator::people_view& people = {});
  /// Finalises the file (it appears under its name only now).
  status close();
  bool is_open() const { return writer_.is_open(); }

 private:
  video_writer writer_;
  std::vector<std::uint8_t> pixels_;
};

}  // namespace avatarmap::cli
