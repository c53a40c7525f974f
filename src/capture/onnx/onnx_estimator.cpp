// The "onnx" estimator backend: the body (pose_pipeline), then both hands (hand_pipeline) and
// the face (face_pipeline), each given the body found in the same frame so that their
// regions come from it when they are not tracked (MediaPipe Holistic's order).
#include "capture/onnx/onnx_estimator.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "avatarmap/capture/face_pipeline.hpp"
#include "avatarmap/capture/hand_pipeline.hpp"
#include "avatarmap/capture/pose_pipeline.hpp"
#include "capture/two_lanes.hpp"

namespace avatarmap {

namespace {

// Copies the parts `mask` (bits of frame_part) of `from` into `to`.
void copy_parts(const landmark_frame& from, std::uint32_t mask, landmark_frame& to) {
  auto copy = [&](frame_part p, const auto& src, auto& dst) {
    const std::uint32_t bit = 1u << static_cast<int>(p);
    if (!(mask & bit)) return;
    to.set(p, from.has(p));
    if (from.has(p)) dst = src;
  };
  copy(frame_part::left_hand, from.left_hand, to.left_hand);
  copy(frame_part::left_hand_world, from.left_hand_world, to.left_hand_world);
  copy(frame_part::right_hand, from.right_hand, to.right_hand);
  copy(frame_part::right_hand_world, from.right_hand_world, to.right_hand_world);
  if (mask & (1u << static_cast<int>(frame_part::face))) {
    to.set(frame_part::face, from.has(frame_part::face));
    to.face_count = from.face_count;
    if (from.has(frame_part::face))
      std::copy(from.face.begin(), from.face.begin() + from.face_count, to.face.begin());
  }
}

constexpr std::uint32_t k_hand_parts = (1u << static_cast<int>(frame_part::left_hand)) |
                                       (1u << static_cast<int>(frame_part::left_hand_world)) |
                                       (1u << static_cast<int>(frame_part::right_hand)) |
                                       (1u << static_cast<int>(frame_part::right_hand_world));
constexpr std::uint32_t k_face_parts = 1u << static_cast<int>(frame_part::face);

class onnx_estimator final : public estimator {
 public:
  onnx_estimator(std::unique_ptr<pose_pipeline> pose, std::unique_ptr<hand_pipeline> hands,
                 std::unique_ptr<face_pipeline> face, bool two_lanes, std::string description)
      : pose_(std::move(pose)),
        hands_(std::move(hands)),
        face_(std::move(face)),
        description_(std::move(description)) {
    if (two_lanes) lanes_ = std::make_unique<capture_detail::two_lanes>();
  }

  status estimate(const estimate_args& args, landmark_frame& out) override {
    for (std::string& e : task_error_) e.clear();
    out.clear();
    out.t = args.t;
    estimator_timings& tm = timings_;
    tm = {};
    if (!lanes_) {  // one lane: body, hands, face in turn, each into `out`
      run_body(args, out, tm);
      if (task_error_[0].empty()) run_hands(args, out, out, tm);
      if (task_error_[0].empty()) run_face(args, out, out, tm);
      return finish(tm);
    }
    run_body(args, out, tm);
    if (!task_error_[0].empty()) return finish(tm);
    // The hands and the face of this frame side by side, each into its own frame (both would
    // otherwise write `out.parts`), then merged.
    task_count_ = 0;
    add_side_tasks(args, out, tm);
    run_tasks();
    merge_side_parts(out);
    return finish(tm);
  }

  status estimate_pipelined(const estimate_args* in, landmark_frame& out, bool& ready) override {
    if (!lanes_) return estimator::estimate_pipelined(in, out, ready);
    ready = false;
    // One batch: the body of frame `in` (into slot cur_) beside the hands and face of the
    // frame before (slot prev, whose body is done).
    const int prev = cur_ ^ 1;
    task_count_ = 0;
    if (in) {
      slot_[cur_].clear();
      slot_[cur_].t = in->t;
      slot_timings_[cur_] = {};
      args_[cur_] = *in;
      tasks_[task_count_++] = {task_kind::body, &args_[cur_], &slot_[cur_], &slot_timings_[cur_]};
    }
    if (pending_) add_side_tasks(args_[prev], slot_[prev], slot_timings_[prev]);
    run_tasks();
    for (int i = 0; i < task_count_; ++i)
      if (!task_error_[i].empty()) return status::internal(task_error_[i]);
    if (pending_) {
      merge_side_parts(slot_[prev]);
      out = slot_[prev];
      timings_ = slot_timings_[prev];
      add_total(timings_);
      ready = true;
    }
    pending_ = in != nullptr;
    if (in) cur_ = prev;
    return {};
  }

  int pipeline_delay() const override { return lanes_ ? 1 : 0; }
  std::string describe() const override { return description_; }
  std::string_view name() const override { return "onnx"; }
  const estimator_timings* last_timings() const override { return &timings_; }

 private:
  enum class task_kind : std::uint8_t { body, hands, face };
  struct task {
    task_kind kind = task_kind::body;
    const estimate_args* args = nullptr;
    landmark_frame* frame = nullptr;  // body: written; hands, face: the body hint
    estimator_timings* timings = nullptr;
  };

  void add_side_tasks(const estimate_args& args, landmark_frame& frame, estimator_timings& tm) {
    // The longer task first: the other lane takes the face and then whatever is left.
    if (args.hands && hands_) tasks_[task_count_++] = {task_kind::hands, &args, &frame, &tm};
    if (args.face && face_) tasks_[task_count_++] = {task_kind::face, &args, &frame, &tm};
  }

  void run_tasks() {
    for (int i = 0; i < task_count_; ++i) task_error_[i].clear();
    auto run = [this](int i) {
      const task& k = tasks_[i];
      switch (k.kind) {
        case task_kind::body:
          run_body(*k.args, *k.frame, *k.timings, i);
          break;
        case task_kind::hands:
          run_hands(*k.args, *k.frame, side_[0], *k.timings, i);
          break;
        case task_kind::face:
          run_face(*k.args, *k.frame, side_[1], *k.timings, i);
          break;
      }
    };
    lanes_->run_batch(task_count_, run);
  }

  void merge_side_parts(landmark_frame& frame) {
    for (int i = 0; i < task_count_; ++i) {
      if (tasks_[i].frame != &frame) continue;
      if (tasks_[i].kind == task_kind::hands) copy_parts(side_[0], k_hand_parts, frame);
      if (tasks_[i].kind == task_kind::face) copy_parts(side_[1], k_face_parts, frame);
    }
  }

  // The work of a frame: its stages summed (with two lanes they overlap in time).
  static void add_total(estimator_timings& tm) {
    tm.total_ms = tm.pose_detector_ms + tm.pose_landmark_ms + tm.palm_detector_ms +
                  tm.hand_landmark_ms + tm.face_detector_ms + tm.face_mesh_ms;
  }

  status finish(estimator_timings& tm) {
    add_total(tm);
    for (int i = 0; i < 3; ++i)
      if (!task_error_[i].empty()) return status::internal(task_error_[i]);
    return {};
  }

  // The three stages; each writes its message to task_error_[slot] on failure.
  void run_body(const estimate_args& args, landmark_frame& out, estimator_timings& tm,
                int slot = 0) {
    task_error_[slot].clear();
    if (!args.body) return;
    if (pose_->process(args.image, out) == pose_result::error) {
      task_error_[slot] = pose_->last_error();
      return;
    }
    const pose_timings& pt = pose_->last_timings();
    tm.pose_detector_ms = pt.detector_ms;
    tm.pose_landmark_ms = pt.landmark_ms;
    tm.detector_runs += pose_->last_ran_detector();
  }
  void run_hands(const estimate_args& args, const landmark_frame& body_frame, landmark_frame& out,
                 estimator_timings& tm, int slot = 0) {
    task_error_[slot].clear();
    if (!args.hands || !hands_) return;
    const landmark_frame* body = body_frame.has(frame_part::pose) ? &body_frame : nullptr;
    if (hands_->process(args.image, body, out, args.t) == hand_result::error) {
      task_error_[slot] = hands_->last_error();
      return;
    }
    const hand_timings& ht = hands_->last_timings();
    tm.palm_detector_ms = ht.palm_ms;
    tm.hand_landmark_ms = ht.landmark_ms;
    tm.detector_runs += hands_->last_ran_palm_detector();
  }
  void run_face(const estimate_args& args, const landmark_frame& body_frame, landmark_frame& out,
                estimator_timings& tm, int slot = 0) {
    task_error_[slot].clear();
    if (!args.face || !face_) return;
    const landmark_frame* body = body_frame.has(frame_part::pose) ? &body_frame : nullptr;
    if (face_->process(args.image, body, out, args.t) == face_result::error) {
      task_error_[slot] = face_->last_error();
      return;
    }
    const face_timings& ft = face_->last_timings();
    tm.face_detector_ms = ft.detector_ms;
    tm.face_mesh_ms = ft.mesh_ms;
    tm.detector_runs += face_->last_ran_detector();
  }

  std::unique_ptr<pose_pipeline> pose_;
  std::unique_ptr<hand_pipeline> hands_;
  std::unique_ptr<face_pipeline> face_;
  std::unique_ptr<capture_detail::two_lanes> lanes_;
  std::string description_;
  estimator_timings timings_;
  // The tasks of the current batch and their errors (messages kept: no allocation once sized).
  task tasks_[3];
  int task_count_ = 0;
  std::string task_error_[3];
  landmark_frame side_[2];  // what the hands (0) and the face (1) write, merged afterwards
  // estimate_pipelined(): two frames in flight, cur_ is the one the next call's body fills.
  landmark_frame slot_[2];
  estimate_args args_[2];
  estimator_timings slot_timings_[2];
  int cur_ = 0;
  bool pending_ = false;  // slot_[cur_ ^ 1] has its body and waits for its hands and face
};

}  // namespace

status create_onnx_estimator(const estimator_options& options, std::unique_ptr<estimator>& out) {
  out.reset();
  if (options.model_complexity < 0 || options.model_complexity > 2)
    return status::error("model complexity must be 0 (lite), 1 (full) or 2 (heavy)");
  if (options.hand_model_complexity < 0 || options.hand_model_complexity > 1)
    return status::error("hand model complexity must be 0 (lite) or 1 (full)");
  if (options.lanes != 1 && options.lanes != 2) return status::error("lanes must be 1 or 2");
  const int all_threads = options.threads < 1 ? 1 : options.threads;
  // Two lanes only pay when there is a second model per frame to run beside the body.
  const bool two_lanes = options.lanes == 2 && all_threads >= 2 && (options.hands || options.face);
  const int threads = two_lanes ? all_threads / 2 : all_threads;
  std::string description =
      options.precision == model_precision::int8
          ? std::string("models: int8") +
                (cpu_has_vnni() ? ""
                                : " (this CPU has no VNNI: int8 leaves Google's tolerances "
                                  "much further here, docs/capture.md)")
          : std::string("models: float");
  description += two_lanes ? "; two lanes" : "; one lane";

  pose_pipeline_options po;
  po.models_dir = options.source;
  po.intra_op_threads = threads;
  po.allow_spinning = options.spin;
  po.complexity = static_cast<pose_model_complexity>(options.model_complexity);
  po.precision = options.precision;
  po.static_images = options.static_images;
  std::unique_ptr<pose_pipeline> pose;
  status s = pose_pipeline::create(po, pose);
  if (!s.ok()) return s;

  std::unique_ptr<hand_pipeline> hands;
  if (options.hands) {
    hand_pipeline_options ho;
    ho.models_dir = options.source;
    ho.intra_op_threads = threads;
    ho.complexity = static_cast<hand_model_complexity>(options.hand_model_complexity);
    ho.precision = options.precision;
    ho.mirrored_input = options.mirrored_input;
    ho.allow_spinning = po.allow_spinning;
    ho.static_images = options.static_images;
    s = hand_pipeline::create(ho, hands);
    if (!s.ok()) return s;
  }
  std::unique_ptr<face_pipeline> face;
  if (options.face) {
    face_pipeline_options fo;
    fo.models_dir = options.source;
    fo.precision = options.precision;
    fo.intra_op_threads = threads;
    fo.allow_spinning = po.allow_spinning;
    fo.static_images = options.static_images;
    if (options.face_model < 0 || options.face_model > 1)
      return status::error("face model must be 0 (attention) or 1 (mesh)");
    fo.model = static_cast<face_mesh_model>(options.face_model);
    s = face_pipeline::create(fo, face);
    if (!s.ok()) return s;
    if (!face->note().empty()) description += "; " + face->note();
  }
  out.reset(new onnx_estimator(std::move(pose), std::move(hands), std::move(face), two_lanes,
                               std::move(description)));
  return {};
}

}  // namespace avatarmap
