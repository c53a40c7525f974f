// pose_pipeline: MediaPipe's pose graph around pose_detection and pose_landmark under ONNX
// Runtime. Mirrors pose_landmark_cpu.pbtxt: PoseDetectionCpu -> PoseDetectionToRoi ->
// PoseLandmarkByRoiCpu -> PoseLandmarksToRoi (tracking), without the smoothing filters. The
// heatmap refinement runs only when the landmark model keeps its heatmap output.
#include "avatarmap/capture/pose_pipeline.hpp"

#include <onnxruntime_cxx_api.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "avatarmap/capture/landmark_smoothing.hpp"
#include "ort_model.hpp"

namespace avatarmap {

namespace {

const char* complexity_name(pose_model_complexity c) {
  switch (c) {
    case pose_model_complexity::lite:
      return "lite";
    case pose_model_complexity::heavy:
      return "heavy";
    default:
      return "full";
  }
}

constexpr int k_detector_size = 224;
constexpr int k_landmark_size = 256;
constexpr int k_landmark_points = 39;  // 33 landmarks + 6 auxiliary points
constexpr int k_aux_first = 33;        // auxiliary points 33 and 34 align the next region
constexpr int k_heatmap_size = 64;     // optional heatmap output [1, 64, 64, 39]
constexpr int k_refine_kernel = 7;     // RefineLandmarksFromHeatmap kernel_size
constexpr float k_min_confidence_to_refine = 0.5f;

}  // namespace

// MediaPipe's RefineLandmarksFromHeatmapCalculator on one point: replaces (x, y) (tensor
// pixels) by the confidence-weighted mean cell of a 7x7 window of the heatmap around it when
// the window's highest confidence reaches 0.5. The window shrinks at the heatmap's edges.
void refine_from_heatmap(const float* heatmap, int channel, float& x, float& y) {
  const int n = k_heatmap_size;
  const int col = static_cast<int>(x / k_landmark_size * n);
  const int row = static_cast<int>(y / k_landmark_size * n);
  if (!(x >= 0.f) || !(y >= 0.f) || col >= n || row >= n) return;
  const int off = (k_refine_kernel - 1) / 2;
  float sum = 0.f, wc = 0.f, wr = 0.f, mx = 0.f;
  for (int r = std::max(0, row - off); r < std::min(n, row + off + 1); ++r) {
    for (int c = std::max(0, col - off); c < std::min(n, col + off + 1); ++c) {
      const float v =
          sigmoid(heatmap[(static_cast<size_t>(r) * n + c) * k_landmark_points + channel]);
      sum += v;
      mx = std::max(mx, v);
      wc += c * v;
      wr += r * v;
    }
  }
  if (mx >= k_min_confidence_to_refine && sum > 0.f) {
    x = wc / n / sum * k_landmark_size;
    y = wr / n / sum * k_landmark_size;
  }
}

struct pose_pipeline::impl {
  bool has_heatmap = false;
  pose_pipeline_options options;
  bound_model detector;  // outputs: boxes [2254 x 12], scores [2254]
  bound_model landmark;  // outputs: landmarks [195], presence [1], world [117]
  std::vector<ssd_anchor> anchors;
  detection_decode_options decode;
  std::vector<detection> decoded;
  std::vector<detection> kept;
  std::vector<int> scratch;
  crop_options detector_crop;
  crop_options landmark_crop;

  // What is tracked of one person between frames. The single-person capture uses people[0];
  // with several people (select_person()) each has its own, the models are shared.
  struct person_state {
    // Video-mode smoothing (pose_pipeline_options::smoothing): tfjs-models' BlazePose
    // configuration (velocity filters on the image and auxiliary points) or MediaPipe's
    // current pose_landmark_filtering.pbtxt (One Euro); world points One Euro in both.
    // smooth_image and smooth_aux get their filter in create(), from options.smoothing.
    landmark_smoother smooth_image;
    landmark_smoother smooth_aux;
    landmark_smoother smooth_world{{0.1f, 40.f, 1.f, true}};
    visibility_smoother smooth_visibility{0.1f};

    bool has_roi = false;
    bool seeded = false;  // start_track(): the next process() runs on roi without the detector
    normalized_rect roi;  // tracked region for the next frame
    normalized_rect used_roi;
  };
  std::array<person_state, k_max_people> people;
  person_state* st = &people[0];  // the selected person
  float presence = 0.f;
  bool ran_detector = false;
  pose_timings timings;
  std::string error;

  // Runs the detector on the whole image; false when nobody is found.
  bool detect(const image_view& image, normalized_rect& out_roi) {
    const auto t0 = std::chrono::steady_clock::now();
    crop_transform tr;
    // The whole image, letterboxed.
    if (!detector.crop_input(image, normalized_rect{}, detector_crop, &tr)) {
      error = "pose detector: the image could not be cropped";
      return false;
    }
    const auto ti = std::chrono::steady_clock::now();
    detector.run();
    timings.detector_inference_ms = ms_since(ti);
    decode_detections(detector.outputs[0].data(), detector.outputs[1].data(), anchors.data(),
                      decode, decoded);
    weighted_non_max_suppression(decoded, options.nms_iou_threshold, 1, kept, scratch);
    timings.detector_ms = ms_since(t0);
    if (kept.empty()) return false;
    // Detection letterbox removal: detector-input fractions -> tensor pixels -> image.
    detection d = kept[0];
    for (int k = 0; k < d.keypoint_count; ++k) {
      crop_point p = project_to_image(
          tr, {d.keypoints[2 * k] * k_detector_size, d.keypoints[2 * k + 1] * k_detector_size, 0});
      d.keypoints[2 * k] = p.x;
      d.keypoints[2 * k + 1] = p.y;
    }
    out_roi = pose_detection_to_roi(d, image.width, image.height);
    return true;
  }

  // Several people: the detector on the whole image, the regions of up to `max` boxes after
  // suppression, best score first (the suppression's order), into out_rois / out_scores.
  // Returns their number, or -1 when the image could not be cropped.
  int detect_all(const image_view& image, int max, normalized_rect* out_rois, float* out_scores,
                 float* out_anchors) {
    const auto t0 = std::chrono::steady_clock::now();
    crop_transform tr;
    if (!detector.crop_input(image, normalized_rect{}, detector_crop, &tr)) {
      error = "pose detector: the image could not be cropped";
      return -1;
    }
    const auto ti = std::chrono::steady_clock::now();
    detector.run();
    timings.detector_inference_ms = ms_since(ti);
    decode_detections(detector.outputs[0].data(), detector.outputs[1].data(), anchors.data(),
                      decode, decoded);
    weighted_non_max_suppression(decoded, options.nms_iou_threshold, max, kept, scratch);
    int n = 0;
    for (const detection& k : kept) {
      if (n >= max) break;
      detection d = k;
      for (int i = 0; i < d.keypoint_count; ++i) {
        const crop_point p = project_to_image(tr, {d.keypoints[2 * i] * k_detector_size,
                                                   d.keypoints[2 * i + 1] * k_detector_size, 0});
        d.keypoints[2 * i] = p.x;
        d.keypoints[2 * i + 1] = p.y;
      }
      out_rois[n] = pose_detection_to_roi(d, image.width, image.height);
      out_scores[n] = d.score;
      out_anchors[4 * n] = d.keypoints[0];  // hip centre
      out_anchors[4 * n + 1] = d.keypoints[1];
      out_anchors[4 * n + 2] = d.keypoints[4];  // shoulder centre (keypoint 2)
      out_anchors[4 * n + 3] = d.keypoints[5];
      ++n;
    }
    timings.detector_ms = ms_since(t0);
    return n;
  }

  void reset_smoothing() {
    st->smooth_image.reset();
    st->smooth_world.reset();
    st->smooth_aux.reset();
    st->smooth_visibility.reset();
  }

  // Runs the landmark model on `r`; false when the pose is not present. `t` (seconds) and
  // `smoothing` drive the video-mode filters.
  bool landmarks(const image_view& image, const normalized_rect& r, double t, bool smoothing,
                 landmark_frame& out) {
    const auto t0 = std::chrono::steady_clock::now();
    crop_transform tr;
    if (!landmark.crop_input(image, r, landmark_crop, &tr)) {
      error = "pose landmarks: the region could not be cropped";
      return false;
    }
    const auto ti = std::chrono::steady_clock::now();
    landmark.run();
    timings.landmark_inference_ms = ms_since(ti);
    const float* raw = landmark.outputs[0].data();
    const float* world = landmark.outputs[2].data();
    presence = landmark.outputs[1][0];
    if (!(presence >= options.min_presence)) {
      timings.landmark_ms = ms_since(t0);
      return false;
    }
    for (int i = 0; i < k_pose_landmark_count; ++i) {
      const float* p = raw + i * 5;
      float px = p[0], py = p[1];
      if (has_heatmap) refine_from_heatmap(landmark.outputs[3].data(), i, px, py);
      const crop_point q = project_to_image(tr, {px, py, p[2]});
      avatarmap::landmark& l = out.pose[i];
      l.x = q.x;
      l.y = q.y;
      l.z = q.z;
      l.visibility = sigmoid(p[3]);
      l.presence = sigmoid(p[4]);
    }
    // WorldLandmarkProjection: the world points come in the region's frame; rotate them
    // back by the region's rotation (about z, metres unchanged).
    const float c = std::cos(r.rotation), s = std::sin(r.rotation);
    for (int i = 0; i < k_pose_landmark_count; ++i) {
      const float* p = world + i * 3;
      avatarmap::landmark& l = out.pose_world[i];
      l.x = c * p[0] - s * p[1];
      l.y = s * p[0] + c * p[1];
      l.z = p[2];
      l.visibility = out.pose[i].visibility;
      l.presence = out.pose[i].presence;
    }
    // PoseLandmarksToRoi: the next region from auxiliary points 33 (centre) and 34 (scale).
    avatarmap::landmark aux[2];
    for (int k = 0; k < 2; ++k) {
      const float* a = raw + (k_aux_first + k) * 5;
      float ax = a[0], ay = a[1];
      if (has_heatmap) refine_from_heatmap(landmark.outputs[3].data(), k_aux_first + k, ax, ay);
      const crop_point c = project_to_image(tr, {ax, ay, a[2]});
      aux[k].x = c.x;
      aux[k].y = c.y;
      aux[k].z = c.z;
    }
    if (smoothing) {
      st->smooth_image.apply(t, out.pose.data(), k_pose_landmark_count, true, image.width,
                             image.height);
      st->smooth_visibility.apply(out.pose.data(), k_pose_landmark_count);
      st->smooth_world.apply(t, out.pose_world.data(), k_pose_landmark_count, false, 0, 0);
      st->smooth_aux.apply(t, aux, 2, true, image.width, image.height);
      for (int i = 0; i < k_pose_landmark_count; ++i)
        out.pose_world[i].visibility = out.pose[i].visibility;
    }
    st->roi = roi_from_alignment_points(aux[0].x, aux[0].y, aux[1].x, aux[1].y, image.width,
                                        image.height);
    st->has_roi = true;
    timings.landmark_ms = ms_since(t0);
    return true;
  }
};

pose_pipeline::pose_pipeline(std::unique_ptr<impl> p) : impl_(std::move(p)) {}
pose_pipeline::~pose_pipeline() = default;

status pose_pipeline::create(const pose_pipeline_options& options,
                             std::unique_ptr<pose_pipeline>& out) {
  out.reset();
  if (const std::string e = check_pipeline_options("pose_pipeline", options.intra_op_threads,
                                                   options.min_detection_score,
                                                   options.nms_iou_threshold, options.min_presence);
      !e.empty())
    return status::error(e);
  const std::string dir = options.models_dir.empty() ? "." : options.models_dir;
  const std::string det_path = dir + "/" + model_file_name("pose_detection", options.precision);
  const std::string lm_path =
      dir + "/" +
      model_file_name(std::string("pose_landmark_") + complexity_name(options.complexity),
                      options.precision);
  for (const std::string& p : {det_path, lm_path})
    if (!std::ifstream(p).good())
      return status::io_error("pose_pipeline: cannot open " + p +
                              missing_model_hint(options.precision));

  std::unique_ptr<impl> m(new impl());
  m->options = options;
  try {
    const Ort::SessionOptions so =
        make_session_options(options.intra_op_threads, options.allow_spinning);
    std::vector<bool> found;
    // Both sessions at once (start-up, model_cache.hpp); an ORT error names its model.
    const std::string e = load_in_parallel(
        [&] {
          return with_model_name(det_path, [&] {
            return m->detector.load(det_path, so, {1, k_detector_size, k_detector_size, 3},
                                    {2254 * 12, 2254});
          });
        },
        [&] {
          return with_model_name(lm_path, [&] {
            return m->landmark.load(lm_path, so, {1, k_landmark_size, k_landmark_size, 3},
                                    {k_landmark_points * 5, 1, k_landmark_points * 3},
                                    {k_heatmap_size * k_heatmap_size * k_landmark_points}, &found);
          });
        });
    m->has_heatmap = !found.empty() && found[0];
    if (!e.empty()) return status::parse_error("pose_pipeline: " + e);
  } catch (const Ort::Exception& ex) {
    return status::parse_error("pose_pipeline: ONNX Runtime: " + std::string(ex.what()));
  }
  for (impl::person_state& ps : m->people) {
    if (options.smoothing == pose_smoothing::velocity) {
      ps.smooth_image = landmark_smoother(mediapipe_velocity_params{5, 10.f});
      ps.smooth_aux = landmark_smoother(mediapipe_velocity_params{5, 10.f});
    } else {
      ps.smooth_image = landmark_smoother(mediapipe_one_euro_params{0.05f, 80.f, 1.f, false});
      ps.smooth_aux = landmark_smoother(mediapipe_one_euro_params{0.01f, 10.f, 1.f, false});
    }
  }
  generate_ssd_anchors(pose_detection_anchor_options(), m->anchors);
  m->decode.min_score_thresh = options.min_detection_score;
  m->decoded.reserve(m->anchors.size());
  m->kept.reserve(m->anchors.size());
  m->scratch.reserve(m->anchors.size());
  m->detector_crop.output_width = m->detector_crop.output_height = k_detector_size;
  m->detector_crop.range_min = -1.f;
  m->detector_crop.range_max = 1.f;
  m->detector_crop.border = crop_border::zero;
  m->landmark_crop.output_width = m->landmark_crop.output_height = k_landmark_size;
  m->landmark_crop.range_min = 0.f;
  m->landmark_crop.range_max = 1.f;
  m->landmark_crop.border = crop_border::replicate;
  m->detector_crop.sampling = m->landmark_crop.sampling = options.sampling;
  if (options.low_light) m->detector.lift = m->landmark.lift = &k_low_light;
  out.reset(new pose_pipeline(std::move(m)));
  return {};
}

pose_result pose_pipeline::process(const image_view& image, landmark_frame& out) {
  impl& m = *impl_;
  m.timings = {};
  m.error.clear();
  m.ran_detector = false;
  m.presence = 0.f;
  out.set(frame_part::pose, false);
  out.set(frame_part::pose_world, false);
  if (image.data == nullptr || image.width <= 0 || image.height <= 0) {
    m.error = "pose_pipeline: empty image";
    return pose_result::error;
  }
  try {
    impl::person_state& ps = *m.st;
    normalized_rect r = ps.roi;
    if (!ps.seeded && (!ps.has_roi || m.options.static_images)) {
      m.ran_detector = true;
      ps.has_roi = false;
      if (!m.detect(image, r)) return m.error.empty() ? pose_result::not_found : pose_result::error;
    }
    ps.seeded = false;
    ps.used_roi = r;
    const bool smoothing = m.options.smoothing != pose_smoothing::none && !m.options.static_images;
    if (!m.landmarks(image, r, out.t, smoothing, out)) {
      ps.has_roi = false;  // lost: the next frame runs the detector
      m.reset_smoothing();
      return m.error.empty() ? pose_result::not_found : pose_result::error;
    }
  } catch (const Ort::Exception& ex) {
    m.st->has_roi = false;
    m.st->seeded = false;
    m.error = std::string("pose_pipeline: ONNX Runtime: ") + ex.what();
    return pose_result::error;
  }
  out.set(frame_part::pose, true);
  out.set(frame_part::pose_world, true);
  return pose_result::found;
}

void pose_pipeline::reset() {
  impl_->st->has_roi = false;
  impl_->st->seeded = false;
  impl_->reset_smoothing();
}

void pose_pipeline::select_person(int person) {
  impl_->st = &impl_->people[std::clamp(person, 0, k_max_people - 1)];
}

int pose_pipeline::detect_people(const image_view& image, int max, normalized_rect* out_rois,
                                 float* out_scores, float* out_anchors) {
  impl& m = *impl_;
  m.timings = {};
  m.error.clear();
  m.ran_detector = true;
  if (image.data == nullptr || image.width <= 0 || image.height <= 0) {
    m.error = "pose_pipeline: empty image";
    return -1;
  }
  max = std::clamp(max, 1, k_max_people);
  try {
    return m.detect_all(image, max, out_rois, out_scores, out_anchors);
  } catch (const Ort::Exception& ex) {
    m.error = std::string("pose_pipeline: ONNX Runtime: ") + ex.what();
    return -1;
  }
}

void pose_pipeline::start_track(const normalized_rect& roi) {
  impl::person_state& ps = *impl_->st;
  ps.roi = roi;
  ps.has_roi = true;
  ps.seeded = true;
  impl_->reset_smoothing();
}

const normalized_rect& pose_pipeline::tracked_roi() const { return impl_->st->roi; }
const normalized_rect& pose_pipeline::last_roi() const { return impl_->st->used_roi; }
bool pose_pipeline::tracking() const { return impl_->st->has_roi; }
float pose_pipeline::last_presence() const { return impl_->presence; }
bool pose_pipeline::last_ran_detector() const { return impl_->ran_detector; }
const pose_timings& pose_pipeline::last_timings() const { return impl_->timings; }
bool pose_pipeline::refines_from_heatmap() const { return impl_->has_heatmap; }
const std::string& pose_pipeline::last_error() const { return impl_->error; }

}  // namespace avatarmap
