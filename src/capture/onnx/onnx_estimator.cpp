// The "onnx" estimator backend: body via pose_pipeline; hands and face come later.
#include "capture/onnx/onnx_estimator.hpp"

#include "avatarmap/capture/pose_pipeline.hpp"

namespace avatarmap {

namespace {

class onnx_estimator final : public estimator {
 public:
  explicit onnx_estimator(std::unique_ptr<pose_pipeline> pose) : pose_(std::move(pose)) {}

  status estimate(const estimate_args& args, landmark_frame& out) override {
    out.clear();
    out.t = args.t;
    if (!args.body) return {};
    if (pose_->process(args.image, out) == pose_result::error)
      return status::error(pose_->last_error());
    return {};
  }

  std::string_view name() const override { return "onnx"; }

 private:
  std::unique_ptr<pose_pipeline> pose_;
};

}  // namespace

status create_onnx_estimator(const estimator_options& options, std::unique_ptr<estimator>& out) {
  pose_pipeline_options po;
  po.models_dir = options.source;
  po.intra_op_threads = options.threads < 1 ? 1 : options.threads;
  if (options.model_complexity < 0 || options.model_complexity > 2)
    return status::error("model complexity must be 0 (lite), 1 (full) or 2 (heavy)");
  po.complexity = static_cast<pose_model_complexity>(options.model_complexity);
  po.static_images = options.static_images;
  std::unique_ptr<pose_pipeline> pose;
  status s = pose_pipeline::create(po, pose);
  if (!s.ok()) return s;
  out.reset(new onnx_estimator(std::move(pose)));
  return {};
}

}  // namespace avatarmap
