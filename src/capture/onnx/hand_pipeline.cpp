// hand_pipeline: MediaPipe's hand graph around palm_detection and hand_landmark under ONNX
// Runtime. Mirrors hand_landmark_tracking_cpu.pbtxt: PalmDetectionCpu (only while fewer hands
// are tracked than wanted) -> PalmDetectionDetectionToRoi -> AssociationNormRect against the
// tracked regions -> HandLandmarkCpu per region -> HandLandmarkLandmarksToRoi (tracking), plus
// Holistic's hand regions from the body's landmarks (without its hand_recrop model).
#include "avatarmap/capture/hand_pipeline.hpp"

#include <onnxruntime_cxx_api.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "ort_model.hpp"

namespace avatarmap {

namespace {

const char* complexity_name(hand_model_complexity c) {
  return c == hand_model_complexity::lite ? "lite" : "full";
}

constexpr int k_palm_size = 192;
constexpr int k_palm_boxes = 2016;
constexpr int k_palm_coords = 18;
constexpr int k_landmark_size = 224;
constexpr int k_max_hands = 2;
// TensorsToLandmarks' normalize_z for the hand model: z / 224 / 0.4.
constexpr float k_normalize_z = 0.4f;
// hand_landmark outputs, in the model's order (SplitTensorVector ranges 0..4 of
// hand_landmark_cpu.pbtxt): landmarks [1, 63], hand flag [1, 1], handedness [1, 1], world
// landmarks [1, 63]. Two pairs share an element count, so they are bound by position.
constexpr int k_out_landmarks = 0;
constexpr int k_out_presence = 1;
constexpr int k_out_handedness = 2;
constexpr int k_out_world = 3;

float sq_distance_px(float ax, float ay, float bx, float by, int w, int h) {
  const float dx = (ax - bx) * static_cast<float>(w), dy = (ay - by) * static_cast<float>(h);
  return dx * dx + dy * dy;
}

}  // namespace

struct hand_pipeline::impl {
  // A region to run the landmark model on this frame.
  struct candidate {
    normalized_rect roi;
    hand_roi_origin origin = hand_roi_origin::palm;
    bool side_known = false;  // from the body: `side` is the pose wrist's
    body_side side = body_side::left;
  };
  // A hand carried into the next frame.
  struct slot {
    normalized_rect roi;
    bool side_known = false;
    body_side side = body_side::left;
    bool has_wrist = false;  // the body's wrist of this side when the region was made
    float wrist_x = 0.f, wrist_y = 0.f;
  };

  // The body's wrist of `side` when it is seen well enough to follow.
  bool body_wrist(const landmark_frame* body, body_side side, float& x, float& y) const {
    if (body == nullptr || !body->has(frame_part::pose)) return false;
    const landmark& w =
        body->pose[idx(pose_landmark::left_wrist) + (side == body_side::left ? 0 : 1)];
    if (!(w.visibility >= options.pose_roi.min_wrist_visibility) || !std::isfinite(w.x) ||
        !std::isfinite(w.y))
      return false;
    x = w.x;
    y = w.y;
    return true;
  }

  hand_pipeline_options options;
  bound_model palm;        // outputs: boxes [2016 x 18], scores [2016]
  bound_model hand_model;  // outputs by position: landmarks, presence, handedness, world
  std::vector<ssd_anchor> anchors;
  detection_decode_options decode;
  std::vector<detection> decoded;
  std::vector<detection> kept;
  std::vector<int> scratch;
  crop_options palm_crop;
  crop_options landmark_crop;

  std::array<slot, k_max_hands> slots{};
  int slot_count = 0;
  std::array<candidate, k_max_hands> candidates{};
  std::array<bool, k_max_hands> candidate_side_known{};
  std::array<hand_observation, k_max_hands> hands{};
  std::array<normalized_rect, k_max_hands> next_rois{};
  int hand_count = 0;
  // Per side (left, right): when its last region from the body held no hand (-1: never).
  std::array<double, 2> missed_at{-1.0, -1.0};
  // Several people (select_person()): the tracked state above (slots, slot_count, missed_at)
  // is the selected person's; the others' wait here (small: swapped in and out).
  struct person_state {
    std::array<slot, k_max_hands> slots{};
    int slot_count = 0;
    std::array<double, 2> missed_at{-1.0, -1.0};
  };
  std::array<person_state, k_max_people> parked{};
  int person = 0;
  void swap_person(person_state& p) {
    std::swap(slots, p.slots);
    std::swap(slot_count, p.slot_count);
    std::swap(missed_at, p.missed_at);
  }
  double now = -1.0;  // this frame's time (process()'s t)
  bool ran_palm = false;
  hand_timings timings;
  std::string error;

  // Runs the palm detector on the whole image; the hand regions of up to `max` palms, best
  // first, into `out`. Returns their number, or -1 on a crop failure.
  int detect_palms(const image_view& image, int max,
                   std::array<normalized_rect, k_max_hands>& out) {
    const auto t0 = std::chrono::steady_clock::now();
    ran_palm = true;
    crop_transform tr;
    // The whole image, letterboxed.
    if (!palm.crop_input(image, normalized_rect{}, palm_crop, &tr)) {
      error = "hand_pipeline: palm detector: the image could not be cropped";
      return -1;
    }
    const auto ti = std::chrono::steady_clock::now();
    palm.run();
    timings.palm_inference_ms = ms_since(ti);
    decode_detections(palm.outputs[0].data(), palm.outputs[1].data(), anchors.data(), decode,
                      decoded);
    weighted_non_max_suppression(decoded, options.nms_iou_threshold, max, kept, scratch);
    int n = 0;
    for (const detection& k : kept) {
      if (n >= max) break;
      // DetectionLetterboxRemoval: detector-input fractions -> tensor pixels -> image.
      detection d = k;
      const crop_point p0 = project_to_image(tr, {d.xmin * k_palm_size, d.ymin * k_palm_size, 0});
      const crop_point p1 = project_to_image(
          tr, {(d.xmin + d.width) * k_palm_size, (d.ymin + d.height) * k_palm_size, 0});
      d.xmin = p0.x;
      d.ymin = p0.y;
      d.width = p1.x - p0.x;
      d.height = p1.y - p0.y;
      for (int i = 0; i < d.keypoint_count; ++i) {
        const crop_point q = project_to_image(
            tr, {d.keypoints[2 * i] * k_palm_size, d.keypoints[2 * i + 1] * k_palm_size, 0});
        d.keypoints[2 * i] = q.x;
        d.keypoints[2 * i + 1] = q.y;
      }
      out[n++] = palm_detection_to_roi(d, image.width, image.height);
    }
    timings.palm_ms = ms_since(t0);
    return n;
  }

  // Runs the landmark model on `r` into `h` and the next region into `next`; false when the
  // hand is not present (or on a crop failure, with `error` set).
  bool landmarks(const image_view& image, const normalized_rect& r, hand_observation& h,
                 normalized_rect& next) {
    const auto t0 = std::chrono::steady_clock::now();
    ++timings.landmark_runs;
    crop_transform tr;
    if (!hand_model.crop_input(image, r, landmark_crop, &tr)) {
      error = "hand_pipeline: hand landmarks: the region could not be cropped";
      return false;
    }
    const auto ti = std::chrono::steady_clock::now();
    hand_model.run();
    timings.landmark_inference_ms += ms_since(ti);
    // The model's hand flag and handedness are probabilities already (MediaPipe applies no
    // activation to either).
    const float presence = hand_model.outputs[k_out_presence][0];
    bool ok = presence >= options.min_presence;
    if (ok) {
      h.presence = presence;
      h.roi = r;
      h.handedness_score = hand_model.outputs[k_out_handedness][0];
      const float* raw = hand_model.outputs[k_out_landmarks].data();
      const float* world = hand_model.outputs[k_out_world].data();
      for (int i = 0; i < k_hand_landmark_count; ++i) {
        const crop_point q = project_to_image(tr, {raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]});
        h.image[i] = {q.x, q.y, q.z / k_normalize_z, 1.f, 1.f};
      }
      // WorldLandmarkProjection: the world points come in the region's frame; rotate them
      // back by the region's rotation (about z, metres unchanged).
      const float c = std::cos(r.rotation), s = std::sin(r.rotation);
      for (int i = 0; i < k_hand_landmark_count; ++i) {
        const float* p = world + 3 * i;
        h.world[i] = {c * p[0] - s * p[1], s * p[0] + c * p[1], p[2], 1.f, 1.f};
      }
      ok = hand_landmarks_to_roi(h.image.data(), image.width, image.height, next);
    }
    timings.landmark_ms += ms_since(t0);
    return ok;
  }

  bool overlaps_any(const normalized_rect& r, int n, const image_view& image) const {
    for (int i = 0; i < n; ++i)
      if (normalized_rect_iou(r, candidates[i].roi, image.width, image.height) >
          options.max_overlap)
        return true;
    return false;
  }

  // Squared pixel distance from hand h's wrist to the pose wrist of its side (infinite when
  // unknown).
  float wrist_gap(const hand_observation& h, const landmark_frame* body,
                  const image_view& image) const {
    if (!body || !body->has(frame_part::pose)) return INFINITY;
    const landmark& w =
        body->pose[idx(pose_landmark::left_wrist) + (h.side == body_side::left ? 0 : 1)];
    if (!std::isfinite(w.x) || !std::isfinite(w.y)) return INFINITY;
    return sq_distance_px(h.image[0].x, h.image[0].y, w.x, w.y, image.width, image.height);
  }

  // Whether `side`'s region from the body held no hand less than retry_after_miss_seconds
  // ago (a clock that went back, or no clock, never skips).
  bool recently_missed(body_side side) const {
    const double at = missed_at[side == body_side::left ? 0 : 1];
    return !options.static_images && now >= 0.0 && at >= 0.0 && now >= at &&
           now - at < options.retry_after_miss_seconds;
  }

  hand_result run(const image_view& image, const landmark_frame* body, landmark_frame& out) {
    const bool has_body = body != nullptr && body->has(frame_part::pose);
    const bool use_pose = options.roi_source == hand_roi_source::pose ||
                          (options.roi_source == hand_roi_source::automatic && has_body);
    if (options.static_images) slot_count = 0;
    const int max = options.max_hands;

    // 1. Tracked hands. With the body, a tracked hand whose pose wrist (when visible) has left
    //    its region is dropped, so that it is found again from the body (Holistic checks its
    //    tracked region against the body's likewise).
    int n = 0;
    for (int i = 0; i < slot_count && n < max; ++i) {
      slot& s = slots[i];
      // Follow the body: move the tracked region by the body's wrist motion since it was
      // made (at low frame rates a hand moves out of last frame's region).
      float wx = 0.f, wy = 0.f;
      if (options.follow_body_motion && s.has_wrist && body_wrist(body, s.side, wx, wy)) {
        s.roi.x_center += wx - s.wrist_x;
        s.roi.y_center += wy - s.wrist_y;
      }
      if (use_pose && has_body && s.side_known) {
        const landmark& w =
            body->pose[idx(pose_landmark::left_wrist) + (s.side == body_side::left ? 0 : 1)];
        if (w.visibility >= options.pose_roi.min_wrist_visibility &&
            !normalized_rect_contains(s.roi, w.x, w.y, image.width, image.height))
          continue;
      }
      candidates[n++] = {s.roi, hand_roi_origin::tracked, s.side_known, s.side};
    }

    // 2. New hands, from the body (each side not yet tracked) or from the palm detector
    //    (at most once). A new region overlapping a tracked one is the same hand: dropped.
    if (n < max) {
      if (use_pose) {
        for (body_side side : {body_side::left, body_side::right}) {
          if (n >= max || !has_body) break;
          bool tracked = false;
          for (int i = 0; i < n; ++i)
            tracked = tracked || (candidates[i].side_known && candidates[i].side == side);
          normalized_rect r;
          if (tracked || recently_missed(side) ||
              !hand_roi_from_pose(*body, side, image.width, image.height, r, options.pose_roi))
            continue;
          if (overlaps_any(r, n, image)) continue;
          candidates[n++] = {r, hand_roi_origin::pose, true, side};
        }
      } else {
        std::array<normalized_rect, k_max_hands> found{};
        const int k = detect_palms(image, max, found);
        if (k < 0) return hand_result::error;
        for (int i = 0; i < k && n < max; ++i)
          if (!overlaps_any(found[i], n, image))
            candidates[n++] = {found[i], hand_roi_origin::palm, false, body_side::left};
      }
    }

    // 3. Landmarks on each region.
    hand_count = 0;
    for (int i = 0; i < n; ++i) {
      hand_observation& h = hands[hand_count];
      const bool from_body = candidates[i].origin == hand_roi_origin::pose;
      const int side_index = candidates[i].side == body_side::left ? 0 : 1;
      if (from_body) missed_at[side_index] = now;  // until a hand is found below
      if (!landmarks(image, candidates[i].roi, h, next_rois[hand_count])) {
        if (!error.empty()) return hand_result::error;
        continue;
      }
      // A region from the body is loose (Holistic tightens it with its hand_recrop model):
      // one more run on the region of the landmarks just found plays that part.
      if (candidates[i].origin == hand_roi_origin::pose && options.refine_pose_roi) {
        const normalized_rect refined = next_rois[hand_count];
        if (!landmarks(image, refined, h, next_rois[hand_count])) {
          if (!error.empty()) return hand_result::error;
          continue;
        }
      }
      if (from_body) missed_at[side_index] = -1.0;
      h.origin = candidates[i].origin;
      candidate_side_known[hand_count] = candidates[i].side_known;
      const body_side model_side = hand_side_from_handedness(
          h.handedness_score, options.mirrored_input, &h.left_probability);
      h.side = candidates[i].side_known ? candidates[i].side : model_side;
      ++hand_count;
    }

    // 4. Two hands on one: the same hand seen twice (tracked regions drifting together).
    if (hand_count == 2 && normalized_rect_iou(next_rois[0], next_rois[1], image.width,
                                               image.height) > options.max_overlap) {
      int drop = hands[1].presence > hands[0].presence ? 0 : 1;
      if (candidate_side_known[0] && candidate_side_known[1]) {
        drop = wrist_gap(hands[0], body, image) > wrist_gap(hands[1], body, image) ? 0 : 1;
      }
      if (drop == 0) {
        hands[0] = hands[1];
        next_rois[0] = next_rois[1];
        candidate_side_known[0] = candidate_side_known[1];
      }
      hand_count = 1;
    }

    // 5. One hand per side: on a clash, a side known from the body wins, else the more
    //    certain handedness; the other hand takes the other side.
    if (hand_count == 2 && hands[0].side == hands[1].side) {
      int keep;
      if (candidate_side_known[0] != candidate_side_known[1]) {
        keep = candidate_side_known[0] ? 0 : 1;
      } else {
        keep = std::fabs(hands[0].left_probability - 0.5f) >=
                       std::fabs(hands[1].left_probability - 0.5f)
                   ? 0
                   : 1;
      }
      hands[1 - keep].side =
          hands[keep].side == body_side::left ? body_side::right : body_side::left;
    }

    // 6. Output and the regions tracked into the next frame.
    slot_count = 0;
    for (int i = 0; i < hand_count; ++i) {
      const hand_observation& h = hands[i];
      const bool left = h.side == body_side::left;
      auto& pts = left ? out.left_hand : out.right_hand;
      auto& wpts = left ? out.left_hand_world : out.right_hand_world;
      pts = h.image;
      wpts = h.world;
      out.set(left ? frame_part::left_hand : frame_part::right_hand, true);
      out.set(left ? frame_part::left_hand_world : frame_part::right_hand_world, true);
      slot& sl = slots[slot_count++];
      sl = {next_rois[i], candidate_side_known[i], h.side, false, 0.f, 0.f};
      sl.has_wrist = body_wrist(body, h.side, sl.wrist_x, sl.wrist_y);
    }
    return hand_count > 0 ? hand_result::found : hand_result::not_found;
  }
};

hand_pipeline::hand_pipeline(std::unique_ptr<impl> p) : impl_(std::move(p)) {}
hand_pipeline::~hand_pipeline() = default;

status hand_pipeline::create(const hand_pipeline_options& options,
                             std::unique_ptr<hand_pipeline>& out) {
  out.reset();
  if (options.max_hands < 1 || options.max_hands > k_max_hands)
    return status::error("hand_pipeline: max_hands must be 1 or 2");
  if (const std::string e = check_pipeline_options("hand_pipeline", options.intra_op_threads,
                                                   options.min_detection_score,
                                                   options.nms_iou_threshold, options.min_presence);
      !e.empty())
    return status::error(e);
  if (!(options.max_overlap > 0.f && options.max_overlap <= 1.f))
    return status::error("hand_pipeline: max_overlap must be in (0, 1]");
  if (!(options.retry_after_miss_seconds >= 0.0) ||
      !std::isfinite(options.retry_after_miss_seconds))
    return status::error("hand_pipeline: retry_after_miss_seconds must be finite and >= 0");
  if (!(options.pose_roi.scale > 0.f) || !std::isfinite(options.pose_roi.scale) ||
      !std::isfinite(options.pose_roi.shift_y) ||
      !(options.pose_roi.min_wrist_visibility >= 0.f &&
        options.pose_roi.min_wrist_visibility <= 1.f))
    return status::error(
        "hand_pipeline: pose_roi needs scale > 0, a finite shift_y and min_wrist_visibility in "
        "[0, 1]");
  const std::string dir = options.models_dir.empty() ? "." : options.models_dir;
  const std::string palm_path =
      dir + "/" +
      model_file_name(std::string("palm_detection_") + complexity_name(options.complexity),
                      options.precision);
  const std::string lm_path =
      dir + "/" +
      model_file_name(std::string("hand_landmark_") + complexity_name(options.complexity),
                      options.precision);
  for (const std::string& p : {palm_path, lm_path})
    if (!std::ifstream(p).good())
      return status::io_error("hand_pipeline: cannot open " + p +
                              missing_model_hint(options.precision));

  std::unique_ptr<impl> m(new impl());
  m->options = options;
  // Both sessions at once (start-up, model_cache.hpp); an ORT error names its model.
  std::string e;
  try {
    const Ort::SessionOptions so =
        make_session_options(options.intra_op_threads, options.allow_spinning);
    e = load_in_parallel(
        [&] {
          return with_model_name(palm_path, [&] {
            return m->palm.load(palm_path, so, {1, k_palm_size, k_palm_size, 3},
                                {k_palm_boxes * k_palm_coords, k_palm_boxes});
          });
        },
        [&] {
          return with_model_name(lm_path, [&] {
            return m->hand_model.load_in_order(
                lm_path, so, {1, k_landmark_size, k_landmark_size, 3},
                {3 * k_hand_landmark_count, 1, 1, 3 * k_hand_landmark_count});
          });
        });
  } catch (const Ort::Exception& ex) {
    return status::parse_error("hand_pipeline: ONNX Runtime: " + std::string(ex.what()));
  }
  if (!e.empty()) return status::parse_error("hand_pipeline: " + e);
  generate_ssd_anchors(palm_detection_anchor_options(), m->anchors);
  m->decode = palm_detection_decode_options();
  m->decode.min_score_thresh = options.min_detection_score;
  m->decoded.reserve(m->anchors.size());
  m->kept.reserve(m->anchors.size());
  m->scratch.reserve(m->anchors.size());
  // palm_detection_cpu.pbtxt: 192x192, keep aspect, range [0, 1], BORDER_ZERO.
  m->palm_crop.output_width = m->palm_crop.output_height = k_palm_size;
  m->palm_crop.range_min = 0.f;
  m->palm_crop.range_max = 1.f;
  m->palm_crop.border = crop_border::zero;
  // hand_landmark_cpu.pbtxt: 224x224, keep aspect, range [0, 1], default border (replicate).
  m->landmark_crop.output_width = m->landmark_crop.output_height = k_landmark_size;
  m->landmark_crop.range_min = 0.f;
  m->landmark_crop.range_max = 1.f;
  m->landmark_crop.border = crop_border::replicate;
  m->palm_crop.sampling = m->landmark_crop.sampling = options.sampling;
  if (options.low_light) m->palm.lift = m->hand_model.lift = &k_low_light;
  out.reset(new hand_pipeline(std::move(m)));
  return {};
}

hand_result hand_pipeline::process(const image_view& image, const landmark_frame* body,
                                   landmark_frame& out, double t) {
  impl& m = *impl_;
  m.now = std::isfinite(t) ? t : -1.0;
  m.timings = {};
  m.error.clear();
  m.ran_palm = false;
  m.hand_count = 0;
  for (frame_part p : {frame_part::left_hand, frame_part::left_hand_world, frame_part::right_hand,
                       frame_part::right_hand_world})
    out.set(p, false);
  if (image.data == nullptr || image.width <= 0 || image.height <= 0) {
    m.error = "hand_pipeline: empty image";
    return hand_result::error;
  }
  hand_result r;
  try {
    r = m.run(image, body, out);
  } catch (const Ort::Exception& ex) {
    m.error = std::string("hand_pipeline: ONNX Runtime: ") + ex.what();
    r = hand_result::error;
  }
  if (r == hand_result::error) {
    m.slot_count = 0;
    m.hand_count = 0;
    for (frame_part p : {frame_part::left_hand, frame_part::left_hand_world, frame_part::right_hand,
                         frame_part::right_hand_world})
      out.set(p, false);
  }
  return r;
}

void hand_pipeline::reset() {
  impl_->slot_count = 0;
  impl_->missed_at = {-1.0, -1.0};
}
void hand_pipeline::select_person(int person) {
  impl& m = *impl_;
  person = std::clamp(person, 0, k_max_people - 1);
  if (person == m.person) return;
  m.swap_person(m.parked[m.person]);  // park the current person's state
  m.swap_person(m.parked[person]);    // and take the new one's
  m.person = person;
}
int hand_pipeline::hand_count() const { return impl_->hand_count; }
const hand_observation& hand_pipeline::hand(int i) const { return impl_->hands[i]; }
int hand_pipeline::tracked_count() const { return impl_->slot_count; }
bool hand_pipeline::last_ran_palm_detector() const { return impl_->ran_palm; }
const hand_timings& hand_pipeline::last_timings() const { return impl_->timings; }
const std::string& hand_pipeline::last_error() const { return impl_->error; }

}  // namespace avatarmap
