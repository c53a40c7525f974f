// The "onnx" estimator backend: the body (pose_pipeline), then both hands (hand_pipeline) and
// the face (face_pipeline), each given the body found in the same frame so that their
// regions come from it when they are not tracked (MediaPipe Holistic's order).
#include "capture/onnx/onnx_estimator.hpp"

#include <chrono>

#include "avatarmap/capture/face_pipeline.hpp"
#include "avatarmap/capture/hand_pipeline.hpp"
#include "avatarmap/capture/pose_pipeline.hpp"

namespace avatarmap {

namespace {

double ms_between(std::chrono::steady_clock::time_point a,
                  std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

class onnx_estimator final : public estimator {
 public:
  onnx_estimator(std::unique_ptr<pose_pipeline> pose, std::unique_ptr<hand_pipeline> hands,
                 std::unique_ptr<face_pipeline> face)
      : pose_(std::move(pose)), hands_(std::move(hands)), face_(std::move(face)) {}

  status estimate(const estimate_args& args, landmark_frame& out) override {
    const auto t0 = std::chrono::steady_clock::now();
    timings_ = {};
    out.clear();
    out.t = args.t;
    if (args.body) {
      if (pose_->process(args.image, out) == pose_result::error)
        return status::error(pose_->last_error());
      const pose_timings& pt = pose_->last_timings();
      timings_.pose_detector_ms = pt.detector_ms;
      timings_.pose_landmark_ms = pt.landmark_ms;
      timings_.detector_runs += pose_->last_ran_detector();
    }
    const landmark_frame* body = out.has(frame_part::pose) ? &out : nullptr;
    if (args.hands && hands_) {
      if (hands_->process(args.image, body, out) == hand_result::error)
        return status::error(hands_->last_error());
      const hand_timings& ht = hands_->last_timings();
      timings_.palm_detector_ms = ht.palm_ms;
      timings_.hand_landmark_ms = ht.landmark_ms;
      timings_.detector_runs += hands_->last_ran_palm_detector();
    }
    if (args.face && face_) {
      if (face_->process(args.image, body, out) == face_result::error)
        return status::error(face_->last_error());
      const face_timings& ft = face_->last_timings();
      timings_.face_detector_ms = ft.detector_ms;
      timings_.face_mesh_ms = ft.mesh_ms;
      timings_.detector_runs += face_->last_ran_detector();
    }
    timings_.total_ms = ms_between(t0, std::chrono::steady_clock::now());
    return {};
  }

  std::string_view name() const override { return "onnx"; }
  const estimator_timings* last_timings() const override { return &timings_; }

 private:
  std::unique_ptr<pose_pipeline> pose_;
  std::unique_ptr<hand_pipeline> hands_;
  std::unique_ptr<face_pipeline> face_;
  estimator_timings timings_;
};

}  // namespace

status create_onnx_estimator(const estimator_options& options, std::unique_ptr<estimator>& out) {
  out.reset();
  if (options.model_complexity < 0 || options.model_complexity > 2)
    return status::error("model complexity must be 0 (lite), 1 (full) or 2 (heavy)");
  if (options.hand_model_complexity < 0 || options.hand_model_complexity > 1)
    return status::error("hand model complexity must be 0 (lite) or 1 (full)");
  const int threads = options.threads < 1 ? 1 : options.threads;

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
    s = face_pipeline::create(fo, face);
    if (!s.ok()) return s;
  }
  out.reset(new onnx_estimator(std::move(pose), std::move(hands), std::move(face)));
  return {};
}

}  // namespace avatarmap
