// avm_capture_file: `avatarmap capture INPUT -o OUT` as a library call, the library's
// capture_file_job (the CLI's `capture` runs it too) on the calling thread and its decoder's.
#include <cstddef>
#include <cstdint>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/capture/capture_file.hpp"
#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/media/video_source.hpp"
#include "c_capture_options.hpp"
#include "c_guard.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

namespace {

// The summary as far as the caller's struct goes: a caller built before the people's fields
// passes a struct_size that ends at `seconds`.
constexpr std::size_t k_summary_v1_size = offsetof(avm_capture_summary, people_ids);

void fill_summary(const am::capture_file_summary& s, avm_capture_summary& out) {
  using fp = am::frame_part;
  out.frames = s.frames;
  out.body_frames = s.part_frames[static_cast<int>(fp::pose)];
  out.left_hand_frames = s.part_frames[static_cast<int>(fp::left_hand)];
  out.right_hand_frames = s.part_frames[static_cast<int>(fp::right_hand)];
  out.face_frames = s.part_frames[static_cast<int>(fp::face)];
  out.frames_not_decoded = s.frames_not_decoded;
  out.image_width = s.input.width;
  out.image_height = s.input.height;
  out.fps = s.input.fps;
  out.seconds = s.seconds;
  if (out.struct_size >= sizeof(avm_capture_summary)) {
    out.people_ids = s.people_ids;
    out.person_lines = s.person_lines;
    out.frames_with_people = s.frames_with_people;
  }
}

}  // namespace

extern "C" {

AVATARMAP_C_API avm_status avm_capture_file(const char* input, const char* out_landmarks,
                                            const avm_estimator_options* options,
                                            avm_capture_summary* out_summary,
                                            avm_progress_fn progress, void* user, char* err,
                                            size_t err_size) {
  copy_message(err, err_size, "");
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  if (input == nullptr || out_landmarks == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT,
                  "avm_capture_file: input and out_landmarks must not be NULL");
  if (out_summary != nullptr && out_summary->struct_size < k_summary_v1_size)
    return report(AVM_ERROR_INVALID_ARGUMENT,
                  "avm_capture_file: set out_summary->struct_size = sizeof(avm_capture_summary)");
  return guard("avm_capture_file", report, [&]() -> avm_status {
    am::capture_pipeline_options po;
    double unused_extrapolation = 0.0;
    std::string msg;
    const avm_status code = read_capture_options(options, nullptr, po, unused_extrapolation, msg);
    if (code != AVM_OK) return report(code, ("avm_capture_file: " + msg).c_str());
    if (!am::video_source_available())
      return report(AVM_ERROR_UNSUPPORTED,
                    "avm_capture_file: this avatarmap library was built without FFmpeg: it "
                    "cannot decode video or images");
    am::capture_file_job job;
    job.input = input;
    job.output = out_landmarks;
    job.options = po.estimator;
    job.allow_live_input = false;
    if (progress != nullptr)
      job.progress = [&](const am::capture_file_progress& p) {
        progress(user, p.frames, p.total_frames);
      };
    am::capture_file_summary s;
    const am::status st = job.run(s);
    if (out_summary != nullptr) fill_summary(s, *out_summary);
    if (!st.ok()) return report(avm_code(st), st.message().c_str());
    if (progress != nullptr)  // the last call says where it ended
      progress(user, s.frames, s.frames);
    return AVM_OK;
  });
}

}  // extern "C"
