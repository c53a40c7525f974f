#include "avatarmap/jobs/solve_file.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/clip_output.hpp"  // k_max_output_fps
#include "avatarmap/jobs/people.hpp"
#include "avatarmap/solve/pose_stream.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "avatarmap/time/seconds_text.hpp"
#include "common/frame_prefetcher.hpp"

namespace avatarmap {

namespace {
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

// Warnings of one kind after which the rest are only counted (the summary has the totals).
constexpr long k_warnings_per_kind = 5;

// The parts of the per-frame work that are large (a landmark frame is ~20 kB, the stream's
// solver, filters and poses more): on the heap, so that a caller on a small stack (a C API
// user's thread) is safe.
// Frames of the warm-up: the solver learns the camera (field of view, pitch and roll, the
// world points' lean) and the performer's proportions from a file's first frames, then the
// file is solved from its start with them known and held (docs/solver.md "Field of view"):
// no pose is solved with the prior's camera, and one depth scale and one vertical hold for
// the whole take (a field of view still moving would stretch a walk). 10 s at 30 frames/s (a
// person walking toward the camera tells the field of view as they come near; 5 s left
// root errors of 28 cm on the world benchmark, 10 s 12 cm); a shorter file is warmed up on all
// its frames. The frames are kept for the replay (~20 kB each: 6 MB). With the offline filter
// only (the default for files): the live and no filters stay the frame-by-frame path.
constexpr std::size_t k_warm_up_frames = 300;

struct solve_state {
  explicit solve_state(const pose_stream_options& options) : stream(options) {
    warm.reserve(k_warm_up_frames);
  }
  pose_stream stream;                // solve -> filter -> resample at output_fps
  landmark_frame frame;              // the direct source's storage (threads == 1)
  std::vector<landmark_frame> warm;  // the warm-up's frames, replayed once it ends
  bool warming = true;
  // A source's first frames held back (the live and no filters) until the face is calibrated
  // over them, then solved in order; a file's face is calibrated over all of it first.
  bool holding_face = false;
};

// Reads straight from the reader on this thread (threads == 1); the same interface as
// jobs_detail::frame_prefetcher.
struct direct_source {
  landmark_reader& reader;
  landmark_frame& frame_storage;
  read_result next() { return reader.next(frame_storage); }
  const landmark_frame& frame() const { return frame_storage; }
  const std::string& error() const { return reader.error(); }
  status_code error_code() const { return reader.error_code(); }
  void release() {}
};

// Pulls frames from the job's `source` on this thread; the same interface again.
struct callback_source {
  const std::function<status(landmark_frame&, bool&)>& source;
  landmark_frame& frame_storage;
  status failed;
  read_result next() {
    bool end = false;
    failed = source(frame_storage, end);
    if (!failed.ok()) return read_result::error;
    return end ? read_result::end : read_result::frame;
  }
  const landmark_frame& frame() const { return frame_storage; }
  const std::string& error() const { return failed.message(); }
  status_code error_code() const { return failed.code(); }
  void release() {}
};

// The stream's solver, to calibrate its face before any frame is solved.
frame_solver& stream_solver(pose_stream& stream) { return stream.solver(); }

// The face calibrated over the whole file before it is solved (docs/expressions.md,
// "Calibration over a take"): a first pass reads every frame's face measurements (a few
// hundred bytes a frame). Lines the reader cannot parse are passed over here (the solving pass
// reports them); a file that cannot be opened is left to the solving pass too.
void calibrate_face_over_file(const std::string& path, int person, frame_solver& solver) {
  landmark_reader reader;
  if (!reader.open(path).ok()) return;
  reader.set_person(person);
  auto frame = std::make_unique<landmark_frame>();
  solver.begin_face_take();
  for (;;) {
    const read_result r = reader.next(*frame);
    if (r == read_result::end) break;
    if (r == read_result::error) {
      if (reader.error_code() == status_code::io) break;
      continue;
    }
    solver.add_face_take(*frame);
  }
  solver.end_face_take();
}

}  // namespace

status solve_file_job::validate() const {
  if (input.empty() && !source)
    return status::error("solve_file_job.input is empty: give a landmark file or a source");
  if (!sink && output.empty())
    return status::error("solve_file_job.output is empty: give a *.pose.jsonl path or a sink");
  if (status st = options.validate(); !st.ok())
    return status::error("solve_file_job.options: " + st.message());
  if (person < -1 || person > k_max_person_id)
    return status::error("solve_file_job.person must be -1 (the file's only person) or in [0, " +
                         std::to_string(k_max_person_id) + "]");
  if (origin_person < -1 || origin_person > k_max_person_id)
    return status::error(
        "solve_file_job.origin_person must be -1 (a file of several people's lowest id) or in "
        "[0, " +
        std::to_string(k_max_person_id) + "]");
  if (!(std::isfinite(image_width) && std::isfinite(image_height) && image_width >= 0.f &&
        image_height >= 0.f) ||
      (image_width > 0.f) != (image_height > 0.f))
    return status::error(
        "solve_file_job.image_width/image_height must be finite and >= 0, both given or "
        "neither (0 = from the file)");
  if (!(std::isfinite(output_fps) && output_fps >= 0.0 && output_fps <= k_max_output_fps))
    return status::error(output_fps_name + " must be 0 (one pose per frame) or in (0, " +
                         limit_text(k_max_fps) + "], got " + seconds_text(output_fps, 6));
  if (threads != 1 && threads != 2)
    return status::error("solve_file_job.threads is 1 or 2, got " + std::to_string(threads));
  // The filter rules (filter_rules.hpp), named as this job's fields.
  if (status st = static_cast<const pose_stream_filters&>(*this).validate(); !st.ok())
    return status::error("solve_file_job." + st.message());
  return {};
}

status solve_file_job::run(solve_file_summary& s) const {
  s = solve_file_summary{};
  if (status st = validate(); !st.ok()) return st;
  const auto t0 = clock_type::now();
  landmark_reader reader;
  status st;
  // The person solved: `person`, else the file's only one (a version-1 file's lines are all
  // person 0; a version-2 file of several people needs `person`, jobs/people.hpp).
  int only = person;
  std::vector<int> ids;  // the file's people, once scanned (a version-2 regular file)
  if (!source) {
    st = reader.open(input);
    if (!st.ok()) return st;  // io (cannot be opened) or parse (a bad header)
    if (only < 0 && reader.header().version >= 2) {
      std::error_code ec;
      if (input == "-" || !std::filesystem::is_regular_file(input, ec))
        return status::invalid_argument(
            input + ": several people's landmarks (version 2) read once: choose one (person)");
      if (st = people_in_file(input, ids); !st.ok()) return st;
      if (ids.size() > 1) {
        return status::invalid_argument(input + " has " + std::to_string(ids.size()) + " people (" +
                                        person_id_list(ids) +
                                        "): choose one (person), or solve each to its own output "
                                        "(jobs/people.hpp; the CLI does)");
      }
      if (ids.size() == 1) only = ids[0];
    }
    reader.set_person(only);
  }
  // Several people standing apart: the origin person's own solve says where it was first seen.
  // -1: a file of several people's first (lowest) id.
  bool shared_origin = false;
  glm::vec2 origin(0.f);
  int origin_id = origin_person;
  if (!source && origin_id != only) {
    std::error_code ec;
    const bool regular = std::filesystem::is_regular_file(input, ec);
    if (!regular && origin_id >= 0)
      return status::invalid_argument(input +
                                      ": origin_person reads the file twice: give a file, "
                                      "not a pipe or standard input");
    if (reader.header().version < 2)
      ids = {0};  // a version-1 file: person 0
    else if (ids.empty() && regular)
      if (st = people_in_file(input, ids); !st.ok()) return st;
    if (origin_id == -1 && reader.header().version >= 2 && ids.size() > 1)
      origin_id = *std::min_element(ids.begin(), ids.end());
    if (origin_id >= 0 && std::find(ids.begin(), ids.end(), origin_id) == ids.end())
      return status::invalid_argument(input + ": no origin person " + std::to_string(origin_id) +
                                      " (its people: " + person_id_list(ids) + ")");
  }
  if (!source && origin_id >= 0 && origin_id != only) {
    solve_file_job first = *this;
    first.person = origin_id;
    first.origin_person = origin_id;
    first.sink = [](const proxy_pose&) { return status{}; };
    first.progress = nullptr;
    first.warning = nullptr;
    first.write_confidence = false;
    solve_file_summary fs;
    if (status st = first.run(fs); !st.ok())
      return status::failure(
          st.code(), "the origin person " + std::to_string(origin_id) + ": " + st.message());
    shared_origin = fs.has_ground_origin;
    origin = {fs.ground_origin[0], fs.ground_origin[1]};
  }
  s.input_opened = true;
  // Frames from a source have no header: its defaults (no image size, no fps).
  const landmark_file_header& header = reader.header();

  solver_options solve_options = options;
  if (image_width > 0.f) {
    solve_options.image_width = image_width;
    solve_options.image_height = image_height;
  } else if (header.image_width > 0 && header.image_height > 0) {
    solve_options.image_width = static_cast<float>(header.image_width);
    solve_options.image_height = static_cast<float>(header.image_height);
  } else if (!(options.image_width > 0.f)) {
    s.image_size_assumed = true;
  }
  s.image_width = solve_options.image_width;
  s.image_height = solve_options.image_height;
  // Solve -> filter -> resample: the pose stream (it opens the solver's gate for the offline
  // filter). Checked again with the image size now known.
  pose_stream_options stream_options;
  stream_options.solver = solve_options;
  stream_options.filters = static_cast<const pose_stream_filters&>(*this);
  stream_options.output_fps = output_fps;
  stream_options.sample_any_time = false;  // poses out through emit only
  stream_options.name = input;
  stream_options.output_fps_name = output_fps_name;
  st = stream_options.validate();
  if (!st.ok()) return st;

  pose_writer writer;
  pose_file_header ph;
  ph.present = true;
  ph.fps = output_fps > 0.0 ? output_fps : header.fps;
  s.fps = ph.fps;
  pose_write_options wo;
  wo.write_confidence = write_confidence;
  if (!sink) {
    st = writer.open(output, ph, wo);
    if (!st.ok()) return st;
  }
  auto emit = [&](const proxy_pose& p) { return sink ? sink(p) : writer.write(p); };

  auto state = std::make_unique<solve_state>(stream_options);
  // The live and no filters reproduce the frame-by-frame path (the C solver handle, `live`)
  // exactly: no warm-up.
  state->warming = filter_mode == pose_filter_mode::offline;
  pose_stream& stream = state->stream;
  // Where the root is measured from (set again after the warm-up's restarts, which forget it),
  // and which point that was (the first one the solver had after the warm-up).
  auto use_origin = [&] {
    if (shared_origin) stream_solver(stream).set_ground_origin(origin);
  };
  auto note_origin = [&] {
    if (s.has_ground_origin || state->warming || state->holding_face) return;
    glm::vec2 o;
    if (!stream.solver().ground_origin(o)) return;
    s.has_ground_origin = true;
    s.ground_origin[0] = o.x;
    s.ground_origin[1] = o.y;
  };
  use_origin();
  // Whatever the filter, a regular file's face is calibrated over all its frames (with the
  // offline filter after the warm-up, else before the first frame); a source's, a pipe's or
  // standard input's (read once) over the first k_warm_up_frames (the warm-up's with the
  // offline filter, else held back for it): these give a file's poses when it is no longer.
  std::error_code fs_error;
  const bool read_twice = !source && std::filesystem::is_regular_file(input, fs_error);
  const bool face = solve_options.parts.face;
  // With the warm-up (the offline filter) the calibration waits for its end, when the field
  // of view is learnt and held: the take is read through the lens it is solved with.
  if (face && read_twice && !state->warming)
    calibrate_face_over_file(input, only, stream_solver(stream));
  state->holding_face = face && !read_twice && !state->warming;
  auto end_holding_face = [&]() -> status {
    solve_state& ws = *state;
    ws.holding_face = false;
    stream_solver(ws.stream).calibrate_face(ws.warm.data(), ws.warm.size());
    for (const landmark_frame& f : ws.warm)
      if (status st = ws.stream.push(f, emit); !st.ok()) return st;
    ws.warm.clear();
    return {};
  };
  // The warm-up's end: a second pass over its frames learns the camera's pitch and roll, the
  // floor and the world points' lean again with the field of view the first pass found; then
  // the pose state is forgotten, the camera kept and held, and the frames solved for output.
  auto end_warm_up = [&]() -> status {
    solve_state& ws = *state;
    ws.warming = false;
    ws.stream.restart_take(false);
    for (const landmark_frame& f : ws.warm) ws.stream.learn_camera(f);
    ws.stream.restart_take();
    ws.stream.hold_view();
    use_origin();
    if (face && read_twice)
      calibrate_face_over_file(input, only, stream_solver(ws.stream));
    else if (face)
      stream_solver(ws.stream).calibrate_face(ws.warm.data(), ws.warm.size());
    for (const landmark_frame& f : ws.warm)
      if (status st = ws.stream.push(f, emit); !st.ok()) return st;
    ws.warm.clear();
    return {};
  };
  auto last_progress = t0;
  const double fps = output_fps;
  const std::string& fps_name = output_fps_name;
  // The first and newest frame read (resampling needs times in order; checked as frames are
  // read, before the filter's delay).
  double t_read_first = 0.0, t_read_newest = 0.0;
  bool have_read = false;

  // One pass over the frames of `src` (the reader itself, or a prefetcher parsing on a second
  // thread): solve, filter, resample, write.
  auto process = [&](auto& src) -> status {
    for (;;) {
      const read_result r = src.next();
      if (r == read_result::end) return {};
      if (r == read_result::error) {
        // The reader's code (parse: a malformed line; io: a read error), or the source's own.
        if (source || !skip_bad_lines) return status::failure(src.error_code(), src.error());
        ++s.bad_lines;
        if (s.bad_lines <= k_warnings_per_kind && warning) warning("skipped " + src.error());
        src.release();
        continue;
      }
      const landmark_frame& frame = src.frame();
      const long index = s.frames + s.out_of_order;  // 0-based among the good frames
      if (fps > 0.0 && have_read) {
        if (frame.t < t_read_newest) {
          // Resampling cannot go back in time. The frame is left out entirely (solving it would
          // also restart the pose filter), with a warning.
          ++s.out_of_order;
          if (s.out_of_order <= k_warnings_per_kind && warning)
            warning("frame " + std::to_string(index) + " (t = " + seconds_text(frame.t) +
                    " s) is earlier than the frame before it (t = " + seconds_text(t_read_newest) +
                    " s); skipped (" + fps_name + " needs times in order)");
          src.release();
          continue;
        }
        if (frame.t - t_read_first > k_max_clip_seconds) {
          // The times are readable but too far apart for the asked rate: an argument error,
          // as for resample_clip (not a malformed line).
          return status::invalid_argument(
              input + ": frame " + std::to_string(index) + " (t = " + seconds_text(frame.t) +
              " s) is " + seconds_text(frame.t - t_read_first, 2) + " s after the first frame; " +
              fps_name + " resamples at most " + seconds_text(k_max_clip_seconds, 0) +
              " s (24 h): check the times or solve without " + fps_name);
        }
      }
      if (!have_read) t_read_first = frame.t;
      have_read = true;
      t_read_newest = frame.t;
      if (s.frames == 0) s.t_first = frame.t;
      s.t_last = frame.t;
      ++s.frames;
      for (int p = 0; p < k_frame_part_count; ++p)
        if (frame.has(static_cast<frame_part>(p))) ++s.part_frames[p];
      if (frame.has(frame_part::face) && frame.face_count == k_face_mesh_iris_count)
        ++s.face_iris_frames;

      status pushed;
      if (state->warming) {
        stream.learn_camera(frame);
        state->warm.push_back(frame);  // reserved: no reallocation
        if (state->warm.size() == k_warm_up_frames) pushed = end_warm_up();
      } else if (state->holding_face) {
        state->warm.push_back(frame);  // reserved: no reallocation
        if (state->warm.size() == k_warm_up_frames) pushed = end_holding_face();
      } else {
        pushed = stream.push(frame, emit);
      }
      note_origin();
      src.release();
      if (!pushed.ok()) return pushed;
      if (progress && (s.frames & 255) == 0) {
        const auto now = clock_type::now();
        if (std::chrono::duration<double>(now - last_progress).count() > 0.25) {
          last_progress = now;
          progress({s.frames, s.t_last - s.t_first, seconds_since(t0)});
        }
      }
    }
  };
  if (source) {
    callback_source from_source{source, state->frame, {}};
    st = process(from_source);
  } else if (threads > 1) {
    jobs_detail::frame_prefetcher prefetcher(reader, !skip_bad_lines);
    st = process(prefetcher);
  } else {
    direct_source direct{reader, state->frame};
    st = process(direct);
  }
  // A file shorter than the warm-up; or an error: the frames before it still reach the
  // output (as without a warm-up), then the error ends the run.
  if (state->warming) {
    const status warmed = end_warm_up();
    if (st.ok()) st = warmed;
  }
  if (state->holding_face) {
    const status held = end_holding_face();
    if (st.ok()) st = held;
  }
  note_origin();
  if (st.ok()) st = stream.finish(emit);  // the poses the offline filter still holds
  s.poses_written = stream.stats().emitted;
  if (!st.ok()) return st;
  if (!sink) st = writer.commit();
  if (!st.ok()) return st;
  s.seconds = seconds_since(t0);
  s.hips_height_min = stream.stats().hips_height_min;
  s.hips_height_max = stream.stats().hips_height_max;
  s.horizontal_fov_degrees = stream.solver().horizontal_fov_degrees();
  s.fov_estimated = solve_options.horizontal_fov_degrees == 0.f;
  s.fov_evidence_frames = stream.solver().fov_evidence_frames();
  s.camera_pitch_degrees = stream.solver().camera_pitch_degrees();
  s.camera_roll_degrees = stream.solver().camera_roll_degrees();
  s.gravity_evidence_frames = stream.solver().gravity_evidence_frames();
  s.floor_evidence_points = stream.solver().floor_evidence_points();
  s.body_hold = stream.solver().hold_stats();
  if (s.body_hold.held_frames > 0 && warning) {
    const body_hold_stats& h = s.body_hold;
    std::string why;
    for (int i = 0; i < k_body_doubt_count; ++i)
      if (h.doubt_frames[i] > 0)
        why += (why.empty() ? "" : ", ") + std::string(body_doubt_name(i)) + " " +
               std::to_string(h.doubt_frames[i]);
    const char* rest = solve_options.lower_body_rest == body_rest::sitting ? "sitting" : "standing";
    warning("the lower body was held at rest (" + std::string(rest) + ") in " +
            std::to_string(h.held_frames) + " of " + std::to_string(h.frames) +
            " frames with a body (" + why + ")" +
            (h.limbs_off_frames > 0
                 ? "; the spine and arms were not followed either in " +
                       std::to_string(h.limbs_off_frames) + " (not a person's points)"
                 : std::string()) +
            "; --lower-body-rest off follows every body");
  }
  return {};
}

}  // namespace avatarmap
