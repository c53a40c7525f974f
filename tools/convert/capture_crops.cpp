// capture_crops: dumps the input tensors the capture pipelines feed each model, on real frames,
// for calibrating the int8 models (tools/convert/quantize.py, docs/convert.md "int8 models").
//
// Usage: capture_crops --models DIR --out DIR SOURCE[@FIRST-LAST] ...
// Each SOURCE (a video or an image, read with video_source) runs through the float pipelines
// (body full, both hands from the body or the palm detector, face from the body) in video
// mode; frames FIRST..LAST (0-based, inclusive) of it are dumped, all of them without @.
// For each dumped frame, each model gets the crop it would see:
//   pose_detection (224, [-1, 1]), palm_detection (192, [0, 1]): the whole image, letterboxed;
//   face_detection_short_range (128, [-1, 1]): the whole image and, with a body, the body's
//     face region (Holistic's search region);
//   pose_landmark (256, [0, 1]): the region the landmark model used this frame;
//   hand_landmark (224, [0, 1]): each hand's region; face_landmark (192, [0, 1]): the mesh's.
// The crops are the pipelines' own (image_crop_job with the pipelines' crop options).
// Output: OUT/<model>.f32 (raw float32, N x H x W x 3, appended in order) and OUT/<model>.txt
// (one line per sample: source and frame index). Nothing here is committed: only the ranges
// computed from these files are (tools/models/int8_ranges/).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/capture/face_pipeline.hpp"
#include "avatarmap/capture/hand_pipeline.hpp"
#include "avatarmap/capture/image_crop.hpp"
#include "avatarmap/capture/pose_pipeline.hpp"
#include "avatarmap/media/video_source.hpp"

namespace avatarmap {
namespace {

struct sink {
  crop_options options;
  std::ofstream data, index;
  std::vector<float> buffer;
  int count = 0;
};

crop_options make_crop(int size, float lo, float hi, crop_border border, bool keep_aspect) {
  crop_options c;
  c.output_width = c.output_height = size;
  c.range_min = lo;
  c.range_max = hi;
  c.border = border;
  c.keep_aspect_ratio = keep_aspect;
  return c;
}

bool dump(sink& s, const image_view& image, const normalized_rect& roi, const std::string& label) {
  image_crop_job job;
  job.image = image;
  job.roi = roi;
  job.options = s.options;
  s.buffer.resize(crop_output_size(s.options));
  job.output = s.buffer.data();
  job.output_size = s.buffer.size();
  if (!job.run()) return false;
  s.data.write(reinterpret_cast<const char*>(s.buffer.data()),
               static_cast<std::streamsize>(s.buffer.size() * sizeof(float)));
  s.index << label << "\n";
  ++s.count;
  return true;
}

int run(int argc, char** argv) {
  std::string models, out;
  std::vector<std::string> sources;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--models" && i + 1 < argc)
      models = argv[++i];
    else if (a == "--out" && i + 1 < argc)
      out = argv[++i];
    else
      sources.push_back(a);
  }
  if (models.empty() || out.empty() || sources.empty()) {
    std::fprintf(stderr, "usage: capture_crops --models DIR --out DIR SOURCE[@FIRST-LAST] ...\n");
    return 2;
  }
  std::map<std::string, sink> sinks;
  auto open_sink = [&](const std::string& name, const crop_options& c) {
    sink& s = sinks[name];
    s.options = c;
    s.data.open(out + "/" + name + ".f32", std::ios::binary | std::ios::trunc);
    s.index.open(out + "/" + name + ".txt", std::ios::trunc);
    return s.data.good() && s.index.good();
  };
  const bool ok =
      open_sink("pose_detection", make_crop(224, -1.f, 1.f, crop_border::zero, true)) &&
      open_sink("pose_landmark", make_crop(256, 0.f, 1.f, crop_border::replicate, true)) &&
      open_sink("palm_detection", make_crop(192, 0.f, 1.f, crop_border::zero, true)) &&
      open_sink("hand_landmark", make_crop(224, 0.f, 1.f, crop_border::replicate, true)) &&
      open_sink("face_detection_short_range", make_crop(128, -1.f, 1.f, crop_border::zero, true)) &&
      open_sink("face_landmark", make_crop(192, 0.f, 1.f, crop_border::replicate, false));
  if (!ok) {
    std::fprintf(stderr, "capture_crops: cannot write into %s\n", out.c_str());
    return 1;
  }

  for (const std::string& spec : sources) {
    std::string path = spec;
    int first = 0, last = 1 << 30;
    if (const size_t at = spec.rfind('@'); at != std::string::npos) {
      path = spec.substr(0, at);
      if (std::sscanf(spec.c_str() + at + 1, "%d-%d", &first, &last) != 2) {
        std::fprintf(stderr, "capture_crops: %s: expected PATH@FIRST-LAST\n", spec.c_str());
        return 2;
      }
    }
    pose_pipeline_options po;
    po.models_dir = models;
    hand_pipeline_options ho;
    ho.models_dir = models;
    face_pipeline_options fo;
    fo.models_dir = models;
    std::unique_ptr<pose_pipeline> pose;
    std::unique_ptr<hand_pipeline> hands;
    std::unique_ptr<face_pipeline> face;
    for (const status& s : {pose_pipeline::create(po, pose), hand_pipeline::create(ho, hands),
                            face_pipeline::create(fo, face)})
      if (!s.ok()) {
        std::fprintf(stderr, "capture_crops: %s\n", s.message().c_str());
        return 1;
      }
    video_source src;
    if (const status s = src.open(path); !s.ok()) {
      std::fprintf(stderr, "capture_crops: %s\n", s.message().c_str());
      return 1;
    }
    const std::string base = path.substr(path.find_last_of('/') + 1);
    image_view img;
    double t = 0.0;
    landmark_frame f;
    for (int i = 0; src.next(img, t) == read_result::frame && i <= last; ++i) {
      f.clear();
      f.t = t;
      const bool body = pose->process(img, f) == pose_result::found;
      hands->process(img, body ? &f : nullptr, f);
      face->process(img, body ? &f : nullptr, f);
      if (i < first) continue;
      const std::string label = base + " " + std::to_string(i);
      dump(sinks["pose_detection"], img, normalized_rect{}, label);
      dump(sinks["palm_detection"], img, normalized_rect{}, label);
      dump(sinks["face_detection_short_range"], img, normalized_rect{}, label + " image");
      if (body) {
        dump(sinks["pose_landmark"], img, pose->last_roi(), label);
        normalized_rect region;
        if (face_region_from_pose(f.pose.data(), img.width, img.height, region))
          dump(sinks["face_detection_short_range"], img, region, label + " body region");
      }
      for (int h = 0; h < hands->hand_count(); ++h)
        dump(sinks["hand_landmark"], img, hands->hand(h).roi, label + " hand " + std::to_string(h));
      if (face->last_acquisition() != face_acquisition::none)
        dump(sinks["face_landmark"], img, face->last_roi(), label);
    }
  }
  for (auto& [name, s] : sinks) std::printf("%s %d\n", name.c_str(), s.count);
  return 0;
}

}  // namespace
}  // namespace avatarmap

int main(int argc, char** argv) { return avatarmap::run(argc, argv); }
