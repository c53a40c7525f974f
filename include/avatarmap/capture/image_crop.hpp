// MediaPipe's ImageToTensor (its CPU or OpenGL converter's sampling) as a job: a rotated,
// optionally letterboxed region of an image resampled into a float RGB tensor, plus the transform
// that maps landmarks found in that tensor back onto the image.
//
// Conventions (shared with MediaPipe; docs/capture.md):
// - Image pixel coordinates: x right, y down, pixel (i, j) sampled at the integer point (i, j)
//   (OpenCV's convention). Normalised image coordinates are pixel coordinates divided by the
//   image width and height: (0.5, 0.5) is the point (width / 2, height / 2).
// - Tensor pixel coordinates: the same convention in the output tensor. With the CPU
//   converter's sampling (crop_sampling::opencv), the tensor pixel (x, y) is sampled at the source
//   point  centre + R(rotation) * ((x / W - 0.5) * roi_width, (y / H - 0.5) * roi_height)  in image
//   pixels, W x H being the tensor size. Note the x / W (not (x + 0.5) / W): MediaPipe's CPU
//   converter maps the tensor's corner points 0 and W onto the ROI's edges (cv::boxPoints ->
//   cv::getPerspectiveTransform -> cv::warpPerspective), so this crop follows it, half-pixel shift
//   included.
// - rotation: radians; positive turns the ROI clockwise on screen (y down), as in
//   MediaPipe's NormalizedRect.
//
// With crop_sampling::opencv (MediaPipe's CPU converter), sampling reproduces OpenCV's 8-bit
// INTER_LINEAR warp bit for bit (up to double rounding at exact ties); crop_sampling::gl (its
// OpenGL converter) samples pixel centres instead, see there. CPU converter details: source
// positions are rounded to 1/32 pixel, the four weights are 15-bit fixed point, the result is
// rounded to 8 bits and then mapped to [range_min, range_max] as
// value * (range_max - range_min) / 255 + range_min.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "avatarmap/capture/estimator.hpp"

namespace avatarmap {

/// A region of interest in normalised image coordinates (MediaPipe's NormalizedRect): centre,
/// size (fractions of the image width and height; may exceed 1 or reach outside the image)
/// and rotation in radians about the centre.
struct normalized_rect {
  float x_center = 0.5f;
  float y_center = 0.5f;
  float width = 1.0f;
  float height = 1.0f;
  float rotation = 0.0f;
};

/// What to do with tensor pixels whose source lies (partly) outside the image.
enum class crop_border : std::uint8_t {
  replicate,  // clamp to the nearest edge pixel (cv::BORDER_REPLICATE, MediaPipe's default)
  zero,       // black, i.e. range_min (cv::BORDER_CONSTANT with value 0)
};

/// Where tensor pixels sample the image and how. MediaPipe's ImageToTensor has two converters
/// whose results differ by a shift that grows with the region's scale (half a tensor pixel,
/// less half an image pixel):
enum class crop_sampling : std::uint8_t {
  /// The CPU converter (OpenCV, MediaPipe's C++ / Python CPU graphs): tensor pixel x samples
  /// the ROI at x / W (its corner points 0 and W on the ROI's edges), image pixel i at i; 8-bit
  /// bilinear with 1/32-pixel positions, bit for bit as cv::warpPerspective.
  opencv,
  /// The OpenGL converter (MediaPipe's GPU graphs and its web solutions, WebGL 2): pixel
  /// centres, tensor pixel x at (x + 0.5) / W of the ROI, image pixel i at i + 0.5; bilinear in
  /// float (GL_LINEAR). replicate is GL_CLAMP_TO_EDGE; zero is MediaPipe's shader for contexts
  /// without GL_CLAMP_TO_BORDER (OpenGL ES 3.0, WebGL 2): a sample whose position lies beyond
  /// the image's outer edge (more than half a pixel outside the edge pixels' centres) is 0,
  /// anything inside is sampled clamped to the edge.
  gl,
};

/// Fixed options of a crop, usually one per model input.
struct crop_options {
  int output_width = 256;   // tensor width W, > 0
  int output_height = 256;  // tensor height H, > 0
  float range_min = 0.0f;   // value of a 0 byte; finite, < range_max
  float range_max = 1.0f;   // value of a 255 byte
  /// Grow the ROI (width or height, never both) so that its aspect matches the tensor's:
  /// the region keeps its proportions and the extra area becomes letterbox bands
  /// (MediaPipe's PadRoi).
  bool keep_aspect_ratio = true;
  crop_border border = crop_border::replicate;
  crop_sampling sampling = crop_sampling::opencv;
};

/// A point in tensor pixels or normalised image coordinates; z in the same units as x.
struct crop_point {
  float x = 0.0f;
  float y = 0.0f;
  float z = 0.0f;
};

/// The geometry of one crop. `to_image` and `to_tensor` are 2x3 row-major affine matrices:
/// image_px = to_image * (tensor_x, tensor_y, 1) and its inverse.
struct crop_transform {
  std::array<double, 6> to_image{};
  std::array<double, 6> to_tensor{};
  /// The ROI after letterbox padding, in image pixels (centre, size, rotation radians).
  float roi_center_x = 0.0f;
  float roi_center_y = 0.0f;
  float roi_width = 0.0f;
  float roi_height = 0.0f;
  float roi_rotation = 0.0f;
  /// Letterbox bands as fractions of the tensor size: left, top, right, bottom (MediaPipe's
  /// LETTERBOX_PADDING); all zero without keep_aspect_ratio.
  std::array<float, 4> letterbox_padding{};
  int image_width = 0;
  int image_height = 0;
  int tensor_width = 0;
  int tensor_height = 0;
};

/// Computes the crop geometry of `roi` on an image_width x image_height image. Returns false
/// (and leaves `out` unspecified) when a size is <= 0, the ROI has a non-finite field or a
/// width or height <= 0 (also after scaling to pixels), or a corner of the (padded) ROI lies
/// more than 2^24 pixels from the image origin.
bool make_crop_transform(int image_width, int image_height, const normalized_rect& roi,
                         const crop_options& options, crop_transform& out);

/// Maps a point found in the tensor (pixels, z in tensor pixels like x) to normalised image
/// coordinates. Equals MediaPipe's TensorsToLandmarks (normalise by the tensor size) ->
/// LandmarkLetterboxRemoval -> LandmarkProjection chain, z included (z is scaled like x: the
/// result's z is in units of the image width). MediaPipe's rect projection rotates in
/// normalised space, which agrees with this exact inverse only when the ROI is square in
/// pixels (as all ROIs of its pose, hand and face graphs are); this one is exact for any ROI.
crop_point project_to_image(const crop_transform& transform, crop_point tensor_point);

/// The inverse of project_to_image: normalised image coordinates to tensor pixels.
crop_point project_to_tensor(const crop_transform& transform, crop_point image_point);

/// Number of floats a crop writes: output_width * output_height * 3.
inline std::size_t crop_output_size(const crop_options& options) {
  return static_cast<std::size_t>(options.output_width) *
         static_cast<std::size_t>(options.output_height) * 3u;
}

/// One crop: `image` (any pixel_format and stride; gray8 is replicated to 3 channels, alpha is
/// dropped, BGR is swapped) -> `output`, W x H x 3 floats, row-major, RGB (NHWC with N = 1).
/// Owns no buffer; allocates nothing; the caller keeps `image` and `output` alive during run().
/// Safe to run concurrently on distinct outputs.
struct image_crop_job {
  image_view image{};
  normalized_rect roi{};
  crop_options options{};
  float* output = nullptr;
  std::size_t output_size = 0;  // floats available at `output`; >= crop_output_size(options)
  /// Optional: receives the crop's geometry (for project_to_image).
  crop_transform* out_transform = nullptr;

  /// True when every input is usable: image data set, sizes > 0, stride large enough, ROI
  /// accepted by make_crop_transform, options sizes > 0, finite range_min < range_max,
  /// output set and large enough.
  bool validate() const;
  /// Runs the crop; false (output untouched) when validate() fails.
  bool run() const;
};

}  // namespace avatarmap
