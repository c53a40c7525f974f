// face_pipeline: MediaPipe's face mesh graph around face_detection_short_range and
// face_landmark_with_attention (or face_landmark) under ONNX Runtime. Mirrors
// face_landmark_front_cpu.pbtxt (FaceDetection -> FaceDetectionFrontDetectionToRoi ->
// FaceLandmarkCpu -> FaceLandmarkLandmarksToRoi) and, with a body, Holistic's
// face_landmarks_from_pose_cpu.pbtxt (FaceLandmarksFromPoseToRecropRoi ->
// FaceDetectionShortRangeByRoi -> FaceDetectionFrontDetectionsToRoi), without the smoothing
// filters. Holistic re-runs the detector in the body's region on every frame and keeps the
// tracked region while it agrees (RoiTrackingCalculator); here the detector runs only to
// acquire, and a tracked region whose centre leaves the body's face region is dropped.
#include "avatarmap/capture/face_pipeline.hpp"

#include <onnxruntime_cxx_api.h>

#include <array>
#include <chrono>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "ort_model.hpp"

namespace avatarmap {

namespace {

constexpr int k_detector_boxes = 896;
constexpr int k_detector_coords = 16;
// face_landmark_with_attention's outputs, in the model's order: mesh 468 x 3, lips 80 x 2,
// left eye 71 x 2, right eye 71 x 2, left iris 5 x 2, right iris 5 x 2, face flag.
constexpr int k_attention_flag_output = 6;

}  // namespace

struct face_pipeline::impl {
  face_pipeline_options options;
  bound_model detector;  // outputs: boxes [896 x 16], scores [896]
  bound_model mesh;      // outputs: landmarks [468 x 3], face flag [1]; or the attention ones
  face_mesh_model model = face_mesh_model::attention;
  int points = k_face_mesh_iris_count;
  std::string note;
  std::array<float, k_face_mesh_iris_count * 3> refined{};  // attention outputs assembled
  std::vector<ssd_anchor> anchors;
  detection_decode_options decode;
  std::vector<detection> decoded;
  std::vector<detection> kept;
  std::vector<int> scratch;
  crop_options detector_crop;
  crop_options mesh_crop;

  bool has_roi = false;
  normalized_rect roi;  // tracked region for the next frame
  normalized_rect used_roi;
  normalized_rect search_region;
  detection best;
  // Centre of the body's face region on the previous frame (follow_body_motion).
  bool has_body_center = false;
  float body_center_x = 0.f, body_center_y = 0.f;
  double missed_at = -1.0;  // when the last search found no face (-1: it did, or none yet)
  // Several people (select_person()): the tracked state above (has_roi .. missed_at) is the
  // selected person's; the others' wait here (small: swapped in and out).
  struct person_state {
    bool has_roi = false;
    normalized_rect roi, used_roi;
    bool has_body_center = false;
    float body_center_x = 0.f, body_center_y = 0.f;
    double missed_at = -1.0;
  };
  std::array<person_state, k_max_people> parked{};
  int person = 0;
  void swap_person(person_state& p) {
    std::swap(has_roi, p.has_roi);
    std::swap(roi, p.roi);
    std::swap(used_roi, p.used_roi);
    std::swap(has_body_center, p.has_body_center);
    std::swap(body_center_x, p.body_center_x);
    std::swap(body_center_y, p.body_center_y);
    std::swap(missed_at, p.missed_at);
  }
  float presence = 0.f;
  bool ran_detector = false;
  face_acquisition acquisition = face_acquisition::none;
  face_timings timings;
  std::string error;

  // Runs the detector on `region` (the whole image or the body's face region); false when no
  // face is found. `keypoint_roi`: Holistic's keypoint-box region, else the front graph's.
  bool detect(const image_view& image, const normalized_rect& region, bool keypoint_roi,
              normalized_rect& out_roi) {
    const auto t0 = std::chrono::steady_clock::now();
    ran_detector = true;
    search_region = region;
    crop_transform tr;
    if (!detector.crop_input(image, region, detector_crop, &tr)) {
      // A degenerate body region (e.g. all face points on one spot) is not an error.
      if (keypoint_roi) return false;
      error = "face detector: the image could not be cropped";
      return false;
    }
    const auto ti = std::chrono::steady_clock::now();
    detector.run();
    timings.detector_inference_ms = ms_since(ti);
    decode_detections(detector.outputs[0].data(), detector.outputs[1].data(), anchors.data(),
                      decode, decoded);
    weighted_non_max_suppression(decoded, options.nms_iou_threshold, 1, kept, scratch);
    bool found = !kept.empty();
    if (found) {
      best = project_detection(tr, kept[0]);
      out_roi = keypoint_roi ? face_detection_keypoints_to_roi(best, image.width, image.height)
                             : face_detection_to_roi(best, image.width, image.height);
    }
    timings.detector_ms = ms_since(t0);
    return found;
  }

  // Runs the mesh on `r`; false when the face is not present.
  bool landmarks(const image_view& image, const normalized_rect& r, landmark_frame& out) {
    const auto t0 = std::chrono::steady_clock::now();
    crop_transform tr;
    if (!mesh.crop_input(image, r, mesh_crop, &tr)) {
      error = "face mesh: the region could not be cropped";
      return false;
    }
    const auto ti = std::chrono::steady_clock::now();
    mesh.run();
    timings.mesh_inference_ms = ms_since(ti);
    // TensorsToFloats with SIGMOID, then ThresholdingCalculator (face_landmark_cpu.pbtxt).
    const bool attention = model == face_mesh_model::attention;
    presence = sigmoid(mesh.outputs[attention ? k_attention_flag_output : 1][0]);
    if (!(presence >= options.min_presence)) {
      timings.mesh_ms = ms_since(t0);
      return false;
    }
    const float* raw = mesh.outputs[0].data();
    if (attention) {
      refine_face_mesh(raw, mesh.outputs[1].data(), mesh.outputs[2].data(), mesh.outputs[3].data(),
                       mesh.outputs[4].data(), mesh.outputs[5].data(), refined.data());
      raw = refined.data();
    }
    for (int i = 0; i < points; ++i) {
      const float* p = raw + i * 3;
      const crop_point q = project_to_image(tr, {p[0], p[1], p[2]});
      avatarmap::landmark& l = out.face[i];
      l.x = q.x;
      l.y = q.y;
      l.z = q.z;
      l.visibility = 1.f;
      l.presence = 1.f;
    }
    has_roi = face_landmarks_to_roi(out.face.data(), points, image.width, image.height, roi);
    timings.mesh_ms = ms_since(t0);
    return true;
  }
};

face_pipeline::face_pipeline(std::unique_ptr<impl> p) : impl_(std::move(p)) {}
face_pipeline::~face_pipeline() = default;

status face_pipeline::create(const face_pipeline_options& options,
                             std::unique_ptr<face_pipeline>& out) {
  out.reset();
  if (const std::string e = check_pipeline_options("face_pipeline", options.intra_op_threads,
                                                   options.min_detection_score,
                                                   options.nms_iou_threshold, options.min_presence);
      !e.empty())
    return status::error(e);
  if (options.model != face_mesh_model::attention && options.model != face_mesh_model::mesh)
    return status::error("face_pipeline: model must be attention or mesh");
  if (!(options.pose_region_scale > 0.f && options.pose_region_scale <= 100.f))
    return status::error("face_pipeline: pose_region_scale must be in (0, 100]");
  if (!(options.retry_after_miss_seconds >= 0.0) ||
      !std::isfinite(options.retry_after_miss_seconds))
    return status::error("face_pipeline: retry_after_miss_seconds must be finite and >= 0");
  const std::string dir = options.models_dir.empty() ? "." : options.models_dir;
  const std::string det_path =
      dir + "/" + model_file_name("face_detection_short_range", options.precision);
  std::unique_ptr<impl> m(new impl());
  m->options = options;
  m->model = options.model;
  std::string mesh_path;
  if (options.model == face_mesh_model::attention) {
    mesh_path = dir + "/" + model_file_name("face_landmark_with_attention", options.precision);
    // The face mesh stays float in the int8 set (docs/capture.md "int8 models"), and the
    // attention model has no int8 file: int8 runs its float one.
    if (options.precision != model_precision::float32 && !std::ifstream(mesh_path).good())
      mesh_path =
          dir + "/" + model_file_name("face_landmark_with_attention", model_precision::float32);
    if (!std::ifstream(mesh_path).good()) {
      m->note = "face: " + mesh_path +
                " not found, using the 468-point mesh without irises (scripts/"
                "prepare_capture.sh converts the attention model)";
      m->model = face_mesh_model::mesh;
    }
  }
  if (m->model == face_mesh_model::mesh)
    mesh_path = dir + "/" + model_file_name("face_landmark", options.precision);
  m->points = m->model == face_mesh_model::attention ? k_face_mesh_iris_count : k_face_mesh_count;
  for (const std::string& p : {det_path, mesh_path})
    if (!std::ifstream(p).good())
      return status::io_error("face_pipeline: cannot open " + p +
                              missing_model_hint(options.precision));

  // Both sessions at once (start-up, model_cache.hpp); an ORT error names its model.
  std::string e;
  try {
    const Ort::SessionOptions so =
        make_session_options(options.intra_op_threads, options.allow_spinning);
    e = load_in_parallel(
        [&] {
          return with_model_name(det_path, [&] {
            return m->detector.load(det_path, so,
                                    {1, k_face_detector_size, k_face_detector_size, 3},
                                    {k_detector_boxes * k_detector_coords, k_detector_boxes});
          });
        },
        [&] {
          return with_model_name(mesh_path, [&] {
            if (m->model == face_mesh_model::attention)
              return m->mesh.load_in_order(
                  mesh_path, so, {1, k_face_mesh_size, k_face_mesh_size, 3},
                  {k_face_mesh_count * 3, k_face_refined_lips * 2, k_face_refined_eye * 2,
                   k_face_refined_eye * 2, k_face_refined_iris * 2, k_face_refined_iris * 2, 1});
            return m->mesh.load(mesh_path, so, {1, k_face_mesh_size, k_face_mesh_size, 3},
                                {k_face_mesh_count * 3, 1});
          });
        });
  } catch (const Ort::Exception& ex) {
    return status::parse_error("face_pipeline: ONNX Runtime: " + std::string(ex.what()));
  }
  if (!e.empty()) return status::parse_error("face_pipeline: " + e);
  generate_ssd_anchors(face_detection_anchor_options(), m->anchors);
  m->decode = face_detection_decode_options(options.min_detection_score);
  m->decoded.reserve(m->anchors.size());
  m->kept.reserve(m->anchors.size());
  m->scratch.reserve(m->anchors.size());
  // face_detection.pbtxt: ImageToTensor keep_aspect_ratio, [-1, 1], BORDER_ZERO.
  m->detector_crop.output_width = m->detector_crop.output_height = k_face_detector_size;
  m->detector_crop.range_min = -1.f;
  m->detector_crop.range_max = 1.f;
  m->detector_crop.keep_aspect_ratio = true;
  m->detector_crop.border = crop_border::zero;
  // face_landmark_cpu.pbtxt: ImageToTensor [0, 1], default border (replicate), no
  // keep_aspect_ratio (the regions are square in pixels anyway).
  m->mesh_crop.output_width = m->mesh_crop.output_height = k_face_mesh_size;
  m->mesh_crop.range_min = 0.f;
  m->mesh_crop.range_max = 1.f;
  m->mesh_crop.keep_aspect_ratio = false;
  m->mesh_crop.border = crop_border::replicate;
  m->detector_crop.sampling = m->mesh_crop.sampling = options.sampling;
  if (options.low_light) m->detector.lift = m->mesh.lift = &k_low_light;
  out.reset(new face_pipeline(std::move(m)));
  return {};
}

face_result face_pipeline::process(const image_view& image, const landmark_frame* body,
                                   landmark_frame& out, double t) {
  impl& m = *impl_;
  const double now = std::isfinite(t) ? t : -1.0;
  m.timings = {};
  m.error.clear();
  m.ran_detector = false;
  m.acquisition = face_acquisition::none;
  m.presence = 0.f;
  // Read the body before `out` (which may be *body) is touched.
  const bool use_body = m.options.roi_source != face_roi_source::detector && body != nullptr &&
                        body->has(frame_part::pose);
  normalized_rect body_region;
  const bool has_body_region =
      use_body && face_region_from_pose(body->pose.data(), image.width, image.height, body_region,
                                        m.options.pose_region_scale);
  out.set(frame_part::face, false);
  out.face_count = 0;
  if (image.data == nullptr || image.width <= 0 || image.height <= 0) {
    m.error = "face_pipeline: empty image";
    return face_result::error;
  }
  try {
    // The body moved the head since the last frame: move the tracked region with it (the
    // mesh is trained on regions about its own landmarks, and a fast head leaves them).
    if (m.has_roi && has_body_region && m.has_body_center && m.options.follow_body_motion) {
      m.roi.x_center += body_region.x_center - m.body_center_x;
      m.roi.y_center += body_region.y_center - m.body_center_y;
    }
    m.has_body_center = has_body_region;
    m.body_center_x = body_region.x_center;
    m.body_center_y = body_region.y_center;
    // A tracked region that has left the body's face region follows something else.
    if (m.has_roi && has_body_region &&
        !normalized_rect_contains(body_region, m.roi.x_center, m.roi.y_center, image.width,
                                  image.height))
      m.has_roi = false;
    normalized_rect r = m.roi;
    m.acquisition = face_acquisition::tracked;
    if (!m.has_roi || m.options.static_images) {
      m.has_roi = false;
      // A search that found nothing a moment ago: wait (retry_after_miss_seconds).
      if (!m.options.static_images && now >= 0.0 && m.missed_at >= 0.0 && now >= m.missed_at &&
          now - m.missed_at < m.options.retry_after_miss_seconds) {
        m.acquisition = face_acquisition::none;
        return face_result::not_found;
      }
      m.missed_at = now;  // until the mesh below accepts what the search found
      bool found = false;
      if (has_body_region) {
        m.acquisition = face_acquisition::detector_region;
        found = m.detect(image, body_region, true, r);
      } else if (m.options.roi_source != face_roi_source::pose) {
        m.acquisition = face_acquisition::detector_image;
        found = m.detect(image, normalized_rect{}, false, r);
      }
      if (!found) {
        m.acquisition = face_acquisition::none;
        return m.error.empty() ? face_result::not_found : face_result::error;
      }
    }
    m.used_roi = r;
    if (!m.landmarks(image, r, out)) {
      m.has_roi = false;  // lost: the next frame acquires again
      return m.error.empty() ? face_result::not_found : face_result::error;
    }
  } catch (const Ort::Exception& ex) {
    m.has_roi = false;
    m.error = std::string("face_pipeline: ONNX Runtime: ") + ex.what();
    return face_result::error;
  }
  m.missed_at = -1.0;
  out.face_count = m.points;
  out.set(frame_part::face, true);
  return face_result::found;
}

void face_pipeline::reset() {
  impl_->has_roi = false;
  impl_->has_body_center = false;
  impl_->missed_at = -1.0;
}
void face_pipeline::select_person(int person) {
  impl& m = *impl_;
  person = std::clamp(person, 0, k_max_people - 1);
  if (person == m.person) return;
  m.swap_person(m.parked[m.person]);  // park the current person's state
  m.swap_person(m.parked[person]);    // and take the new one's
  m.person = person;
}
face_mesh_model face_pipeline::mesh_model() const { return impl_->model; }
int face_pipeline::mesh_points() const { return impl_->points; }
const std::string& face_pipeline::note() const { return impl_->note; }
const normalized_rect& face_pipeline::last_roi() const { return impl_->used_roi; }
bool face_pipeline::tracking() const { return impl_->has_roi; }
const normalized_rect& face_pipeline::last_search_region() const { return impl_->search_region; }
float face_pipeline::last_presence() const { return impl_->presence; }
bool face_pipeline::last_ran_detector() const { return impl_->ran_detector; }
const detection& face_pipeline::last_detection() const { return impl_->best; }
face_acquisition face_pipeline::last_acquisition() const { return impl_->acquisition; }
const face_timings& face_pipeline::last_timings() const { return impl_->timings; }
const std::string& face_pipeline::last_error() const { return impl_->error; }

}  // namespace avatarmap
