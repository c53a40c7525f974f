// The video-file -> landmarks-file workflow, written once for the CLI (`capture`) and the C
// API (avm_capture_file): open a video file, an image, a folder of images or a printf pattern
// (or, when allowed, a device or stream), decode it a few frames ahead of the estimator on a
// second thread (a file's decoder at nice 10), estimate every frame through
// estimator::estimate_pipelined() (two lanes: a frame's body beside the previous frame's hands
// and face), and write a *.landmarks.jsonl atomically.
//
// Memory: the decode-ahead ring (3 frames of pixels) and the estimator's own; the frames are
// streamed, never held all.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/media/video_source.hpp"

namespace avatarmap {

/// What a capture_file_job reports to its progress callback.
struct capture_file_progress {
  long frames = 0;               // frames written so far
  long total_frames = 0;         // frames expected (frame count x loops); 0 = unknown
  double elapsed_seconds = 0.0;  // wall-clock time since the frames started (after start-up)
};

/// What a run did.
struct capture_file_summary {
  long frames = 0;                            // frames written
  long part_frames[k_frame_part_count] = {};  // frames that had each part
  long frames_not_decoded = 0;                // broken frames skipped with a warning
  /// Several people (options.max_people > 1; the file is then version 2, one line per person
  /// and frame): part_frames counts those lines; the lines written, the frames with at least
  /// one person, and the distinct ids seen (of the first k_max_people * 64; more are counted
  /// once each beyond that). All 0 with one person.
  long person_lines = 0, frames_with_people = 0, people_ids = 0;
  video_info input{};            // the input as opened (size, fps, codec, kind)
  double startup_ms = 0.0;       // creating the estimator (loading the models)
  double capture_seconds = 0.0;  // from the first frame's decode to the output's commit
  double seconds = 0.0;          // the whole run, opening and start-up included
  /// Sums of the estimator's per-frame timings (estimator::last_timings()) over timed_frames
  /// frames, and the frames on which each detector ran.
  estimator_timings timing_sum{};
  long timed_frames = 0;
  long pose_detector_frames = 0, palm_frames = 0, face_detector_frames = 0;
  /// Resident memory of the process (KiB; 0 = fewer than 100 frames or unknown): after 100
  /// frames, and the most seen after (every 100 frames and at the end).
  long resident_kib_after_100 = 0;
  long resident_kib_peak = 0;
  std::string estimator_description;  // estimator::describe() ("models: ...", lanes)
  /// Why a device or stream stopped (video_source::end_reason()); "" for files.
  std::string end_reason;
};

/// The job. Fill the inputs, call run(). Thread-safety: a job may be run from any thread; the
/// callbacks are called on the thread that called run().
struct capture_file_job {
  /// What video_source::open() accepts: a video file, an image, a folder of images, a printf
  /// pattern; devices ("FORMAT:DEVICE") and URLs only with allow_live_input.
  std::string input;
  /// *.landmarks.jsonl to write ("-" = standard output), atomically: on failure an existing
  /// file is left as it was.
  std::string output;
  /// The estimator's options (source = the models folder; hands, face, threads, lanes, ...).
  estimator_options options{};
  /// Creates the estimator; empty = create_estimator("onnx", ...). The CLI's adds a hint on
  /// how to get the models. A failure ends the run with its code (io: the models cannot be
  /// read; unsupported: the backend is not built).
  std::function<status(const estimator_options&, std::unique_ptr<estimator>&)> make_estimator;
  video_source_options video{};
  /// Devices and streams are read until they end or stall; refused (invalid_argument) when
  /// false, before anything is opened.
  bool allow_live_input = false;
  /// Passes over a file, >= 1 (times keep increasing: each pass starts one frame period after
  /// the last frame of the one before). Files only.
  long loops = 1;
  /// > 0: stop at this input time (seconds, the loops' times); 0 = the whole input.
  double seconds = 0.0;

  /// Optional: called after the input and the estimator are open, before the output is
  /// opened (the CLI opens its overlay here); an error ends the run, its code kept.
  std::function<status(const video_info&)> on_open;
  /// Optional: each frame written, with its decoded image (RGB8; the CLI's overlay draws on
  /// it), the frame (with several people: the first person, as estimator::estimate() gives
  /// it) and every person of it (estimator::last_people(): count -1 with one person, else
  /// the people in view, ascending by id, each with its person id; valid during the call);
  /// an error ends the run, its code kept.
  std::function<status(const image_view&, const landmark_frame&, const estimator::people_view&)>
      on_frame;
  /// Optional: after the output is committed (the CLI closes its overlay here); an error ends
  /// the run, its code kept (the landmarks are written).
  std::function<status()> on_finish;
  /// Optional: about twice a second.
  std::function<void(const capture_file_progress&)> progress;
  /// Optional: each frame that could not be decoded (skipped), one sentence without a
  /// "warning:" prefix.
  std::function<void(const std::string&)> warning;

  /// Checks the fields that need no file: input and output set, loops in [1, 1e6], seconds
  /// finite and >= 0, a live input only when allowed (and then loops 1). The message names
  /// the field.
  status validate() const;
  /// validate(), then the whole run into `out` (replaced). Fails with a message naming the
  /// input, output or the frame's time, and the code of the step that failed:
  /// invalid_argument (the fields, a live input not allowed), io (the input, the models or
  /// the output cannot be opened, read or written), unsupported (no FFmpeg for a video, no
  /// ONNX backend), internal (the estimator failed on a frame), out_of_memory; a hook's error
  /// keeps its own code. Never throws but for std::bad_alloc.
  status run(capture_file_summary& out) const;
};

/// Resident memory of this process in KiB (Linux: /proc/self/status; 0 when unknown).
long resident_memory_kib();

/// Whether `input` names a device ("FORMAT:DEVICE") or a network stream ("SCHEME://...")
/// rather than a file, folder or pattern, by video_source::open()'s rules, without opening
/// it (an existing file or folder, and "file:PATH", are files).
bool names_live_input(const std::string& input);

}  // namespace avatarmap
