#define STB_IMAGE_IMPLEMENTATION
#include "onnx_support.hpp"

#include <stb/stb_image.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>

namespace avatarmap::test {

std::string models_dir() {
  const char* m = std::getenv("AVATARMAP_MODELS");
  if (m == nullptr || *m == '\0') return "";
  const std::string sub = std::string(m) + "/onnx";
  if (std::ifstream(sub + "/pose_detection.onnx").good()) return sub;
  return m;
}

bool load_image(const std::string& path, loaded_image& out) {
  int c = 0;
  unsigned char* p = stbi_load(path.c_str(), &out.width, &out.height, &c, 3);
  if (!p) return false;
  out.pixels.assign(p, p + static_cast<size_t>(out.width) * out.height * 3);
  stbi_image_free(p);
  return true;
}

bool has_model(const std::string& stem, model_precision precision) {
  return std::ifstream(models_dir() + "/" + model_file_name(stem, precision)).good();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace avatarmap::test
