#include "avatarmap/capture/capture_pipeline.hpp"

#include <cmath>
#include <string>
#include <utility>

namespace avatarmap {

status check_image(const image_view& image) {
  if (image.data == nullptr) return status::error("image: no pixels (data is NULL)");
  if (image.width < 1 || image.height < 1 || image.width > k_max_image_side ||
      image.height > k_max_image_side)
    return status::error("image: width and height must be in [1, " +
                         std::to_string(k_max_image_side) + "], got " +
                         std::to_string(image.width) + "x" + std::to_string(image.height));
  const int bpp = image_bytes_per_pixel(image.format);
  if (bpp == 0) return status::error("image: unknown pixel format");
  if (static_cast<long long>(image.stride_bytes) < static_cast<long long>(image.width) * bpp)
    return status::error("image: stride_bytes (" + std::to_string(image.stride_bytes) +
                         ") must be at least width x " + std::to_string(bpp) + " = " +
                         std::to_string(static_cast<long long>(image.width) * bpp));
  return {};
}

namespace {
// The stream of a capture pipeline: the live filter (or none), one pose per image.
pose_stream_options stream_options(const capture_pipeline_options& o) {
  pose_stream_options so;
  so.solver = o.solver;
  so.filters.filter_mode = pose_filter_mode::live;  // filter.enabled = false: none
  so.filters.filter = o.filter;
  so.filters.foot_contacts = o.foot_contacts;
  so.resampler = o.resampler;
  so.name = "capture";
  return so;
}
}  // namespace

status capture_pipeline_options::validate() const {
  if (status st = solver.validate(); !st.ok()) return st;
  if (status st = stream_options(*this).validate(); !st.ok())
    return status::error("capture_pipeline_options." + st.message());
  const estimator_backend_list list = estimator_backends();
  std::string names;
  for (int i = 0; i < list.count; ++i) {
    if (list.items[i].name == backend) return {};
    names += (i > 0 ? ", " : "") + std::string(list.items[i].name);
  }
  // "onnx" is a backend a build without ONNX Runtime lacks (unsupported); others are unknown.
  const std::string message = "capture_pipeline_options.backend '" + backend +
                              "' is not built in (this build has: " + names + ")";
  return backend == "onnx" ? status::unsupported(message) : status::invalid_argument(message);
}

status capture_pipeline::create(const capture_pipeline_options& options,
                                std::unique_ptr<capture_pipeline>& out) {
  out.reset();
  if (status st = options.validate(); !st.ok()) return st;
  std::unique_ptr<capture_pipeline> p(new capture_pipeline());
  p->options_ = options;
  if (status st = create_estimator(options.backend, options.estimator, p->estimator_); !st.ok())
    return st;
  p->stream_ = std::make_unique<pose_stream>(stream_options(options));
  p->args_.body = true;
  p->args_.hands = options.estimator.hands;
  p->args_.face = options.estimator.face;
  out = std::move(p);
  return {};
}

capture_pipeline::~capture_pipeline() = default;

status capture_pipeline::process(const image_view& image, double t, landmark_frame& frame,
                                 proxy_pose& pose) {
  if (status st = estimate(image, t, frame); !st.ok()) return st;
  solve(frame, pose);
  return {};
}

status capture_pipeline::estimate(const image_view& image, double t, landmark_frame& frame) {
  if (!std::isfinite(t)) return status::error("capture time must be finite");
  // The replay backend needs no pixels; every other one does.
  if (options_.backend != "replay")
    if (status st = check_image(image); !st.ok()) return st;
  // The solver scales image points by the image's size: made for it when the options leave it
  // open, remade (fresh state) when the size changes.
  if (!(options_.solver.image_width > 0.f) &&
      (image.width != solver_width_ || image.height != solver_height_) && image.width > 0) {
    solver_options so = options_.solver;
    so.image_width = static_cast<float>(image.width);
    so.image_height = static_cast<float>(image.height);
    stream_->restart(so);
    solver_width_ = image.width;
    solver_height_ = image.height;
  }
  args_.image = image;
  args_.t = t;
  if (status st = estimator_->estimate(args_, frame); !st.ok()) return st;
  frame.t = t;
  return {};
}

void capture_pipeline::solve(const landmark_frame& frame, proxy_pose& pose) {
  // One pose per frame (the live filter or none, no grid): emit is called once.
  stream_->push(frame, [&pose](const proxy_pose& p) {
    pose = p;
    return status{};
  });
  pose.t = frame.t;
}

const estimator_timings* capture_pipeline::last_timings() const {
  return estimator_->last_timings();
}

void capture_pipeline::reset() { stream_->reset(); }

}  // namespace avatarmap
