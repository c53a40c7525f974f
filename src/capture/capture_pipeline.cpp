#include "avatarmap/capture/capture_pipeline.hpp"

#include <algorithm>
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
  const int streams = std::max(1, options.estimator.max_people);
  for (int i = 0; i < streams; ++i)
    p->streams_.push_back(std::make_unique<pose_stream>(stream_options(options)));
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
    for (auto& s : streams_) s->restart(so);
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
  streams_[0]->push(frame, [&pose](const proxy_pose& p) {
    pose = p;
    return status{};
  });
  pose.t = frame.t;
}

const estimator_timings* capture_pipeline::last_timings() const {
  return estimator_->last_timings();
}

void capture_pipeline::reset() {
  for (auto& s : streams_) s->reset();
  slots_ = {};
  have_shared_origin_ = false;
}

int capture_pipeline::slot_for(int id, double t) {
  const int n = max_people();
  for (int k = 0; k < n; ++k)
    if (slots_[k].id == id) return k;
  // The lowest free slot, else the one whose person was seen longest ago (only when more ids
  // than slots are held at once, which the estimator does not give).
  int pick = -1;
  for (int k = 0; k < n && pick < 0; ++k)
    if (slots_[k].id < 0) pick = k;
  if (pick < 0) {
    pick = 0;
    for (int k = 1; k < n; ++k)
      if (slots_[k].seen_t < slots_[pick].seen_t) pick = k;
  }
  streams_[pick]->reset();
  slots_[pick] = {id, t};
  return pick;
}

void capture_pipeline::solve_people(const landmark_frame& frame, people_poses& out) {
  out.count = 0;
  const estimator::people_view view = estimator_->last_people();
  const double t = frame.t;
  if (view.count < 0) {  // one person: the frame estimate() gave, in slot 0
    if (!frame.has(frame_part::pose) && !frame.has(frame_part::pose_world)) {
      proxy_pose ignored;
      solve(frame, ignored);  // the stream holds and eases what it lost
      return;
    }
    person_pose& p = out.people[0];
    p.id = 0;
    p.slot = 0;
    p.frame = &frame;
    solve(frame, p.pose);
    slots_[0] = {0, t};
    out.count = 1;
    return;
  }
  // Free the slots of people gone for longer than the estimator keeps their ids.
  for (int k = 0; k < max_people(); ++k)
    if (slots_[k].id >= 0 && t - slots_[k].seen_t > k_person_hold_seconds) slots_[k] = {};
  for (int i = 0; i < view.count && i < k_max_people; ++i) {
    const landmark_frame& f = view.frames[i];
    person_pose& p = out.people[out.count++];
    p.id = f.person;
    p.slot = slot_for(f.person, t);
    p.frame = &f;
    slots_[p.slot].seen_t = t;
    pose_stream& stream = *streams_[p.slot];
    // One origin for everyone: the first person's first ground position.
    glm::vec2 origin;
    if (have_shared_origin_ && !stream.solver().ground_origin(origin))
      stream.solver().set_ground_origin(shared_origin_);
    stream.push(f, [&p](const proxy_pose& q) {
      p.pose = q;
      return status{};
    });
    p.pose.t = t;
    if (!have_shared_origin_ && stream.solver().ground_origin(shared_origin_))
      have_shared_origin_ = true;
  }
}

}  // namespace avatarmap
