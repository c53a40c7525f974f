// The pluggable landmark estimator: an image in, a landmark frame out. Backends are listed
// in one table (estimator_backends()); "replay" (recorded landmarks) is always built, so
// everything downstream is testable without models; "onnx" runs MediaPipe's models
// (capture/*_pipeline.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/core/option_table.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/media/image.hpp"

namespace avatarmap {

/// Arguments of one estimate() call; a struct so that fields can be added compatibly.
struct estimate_args {
  image_view image{};
  double t = 0.0;  // capture time, seconds
  bool body = true;
  bool hands = true;
  bool face = true;
};

/// Numeric precision of the ONNX models: the float conversions (<model>.onnx) or their int8
/// versions (<model>.int8.onnx: weights int8 per channel, activations uint8 from ranges
/// calibrated on real frames; scripts/prepare_capture.sh builds them, docs/convert.md).
/// float32 is the default: int8 is faster but leaves Google's tolerances on some references,
/// and on CPUs without VNNI on most (docs/capture.md "int8 models").
enum class model_precision : std::uint8_t { float32, int8 };

/// Whether this CPU has VNNI (AVX512-VNNI or AVX-VNNI): ONNX Runtime's int8 kernels then
/// accumulate in 32 bits; without it (AVX2 only) its u8s8 kernels saturate 16-bit sums and the
/// int8 models leave the tolerances much further (docs/capture.md).
bool cpu_has_vnni();

/// The model file name for `precision`: `stem` + ".onnx" or `stem` + ".int8.onnx".
inline std::string model_file_name(std::string_view stem, model_precision precision) {
  return std::string(stem) + (precision == model_precision::int8 ? ".int8.onnx" : ".onnx");
}

/// The most people one estimator follows at once (estimator_options::max_people, --people).
inline constexpr int k_max_people = 8;

/// Options given when a backend is created; a struct for the same reason.
struct estimator_options {
  std::string source;  // replay: the *.landmarks.jsonl path; onnx: the models folder
  int threads = 1;     // onnx: ORT intra-op threads (one pool shared by all models)
  /// onnx: let ORT's threads spin between operators: faster on an idle machine, much slower
  /// when another process holds a core (docs/capture.md has the measurements).
  bool spin = false;
  int model_complexity = 1;       // onnx: pose landmark model 0 lite, 1 full, 2 heavy
  bool static_images = false;     // onnx: detect on every frame (no tracking between frames)
  bool hands = false;             // onnx: load the hand models (estimate_args::hands then works)
  bool face = false;              // onnx: load the face models (estimate_args::face then works)
  int hand_model_complexity = 1;  // onnx: hand landmark model 0 lite, 1 full
  /// onnx: the images are mirrored (a selfie preview). Sides in the output are always the
  /// person's own; this only tells the hand model's handedness how to read the image.
  bool mirrored_input = false;
  /// onnx: with hands or face and threads >= 2, run the models on two lanes (the calling
  /// thread and a worker, each with threads / 2 ORT threads): the hands and the face of a
  /// frame side by side, and in estimate_pipelined() the body of the next frame beside them.
  /// 1: one lane, every model on all `threads` ORT threads (docs/capture.md, "Two lanes").
  int lanes = 2;
  /// onnx: the models' precision, for every model (docs/capture.md "int8 models").
  model_precision precision = model_precision::float32;
  /// onnx: the face mesh model: 0 face_landmark_with_attention (478 points with irises,
  /// refined lips and eyes; falls back to 1 when its file is missing), 1 face_landmark (468
  /// points, cheaper). docs/capture-face.md has the costs.
  int face_model = 0;
  /// onnx: how many people to follow, 1..k_max_people. 1 (the default) is the single-person
  /// capture, unchanged. More: the pose detector's boxes are kept per person (up to this many,
  /// best scores first), each person tracked with a stable id and given its own hands and face;
  /// estimate() then gives the first person (the lowest id) and last_people() every person
  /// (docs/capture-people.md). Runs on one lane.
  int max_people = 1;
  /// onnx: lift dim, low-contrast model inputs (a dark room, a washed-out picture) before the
  /// models see them; well-exposed inputs are untouched (low_light.hpp, docs/capture.md).
  bool low_light = true;
};

/// The estimator's options as every front end takes them (the CLI's capture, live and animate
/// flags, avm_estimator_options, Python's Estimator, Live and capture_file), one row per
/// option; the rows the C struct has come in its order, with its names. Defaults: the
/// struct's, except the models' threads (2) and the hands and face (on), which the front ends
/// start from (`avatarmap capture` alone turns the hands and face off by default).
inline constexpr option_row<estimator_options> k_estimator_option_table[] = {
    option_row<estimator_options>("models_dir", AVATARMAP_OPTION_TEXT(estimator_options, source))
        .cli("--models", "DIR")
        .help("converted models; empty: $AVATARMAP_MODELS/onnx, else the installed ones, else "
              "the cache scripts/prepare_capture.sh fills (`avatarmap backends` says which)"),
    option_row<estimator_options>("model_complexity",
                                  AVATARMAP_OPTION_FIELD(estimator_options, model_complexity))
        .choices("lite|full|heavy")
        .cli("--model")
        .help("pose landmark model"),
    option_row<estimator_options>("hands", AVATARMAP_OPTION_FIELD(estimator_options, hands))
        .boolean()
        .defaults_to(1)
        .cli("--hands", nullptr, "--no-hands")
        .help("estimate both hands (21 points each, image + world)"),
    option_row<estimator_options>("face", AVATARMAP_OPTION_FIELD(estimator_options, face))
        .boolean()
        .defaults_to(1)
        .cli("--face", nullptr, "--no-face")
        .help("estimate the face mesh (478 points with irises; 468 with --face-model mesh)"),
    option_row<estimator_options>("hand_model_complexity",
                                  AVATARMAP_OPTION_FIELD(estimator_options, hand_model_complexity))
        .choices("lite|full")
        .cli("--hand-model")
        .help("hand landmark model"),
    option_row<estimator_options>("threads", AVATARMAP_OPTION_FIELD(estimator_options, threads))
        .integer(1, k_max_model_threads)
        .defaults_to(2)
        .cli("--threads", "N")
        .help("threads for the models (1 is better when another process keeps a core busy)"),
    option_row<estimator_options>("mirrored",
                                  AVATARMAP_OPTION_FIELD(estimator_options, mirrored_input))
        .boolean()
        .cli("--mirrored")
        .help("the input is mirrored (a selfie preview); sides stay the person's"),
    option_row<estimator_options>("static_images",
                                  AVATARMAP_OPTION_FIELD(estimator_options, static_images))
        .boolean()
        .cli("--static")
        .help("detect on every frame (images unrelated to each other)"),
    option_row<estimator_options>("precision", AVATARMAP_OPTION_FIELD(estimator_options, precision))
        .choices("float|int8")
        .cli("--precision")
        .not_in_c()
        .help("model precision. int8 (the int8 models scripts/prepare_capture.sh builds) is "
              "faster but leaves Google's tolerances on some references, on CPUs without "
              "VNNI on most (docs/capture.md \"int8 models\")"),
    option_row<estimator_options>("lanes", AVATARMAP_OPTION_FIELD(estimator_options, lanes))
        .integer(1, 2)
        .cli("--lanes", "1|2")
        .not_in_c()
        .help("with hands or face and 2+ threads: 2 runs the hands and face beside the body "
              "(of the next frame, for files), each model on one thread; 1 runs every model "
              "on all threads in turn"),
    option_row<estimator_options>("face_model",
                                  AVATARMAP_OPTION_FIELD(estimator_options, face_model))
        .choices("attention|mesh")
        .cli("--face-model")
        .not_in_c()
        .help("face mesh model: attention = 478 points with irises (gaze), refined lips and "
              "eyes; mesh = 468 points, about half the face stage's cost"),
    option_row<estimator_options>("max_people",
                                  AVATARMAP_OPTION_FIELD(estimator_options, max_people))
        .integer(1, k_max_people)
        .defaults_to(1)
        .cli("--people", "N")
        .help("follow up to N people, each with an id, its hands and face (a version-2 "
              "landmark file, one line per person and frame); 1 is the single-person capture "
              "(docs/capture-people.md)"),
    option_row<estimator_options>("low_light", AVATARMAP_OPTION_FIELD(estimator_options, low_light))
        .boolean()
        .defaults_to(1)
        .cli("--low-light", nullptr, "--no-low-light")
        .not_in_c()
        .help("stretch the levels of a dim, low-contrast picture before the models see it "
              "(well-exposed pictures are untouched; docs/capture.md \"Low light\")"),
    option_row<estimator_options>("spin", AVATARMAP_OPTION_FIELD(estimator_options, spin))
        .boolean()
        .cli("--spin")
        .not_in_c()
        .help("let ONNX Runtime's threads spin between operators: faster on an idle machine, "
              "much slower when another process is busy"),
};

/// Where the time of the last estimate() went, milliseconds (0 for a stage that did not run).
struct estimator_timings {
  double total_ms = 0.0;  // the stages below summed (with two lanes they overlap in time)
  double pose_detector_ms = 0.0;
  double pose_landmark_ms = 0.0;
  double palm_detector_ms = 0.0;
  double hand_landmark_ms = 0.0;  // both hands together
  double face_detector_ms = 0.0;
  double face_mesh_ms = 0.0;
  int detector_runs = 0;  // detectors (pose, palm, face) run for this frame

  /// Adds another frame's timings (sums over frames).
  estimator_timings& operator+=(const estimator_timings& t) {
    total_ms += t.total_ms;
    pose_detector_ms += t.pose_detector_ms;
    pose_landmark_ms += t.pose_landmark_ms;
    palm_detector_ms += t.palm_detector_ms;
    hand_landmark_ms += t.hand_landmark_ms;
    face_detector_ms += t.face_detector_ms;
    face_mesh_ms += t.face_mesh_ms;
    detector_runs += t.detector_runs;
    return *this;
  }
};

class estimator {
 public:
  virtual ~estimator() = default;
  /// Estimates the landmarks of the frame in `args` into `out` (cleared first). A frame with
  /// no person is not an error: `out` then has no parts. Errors (a broken file, end of a
  /// replay) are reported in the status.
  virtual status estimate(const estimate_args& args, landmark_frame& out) = 0;
  /// Backend name as listed in estimator_backends().
  virtual std::string_view name() const = 0;
  /// Per-stage timings of the last estimate(), or nullptr for a backend without stages.
  /// After estimate_pipelined(): those of the frame it gave back.
  virtual const estimator_timings* last_timings() const { return nullptr; }
  /// What the backend runs, in words (e.g. which models at which precision), or "".
  virtual std::string describe() const { return {}; }

  /// Pipelined estimation, for files and other sources whose frames can wait: hands frame
  /// `in` over and gives back, in `out`, the oldest frame that is finished (`ready` true), or
  /// nothing yet (`ready` false). Frames come back in the order they went in, each with the
  /// same landmarks estimate() would give (it only overlaps the work of neighbouring frames).
  /// Call with `in` == nullptr after the last frame until `ready` is false, to drain. The
  /// pixels of a frame must stay valid until that frame has come back: up to
  /// pipeline_delay() calls later. The default finishes each frame in its own call.
  virtual status estimate_pipelined(const estimate_args* in, landmark_frame& out, bool& ready) {
    ready = false;
    if (in == nullptr) return {};
    status s = estimate(*in, out);
    ready = s.ok();
    return s;
  }
  /// How many calls of estimate_pipelined() a frame waits before it comes back (0 or 1).
  virtual int pipeline_delay() const { return 0; }

  /// Every person of the frame last given back (estimate(), or estimate_pipelined() with
  /// `ready`), when the backend follows several (estimator_options::max_people > 1): `count`
  /// frames, ascending by their `person` id, each with its own parts and the frame's t; count
  /// 0 when nobody is in view. {nullptr, -1} for a single-person backend: its one frame is
  /// the estimate. Valid until the next estimate call.
  struct people_view {
    const landmark_frame* frames = nullptr;
    int count = -1;
  };
  virtual people_view last_people() const { return {}; }
};

/// One row of the backend table.
struct estimator_backend {
  std::string_view name;
  std::string_view description;
  status (*create)(const estimator_options& options, std::unique_ptr<estimator>& out);
};

/// All backends compiled into this build. The returned span-like pair stays valid forever.
struct estimator_backend_list {
  const estimator_backend* items;
  int count;
};
estimator_backend_list estimator_backends();

/// Creates the backend called `name`; the error lists the available names when unknown.
status create_estimator(std::string_view name, const estimator_options& options,
                        std::unique_ptr<estimator>& out);

}  // namespace avatarmap
