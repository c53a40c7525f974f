// Helpers shared by the ONNX pipeline tests: the models folder, decoding a test image, medians.
#pragma once

#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"

namespace avatarmap::test {

/// $AVATARMAP_MODELS is the model cache (scripts/prepare_capture.sh puts the ONNX conversions in
/// its onnx/ folder) or directly a folder of .onnx files; "" when unset.
std::string models_dir();

/// An RGB image decoded with stb_image (an independent JPEG decoder).
struct loaded_image {
  std::vector<unsigned char> pixels;
  int width = 0, height = 0;
  image_view view() const { return {pixels.data(), width, height, width * 3, pixel_format::rgb8}; }
};
bool load_image(const std::string& path, loaded_image& out);

double median(std::vector<double> v);

/// Whether models_dir() holds `stem` at `precision` (stem.onnx or stem.int8.onnx).
bool has_model(const std::string& stem, model_precision precision);

}  // namespace avatarmap::test
