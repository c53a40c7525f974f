// The C API's solver handle and file solve (avm_solver_*, avm_solve_file): options read and
// checked, the library's pose stream per frame (landmarks -> proxy pose -> live filter ->
// resampler), and the library's solve-file job for files.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/pose_stream.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "c_clip.hpp"
#include "c_frame_block.hpp"
#include "c_frames.hpp"
#include "c_guard.hpp"
#include "c_solver_options.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

// The handle. Everything a frame needs is preallocated here.
struct avm_solver : avatarmap::c_api::error_slot {
  am::pose_stream stream;    // solve -> live filter (its channels) -> resampler
  am::landmark_frame frame;  // scratch: the C frame converted
  am::proxy_pose latest;     // solved and filtered
  am::proxy_pose sampled;    // scratch for sample()

  explicit avm_solver(const am::pose_stream_options& o) : stream(o) {}
};

namespace {

// The stream of a solver handle: the live filter on the channels asked for, one pose per
// frame, sample() at any time.
am::pose_stream_options stream_options(const core_options& o) {
  am::pose_stream_options so;
  so.solver = o.solver;
  so.filters.filter_mode = am::pose_filter_mode::live;  // filter.enabled = false: none
  so.filters.filter = o.filter;
  so.filters.filter_channels = o.channels;
  so.filters.foot_contacts = o.foot_contacts;
  so.resampler = o.resampler;
  so.name = "avm_solver";
  return so;
}

// What avm_solve_file, avm_solve_file_to_clip and avm_solve_frames share: the options read
// and checked, the job made (file_job), `setup` giving it its input and output, the run, and
// a failure reported as the file functions report it. `summary` is the run's.
template <class Report, class Setup>
avm_status run_file_job(const avm_solver_options* options, Report& report, Setup&& setup,
                        am::solve_file_summary& summary) {
  core_options o;
  std::string msg;
  if (!read_options(options, o, msg)) {
    set_create_error(msg.c_str());
    return report(AVM_ERROR_INVALID_ARGUMENT, msg.c_str());
  }
  am::solve_file_job job = file_job(o);
  setup(job);
  const am::status st = job.run(summary);
  if (!st) return report(avm_code(st), st.message().c_str());
  return AVM_OK;
}

}  // namespace

extern "C" {

// (The name in parentheses: the header also defines avm_solver_options_init as a macro.)
AVATARMAP_C_API avm_status(avm_solver_options_init)(avm_solver_options* options) {
  return avm_solver_options_init_sized(options, sizeof(avm_solver_options));
}

AVATARMAP_C_API avm_status avm_solver_options_init_sized(avm_solver_options* options, size_t size) {
  if (options == nullptr || size < 8 || size > 4096 || size % 4 != 0)
    return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_solver_options_init_sized", silently, [&]() -> avm_status {
    const avm_solver_options d = default_options();
    // Only the caller's bytes, and of those only the fields this library knows.
    std::memcpy(options, &d, std::min(size, sizeof d));
    options->struct_size = static_cast<std::uint32_t>(size);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_solver_create(const avm_solver_options* options,
                                             avm_solver** out_solver) {
  set_create_error("");
  if (out_solver == nullptr) {
    set_create_error("avm_solver_create: out_solver is NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  *out_solver = nullptr;
  return guard("avm_solver_create", to_create_error, [&]() -> avm_status {
    core_options o;
    std::string msg;
    if (!read_options(options, o, msg)) {
      set_create_error(msg.c_str());
      return AVM_ERROR_INVALID_ARGUMENT;
    }
    const am::pose_stream_options so = stream_options(o);
    if (const am::status st = so.validate(); !st.ok()) {
      const std::string m = "avm_solver_options: " + st.message();
      set_create_error(m.c_str());
      return avm_code(st);  // invalid_argument
    }
    auto* s = new avm_solver(so);
    s->latest.set_rest();
    s->last_error.reserve(128);  // push's messages fit without allocating
    *out_solver = s;
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_solver_destroy(avm_solver* solver) {
  guard_value(0, [&] {
    delete solver;
    return 0;
  });
}

AVATARMAP_C_API avm_status avm_solver_reset(avm_solver* solver) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  return guard("avm_solver_reset", to_handle(solver), [&]() -> avm_status {
    solver->stream.reset();
    solver->latest.set_rest();
    solver->latest.t = 0.0;
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_solver_push(avm_solver* solver, const avm_frame* frame) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  if (frame == nullptr)
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_push: frame is NULL");
  if (const char* bad = check_frame(*frame)) return fail(solver, AVM_ERROR_INVALID_ARGUMENT, bad);
  return guard("avm_solver_push", to_handle(solver), [&]() -> avm_status {
    convert_frame(*frame, solver->frame);
    // One pose per frame (the live filter, no grid): emit is called once.
    solver->stream.push(solver->frame, [solver](const am::proxy_pose& p) {
      solver->latest = p;
      return am::status{};
    });
    solver->latest.t = frame->t;
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_solver_get_pose(const avm_solver* solver, avm_pose* out_pose) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  if (out_pose == nullptr)
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_get_pose: out_pose is NULL");
  return guard("avm_solver_get_pose", to_handle(solver), [&]() -> avm_status {
    to_c_pose(solver->latest, *out_pose);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_solver_sample(avm_solver* solver, double t, avm_pose* out_pose) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  if (out_pose == nullptr)
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_sample: out_pose is NULL");
  if (!std::isfinite(t))
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_sample: t must be finite");
  return guard("avm_solver_sample", to_handle(solver), [&]() -> avm_status {
    if (!solver->stream.sample(t, solver->sampled)) {
      solver->sampled.set_rest();  // nothing pushed yet
      solver->sampled.t = t;
    }
    to_c_pose(solver->sampled, *out_pose);
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_solver_last_error(const avm_solver* solver) {
  return guard_value<const char*>(
      "", [&] { return solver == nullptr ? "" : solver->last_error.c_str(); });
}

AVATARMAP_C_API avm_status avm_solve_file(const char* in_landmarks, const char* out_pose,
                                          const avm_solver_options* options, char* err,
                                          size_t err_size) {
  copy_message(err, err_size, "");
  set_create_error("");
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  if (in_landmarks == nullptr || out_pose == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT, "avm_solve_file: a path is NULL");
  return guard("avm_solve_file", report, [&]() -> avm_status {
    // The library's solve-file job (the CLI's `solve` runs it too).
    am::solve_file_summary summary;
    return run_file_job(
        options, report,
        [&](am::solve_file_job& job) {
          job.input = in_landmarks;
          job.output = out_pose;
        },
        summary);
  });
}

AVATARMAP_C_API avm_status avm_solve_file_to_clip(const char* in_landmarks,
                                                  const avm_solver_options* options, avm_clip** out,
                                                  char* err, size_t err_size) {
  copy_message(err, err_size, "");
  set_create_error("");
  if (out != nullptr) *out = nullptr;
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  if (in_landmarks == nullptr || out == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT,
                  "avm_solve_file_to_clip: in_landmarks and out must not be NULL");
  return guard("avm_solve_file_to_clip", report, [&]() -> avm_status {
    // avm_solve_file's job with the poses kept in the clip instead of written.
    std::unique_ptr<avm_clip> clip(new avm_clip());
    am::solve_file_summary summary;
    const avm_status code = run_file_job(
        options, report,
        [&](am::solve_file_job& job) {
          job.input = in_landmarks;
          job.sink = [&clip](const am::proxy_pose& p) {
            clip->frames.push_back(p);
            return am::status{};
          };
        },
        summary);
    if (code != AVM_OK) return code;
    clip->source_fps = summary.fps;  // a .pose.jsonl written from it has avm_solve_file's header
    *out = clip.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_solve_frames(const avm_frame_block* frames,
                                            const avm_solver_options* options, avm_pose* out_poses,
                                            char* err, size_t err_size) {
  copy_message(err, err_size, "");
  set_create_error("");
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  if (frames == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT, "avm_solve_frames: frames is NULL");
  if (const char* bad = check_block(*frames)) return report(AVM_ERROR_INVALID_ARGUMENT, bad);
  if (frames->count > 0 && out_poses == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT, "avm_solve_frames: out_poses is NULL");
  return guard("avm_solve_frames", report, [&]() -> avm_status {
    // The same job as avm_solve_file, its frames pulled from the block and its poses put in
    // out_poses (one per frame: no resampling).
    const std::int64_t count = frames->count;
    std::int64_t next = 0, written = 0;
    auto source = [&](am::landmark_frame& out, bool& end) -> am::status {
      if (next >= count) {
        end = true;
        return {};
      }
      if (!std::isfinite(frames->t[next]))
        return am::status::error("avm_solve_frames: frames->t[" + std::to_string(next) +
                                 "] is not finite");
      block_row_to_frame(*frames, next++, out);
      return {};
    };
    auto sink = [&](const am::proxy_pose& p) -> am::status {
      if (written >= count)  // the job gives one pose per frame; never more
        return am::status::internal("avm_solve_frames: more poses than frames");
      to_c_pose(p, out_poses[written++]);
      return {};
    };
    am::solve_file_summary summary;
    const avm_status code = run_file_job(
        options, report,
        [&](am::solve_file_job& job) {
          job.input = "frames";
          job.source = source;
          job.sink = sink;
        },
        summary);
    if (code != AVM_OK) return code;
    if (written != count)
      return report(AVM_ERROR_INTERNAL, "avm_solve_frames: fewer poses than frames");
    return AVM_OK;
  });
}

}  // extern "C"
