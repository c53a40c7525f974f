// The "onnx" estimator backend: the body (pose_pipeline), then both hands (hand_pipeline) and
// the face (face_pipeline), each given the body found in the same frame so that their
// regions come from it when they are not tracked (MediaPipe Holistic's order).
#include "capture/onnx/onnx_estimator.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "avatarmap/capture/face_pipeline.hpp"
#include "avatarmap/capture/hand_pipeline.hpp"
#include "avatarmap/capture/people_tracker.hpp"
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
                 std::unique_ptr<face_pipeline> face, bool two_lanes, std::string description,
                 int max_people, bool static_images)
      : pose_(std::move(pose)),
        hands_(std::move(hands)),
        face_(std::move(face)),
        description_(std::move(description)),
        max_people_(max_people),
        static_images_(static_images) {
    if (two_lanes) lanes_ = std::make_unique<capture_detail::two_lanes>();
    if (max_people_ > 1) {
      people_tracker_options to;
      to.max_people = max_people_;
      tracker_ = people_tracker(to);
      people_ = std::make_unique<people_state>();
    }
  }

  status estimate(const estimate_args& args, landmark_frame& out) override {
    if (max_people_ > 1) return estimate_people(args, out);
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
    if (max_people_ > 1) return estimate_people_pipelined(in, out, ready);
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
  people_view last_people() const override {
    if (max_people_ <= 1) return {};
    const people_frame& f = people_->frame[people_->given];
    return {f.frames.data(), f.count};
  }
  std::string describe() const override { return description_; }
  std::string_view name() const override { return "onnx"; }
  const estimator_timings* last_timings() const override { return &timings_; }

 private:
  enum class task_kind : std::uint8_t { body, hands, face, people_body, people_hands, people_face };

  // ---- several people (max_people_ > 1) ----------------------------------------------------
  // The same stages per person, one after another through the shared sessions (a session runs
  // one inference at a time); each person's tracking state lives in its slot of each pipeline
  // (select_person()), and people_tracker says who is who. With two lanes, as for one person:
  // every person's body of frame t beside every person's hands and face of frame t-1.
  struct people_frame {
    std::array<landmark_frame, k_max_people> frames;  // ascending by person id
    std::array<int, k_max_people> slot{};             // the pipelines' slot of each
    std::array<bool, k_max_people> fresh{};  // a new track: its hand and face slots restart
    int count = 0;
    estimate_args args;
    estimator_timings tm;
    int side_detector_runs[2] = {0, 0};  // palm (hands task), face (face task)
  };
  struct people_state {
    people_frame frame[2];  // estimate_pipelined(): two in flight, as slot_
    std::array<landmark_frame, k_max_people> side_hands, side_face;
    int given = 0;  // the frame last given back (last_people())
  };

  // Every person's body on frame `f` (f.args set): the detector when the tracker wants it,
  // then each tracked person's landmarks; merged tracks resolved. False on an error
  // (task_error_[slot] set).
  bool people_body(people_frame& f, int slot) {
    task_error_[slot].clear();
    f.count = 0;
    f.tm = {};
    f.side_detector_runs[0] = f.side_detector_runs[1] = 0;
    const estimate_args& a = f.args;
    if (!a.body) return true;
    const int w = a.image.width, h = a.image.height;
    if (static_images_) tracker_.reset();  // images unrelated: each one's people anew
    if (tracker_.wants_detection(a.t)) {
      std::array<normalized_rect, k_max_people> regions;
      std::array<float, k_max_people> scores;
      std::array<float, 4 * k_max_people> anchors;
      const int n =
          pose_->detect_people(a.image, max_people_, regions.data(), scores.data(), anchors.data());
      if (n < 0) {
        task_error_[slot] = pose_->last_error();
        return false;
      }
      f.tm.pose_detector_ms += pose_->last_timings().detector_ms;
      ++f.tm.detector_runs;
      tracker_.on_detections(a.t, regions.data(), anchors.data(), n, w, h);
    }
    // A copy: on_lost() below changes the tracker's list.
    std::array<people_tracker::track, k_max_people> tracks;
    const int count = tracker_.active_count();
    for (int i = 0; i < count; ++i) tracks[i] = tracker_.active(i);
    for (int i = 0; i < count; ++i) {
      const people_tracker::track& tr = tracks[i];
      pose_->select_person(tr.slot);
      if (tr.is_new) pose_->start_track(tr.start_region);
      landmark_frame& fr = f.frames[f.count];
      fr.clear();
      fr.t = a.t;
      fr.person = tr.id;
      const pose_result r = pose_->process(a.image, fr);
      f.tm.pose_landmark_ms += pose_->last_timings().landmark_ms;
      if (r == pose_result::error) {
        task_error_[slot] = pose_->last_error();
        return false;
      }
      if (r == pose_result::not_found) {
        tracker_.on_lost(tr.slot, a.t);
        continue;
      }
      tracker_.on_found(tr.slot, a.t, pose_->last_roi(), pose_->tracked_roi(), fr.pose.data(), w,
                        h);
      f.slot[f.count] = tr.slot;
      f.fresh[f.count] = tr.is_new;
      ++f.count;
    }
    std::array<int, k_max_people> dropped;
    const int nd = tracker_.resolve_merges(a.t, dropped.data());
    for (int d = 0; d < nd; ++d) {
      pose_->select_person(dropped[d]);
      pose_->reset();
      int k = 0;
      for (int i = 0; i < f.count; ++i) {
        if (f.slot[i] == dropped[d]) continue;
        if (k != i) {
          std::swap(f.frames[k], f.frames[i]);
          f.slot[k] = f.slot[i];
          f.fresh[k] = f.fresh[i];
        }
        ++k;
      }
      f.count = k;
    }
    return true;
  }

  // Every person's hands (hands true) or face of frame `f`, each from its own body, into the
  // side frames (merged by people_merge()).
  bool people_side(people_frame& f, bool hands, int slot) {
    task_error_[slot].clear();
    const estimate_args& a = f.args;
    if (hands ? !(a.hands && hands_) : !(a.face && face_)) return true;
    for (int i = 0; i < f.count; ++i) {
      if (hands) {
        hands_->select_person(f.slot[i]);
        if (f.fresh[i]) hands_->reset();
        if (hands_->process(a.image, &f.frames[i], people_->side_hands[i], a.t) ==
            hand_result::error) {
          task_error_[slot] = hands_->last_error();
          return false;
        }
        const hand_timings& ht = hands_->last_timings();
        f.tm.palm_detector_ms += ht.palm_ms;
        f.tm.hand_landmark_ms += ht.landmark_ms;
        f.side_detector_runs[0] += hands_->last_ran_palm_detector();
      } else {
        face_->select_person(f.slot[i]);
        if (f.fresh[i]) face_->reset();
        if (face_->process(a.image, &f.frames[i], people_->side_face[i], a.t) ==
            face_result::error) {
          task_error_[slot] = face_->last_error();
          return false;
        }
        const face_timings& ft = face_->last_timings();
        f.tm.face_detector_ms += ft.detector_ms;
        f.tm.face_mesh_ms += ft.mesh_ms;
        f.side_detector_runs[1] += face_->last_ran_detector();
      }
    }
    return true;
  }

  void people_merge(people_frame& f) {
    for (int i = 0; i < f.count; ++i) {
      if (f.args.hands && hands_) copy_parts(people_->side_hands[i], k_hand_parts, f.frames[i]);
      if (f.args.face && face_) copy_parts(people_->side_face[i], k_face_parts, f.frames[i]);
    }
    f.tm.detector_runs += f.side_detector_runs[0] + f.side_detector_runs[1];
    add_total(f.tm);
  }

  // The frame's first person (the lowest id: the one known longest), or an empty frame.
  static void first_person(const people_frame& f, landmark_frame& out) {
    if (f.count > 0) {
      out = f.frames[0];
    } else {
      out.clear();
      out.t = f.args.t;
    }
  }

  status people_errors(int count) {
    for (int i = 0; i < count; ++i)
      if (!task_error_[i].empty()) return status::internal(task_error_[i]);
    return {};
  }

  status estimate_people(const estimate_args& args, landmark_frame& out) {
    for (std::string& e : task_error_) e.clear();
    people_frame& f = people_->frame[0];
    people_->given = 0;
    f.args = args;
    if (!people_body(f, 0)) {
      f.count = 0;
      first_person(f, out);
      return people_errors(1);
    }
    task_count_ = 0;
    if (args.hands && hands_)
      tasks_[task_count_++] = {task_kind::people_hands, &f.args, nullptr, nullptr};
    if (args.face && face_)
      tasks_[task_count_++] = {task_kind::people_face, &f.args, nullptr, nullptr};
    if (lanes_) {
      run_tasks();
    } else {
      for (int i = 0; i < task_count_; ++i)
        people_side(f, tasks_[i].kind == task_kind::people_hands, i);
    }
    people_merge(f);
    timings_ = f.tm;
    first_person(f, out);
    return people_errors(task_count_);
  }

  status estimate_people_pipelined(const estimate_args* in, landmark_frame& out, bool& ready) {
    ready = false;
    const int prev = cur_ ^ 1;
    people_frame& fc = people_->frame[cur_];
    people_frame& fp = people_->frame[prev];
    task_count_ = 0;
    if (in) {
      fc.args = *in;
      tasks_[task_count_++] = {task_kind::people_body, &fc.args, nullptr, nullptr};
    }
    if (pending_) {
      if (fp.args.hands && hands_)
        tasks_[task_count_++] = {task_kind::people_hands, &fp.args, nullptr, nullptr};
      if (fp.args.face && face_)
        tasks_[task_count_++] = {task_kind::people_face, &fp.args, nullptr, nullptr};
    }
    people_cur_ = cur_;
    run_tasks();
    if (status s = people_errors(task_count_); !s.ok()) return s;
    if (pending_) {
      people_merge(fp);
      people_->given = prev;
      timings_ = fp.tm;
      first_person(fp, out);
      ready = true;
    }
    pending_ = in != nullptr;
    if (in) cur_ = prev;
    return {};
  }
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
        case task_kind::people_body:
          people_body(people_->frame[people_cur_], i);
          break;
        case task_kind::people_hands:
        case task_kind::people_face: {
          // The frame whose args these are (estimate(): frame 0; pipelined: the previous one).
          people_frame& f =
              k.args == &people_->frame[0].args ? people_->frame[0] : people_->frame[1];
          people_side(f, k.kind == task_kind::people_hands, i);
          break;
        }
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
  // Several people.
  int max_people_ = 1;
  bool static_images_ = false;
  people_tracker tracker_;
  std::unique_ptr<people_state> people_;
  int people_cur_ = 0;  // the frame the people_body task fills
};

}  // namespace

status create_onnx_estimator(const estimator_options& options, std::unique_ptr<estimator>& out) {
  out.reset();
  if (options.model_complexity < 0 || options.model_complexity > 2)
    return status::error("model complexity must be 0 (lite), 1 (full) or 2 (heavy)");
  if (options.hand_model_complexity < 0 || options.hand_model_complexity > 1)
    return status::error("hand model complexity must be 0 (lite) or 1 (full)");
  if (options.lanes != 1 && options.lanes != 2) return status::error("lanes must be 1 or 2");
  if (options.max_people < 1 || options.max_people > k_max_people)
    return status::invalid_argument("max_people (--people) must be in 1.." +
                                    std::to_string(k_max_people) + ", got " +
                                    std::to_string(options.max_people));
  const bool several = options.max_people > 1;
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
  po.low_light = options.low_light;
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
    ho.low_light = options.low_light;
    // Several people: a hand only from its person's wrists, never a palm found anywhere.
    if (several) ho.roi_source = hand_roi_source::pose;
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
    fo.low_light = options.low_light;
    // Several people: a face only in its person's face region, never the image's best face.
    if (several) fo.roi_source = face_roi_source::pose;
    if (options.face_model < 0 || options.face_model > 1)
      return status::error("face model must be 0 (attention) or 1 (mesh)");
    fo.model = static_cast<face_mesh_model>(options.face_model);
    s = face_pipeline::create(fo, face);
    if (!s.ok()) return s;
    if (!face->note().empty()) description += "; " + face->note();
  }
  if (options.max_people > 1)
    description += "; up to " + std::to_string(options.max_people) + " people";
  out.reset(new onnx_estimator(std::move(pose), std::move(hands), std::move(face), two_lanes,
                               std::move(description), options.max_people, options.static_images));
  return {};
}

}  // namespace avatarmap
