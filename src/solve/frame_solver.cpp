// Landmarks -> proxy pose: the orchestrator. Each stage lives in its own file (docs/solver.md,
// "Stages"); what couples them is visible here:
//   prepare (solve_prepare.cpp): frame checks, mirroring, image aspect
//   -> each hand fitted to the shape learnt so far, then learnt from (hand_shape.cpp; learnt
//      in solve() only, measure() fits)
//   -> measure body (solve_body.cpp), hands (solve_hands.cpp), face (solve_face.cpp)
//   -> confidence gate (solve_gate.cpp with solve/confidence_gate.hpp): hysteresis, hold and
//      ease, blend back in, per bone, for the hips position and for the expressions.
// See include/avatarmap/solve/frame_solver.hpp.
#include "avatarmap/solve/frame_solver.hpp"

#include <cmath>
#include <limits>

#include "solve/body_hold.hpp"
#include "solve/solve_body.hpp"
#include "solve/solve_camera.hpp"
#include "solve/solve_face.hpp"
#include "solve/solve_fit.hpp"
#include "solve/solve_geometry.hpp"
#include "solve/solve_hands.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap {

using namespace solve_detail;

namespace {
// Field of view assumed until the pose has told better, and its uncertainty (a fraction of
// the focal length: 60 +-30 % covers ~45-80 degrees).
constexpr float k_prior_fov_degrees = 60.f;
constexpr double k_prior_focal_fraction = 0.3;
// Every k_focal_every-th frame is fitted, until k_focal_max_frames frames have told the focal
// length.
constexpr long k_focal_every = 3;
constexpr long k_focal_max_frames = 600;
// Most information one frame adds, as a share of the information so far: the estimate moves
// by at most a tenth of the way per sampled frame, and a few frames that happen to agree
// cannot outweigh the prior (1.1^-n of it is left after n frames).
constexpr double k_frame_information_cap = 0.1;
}  // namespace

frame_solver::frame_solver(const solver_options& options)
    : options_(options.validate().ok() ? options : solver_options{}),
      lengths_(std::make_unique<body_lengths>()),
      gravity_(std::make_unique<camera_gravity>()),
      fit_(std::make_unique<body_fit>()),
      face_calibration_(std::make_unique<face_calibration>()),
      face_features_(std::make_unique<face_features>()) {
  reset();
}

frame_solver::~frame_solver() = default;
frame_solver::frame_solver(frame_solver&&) noexcept = default;
frame_solver& frame_solver::operator=(frame_solver&&) noexcept = default;

void frame_solver::reset() {
  for (auto& b : bones_) b = rotation_gate{};
  prev_world_.fill(identity_quat());
  world_stamp_.fill(0);
  world_generation_ = 1;
  have_arm_reference_[0] = have_arm_reference_[1] = false;
  hand_shapes_[0].reset();
  hand_shapes_[1].reset();
  hips_height_state_ = gate_state{};
  ground_state_ = gate_state{};
  face_state_ = gate_state{};
  hips_height_ = hips_height_held_ = options_.rest_hips_height;
  ground_ = ground_origin_ = glm::vec2(0.f);
  have_origin_ = false;
  expressions_held_.fill(0.f);
  blendshapes_held_.fill(0.f);
  face_calibration_->reset();
  last_t_ = 0.0;
  started_ = false;
  hold_.reset();
  hold_stats_ = {};
  const bool estimate_fov = options_.horizontal_fov_degrees == 0.f;
  const float fov = estimate_fov ? k_prior_fov_degrees : options_.horizontal_fov_degrees;
  focal_per_width_ = 0.5f / std::tan(0.5f * fov * k_deg);
  const double sd = k_prior_focal_fraction * focal_per_width_;
  focal_information_ = 1.0 / (sd * sd);
  focal_weighted_sum_ = focal_information_ * focal_per_width_;
  focal_frames_ = 0;
  focal_tick_ = 0;
  focal_t_last_ = -std::numeric_limits<double>::infinity();
  lengths_->reset();
  gravity_->reset();
}

void frame_solver::restart_take(bool keep_view) {
  const float focal = focal_per_width_;
  const double information = focal_information_, weighted = focal_weighted_sum_;
  const long frames = focal_frames_, tick = focal_tick_;
  const double t_last = focal_t_last_;
  const body_lengths lengths = *lengths_;
  camera_gravity gravity = *gravity_;
  const std::array<hand_shape, 2> hands = hand_shapes_;
  const face_calibration face = *face_calibration_;
  reset();
  *face_calibration_ = face;
  focal_per_width_ = focal;
  focal_information_ = information;
  focal_weighted_sum_ = weighted;
  focal_frames_ = frames;
  focal_tick_ = tick;
  focal_t_last_ = t_last;
  *lengths_ = lengths;
  gravity.has_floor = false;  // the floor's height is found again from the start
  if (keep_view) *gravity_ = gravity;
  hand_shapes_ = hands;
}

bool frame_solver::face_calibrated() const { return face_calibration_->calibrated(); }
long frame_solver::face_calibration_frames() const { return face_calibration_->frames; }

void frame_solver::begin_face_take() {
  if (!face_take_) face_take_ = std::make_unique<face_take>();
  face_take_->frames.clear();
}

void frame_solver::add_face_take(const landmark_frame& in) {
  if (!face_take_) begin_face_take();
  // The field of view in use (given, else estimated so far): the take must be read through
  // the lens its frames will be solved with (a field of view other than the camera's shears
  // the mesh in proportion to depth, and the irises sit in front of the eye corners: a
  // mismatch reads as a constant gaze). solve_file calibrates after its warm-up, once the
  // field of view is held.
  prepared_frame f;
  prepare_frame(in, options_, focal_per_width_, f);
  face_features& ff = face_take_->frames.emplace_back();
  read_face_features(f, options_, ff);
}

bool frame_solver::end_face_take() {
  if (!face_take_) return false;
  const bool done = calibrate_take(*face_take_, *face_calibration_);
  face_take_.reset();
  return done;
}

bool frame_solver::calibrate_face(const landmark_frame* frames, std::size_t count) {
  begin_face_take();
  face_take_->frames.reserve(count);
  for (std::size_t i = 0; frames != nullptr && i < count; ++i) add_face_take(frames[i]);
  return end_face_take();
}

float frame_solver::performer_leg_length() const {
  const float thigh = lengths_->get(body_lengths::thigh);
  const float shin = lengths_->get(body_lengths::shin);
  return thigh > 0.f && shin > 0.f ? thigh + shin : 0.f;
}

bool frame_solver::ground_origin(glm::vec2& out) const {
  if (!have_origin_) return false;
  out = ground_origin_;
  return true;
}

void frame_solver::set_ground_origin(const glm::vec2& origin) {
  ground_origin_ = origin;
  have_origin_ = true;
}

float frame_solver::horizontal_fov_degrees() const {
  return 2.f * std::atan(0.5f / focal_per_width_) / k_deg;
}

void frame_solver::update_focal(const landmark_frame& in) {
  if (options_.horizontal_fov_degrees != 0.f || !(options_.image_width > 0.f)) return;
  // A sample of the take's frames tells the field of view (consecutive frames are nearly the
  // same view); the fit's cost stays off most frames.
  // The file warm-up solves its frames again (restart_take): each frame tells once.
  if (!(in.t > focal_t_last_) || gravity_->view_held) return;
  focal_t_last_ = in.t;
  if (focal_frames_ >= k_focal_max_frames || (focal_tick_++ % k_focal_every) != 0) return;
  const focal_evidence e = estimate_focal(in, options_.image_width, options_.image_height);
  if (!(e.information > 0.0)) return;
  // In units of the image width, as focal_per_width_.
  const double w = options_.image_width;
  // No frame tells more than a fraction of what is known so far: one frame whose world and
  // image points happen to agree closely must not swing the estimate (and every depth with
  // it) at once.
  const double information =
      std::min(e.information * w * w, k_frame_information_cap * focal_information_);
  focal_information_ += information;
  focal_weighted_sum_ += information * (e.focal / w);
  focal_per_width_ = static_cast<float>(focal_weighted_sum_ / focal_information_);
  gravity_->focal_lean_sum += e.lean;  // the lean with the focal length free (solve_fit.hpp)
  gravity_->focal_lean_frames += 1.0;
  ++focal_frames_;
}

const body_fit* frame_solver::fit_frame(const landmark_frame& in, bool learn, body_fit& out) const {
  if (!options_.fit_body_to_image || !options_.parts.body || !(options_.image_width > 0.f))
    return nullptr;
  const float focal = focal_per_width_ * options_.image_width;
  if (learn)
    return fit_body(in, options_.image_width, options_.image_height, focal, true, *lengths_,
                    *gravity_, out)
               ? &out
               : nullptr;
  // measure() learns nothing: it fits with copies of what was learnt so far.
  body_lengths lengths = *lengths_;
  camera_gravity gravity = *gravity_;
  return fit_body(in, options_.image_width, options_.image_height, focal, false, lengths, gravity,
                  out)
             ? &out
             : nullptr;
}

void frame_solver::hold_view(bool hold) { gravity_->view_held = hold; }

float frame_solver::camera_pitch_degrees() const { return gravity_->pitch_degrees(); }
float frame_solver::camera_roll_degrees() const { return gravity_->roll_degrees(); }
long frame_solver::gravity_evidence_frames() const { return gravity_->frames; }
long frame_solver::floor_evidence_points() const {
  glm::vec3 n;
  return gravity_->floor_normal(n) ? static_cast<long>(gravity_->floor_n) : 0;
}

void frame_solver::measure(const landmark_frame& in, frame_measurement& m) const {
  prepared_frame f;
  body_fit fit;
  prepare_frame(in, options_, focal_per_width_, f, fit_frame(in, false, fit));
  for (int side = 0; side < 2; ++side)  // the shapes learnt so far; nothing learnt
    if (fits_hand(f, side)) hand_shapes_[side].fit(f.hand[side].p, f.hand[side].c);
  face_features features;
  measure_prepared(in, f, hold_.state(), m, features);
}

bool frame_solver::fits_hand(const prepared_frame& f, int side) const {
  return options_.fit_hand_shape && options_.parts.hands && f.hand[side].c > 0.f &&
         f.hand[side].metric;
}

void frame_solver::measure_prepared(const landmark_frame& in, const prepared_frame& f,
                                    body_follow follow, frame_measurement& m,
                                    face_features& features) const {
  for (auto& b : m.bones) b.confidence = 0.f;  // the other fields are written with it
  m.hips_height_valid = m.hips_ground_valid = m.expressions_valid = false;
  m.expressions.fill(0.f);
  m.blendshapes.fill(0.f);
  // Coupling to the previous frame: a straight arm keeps the twist it had.
  const glm::quat* arm_ref[2] = {have_arm_reference_[0] ? &arm_reference_[0] : nullptr,
                                 have_arm_reference_[1] ? &arm_reference_[1] : nullptr};
  measure_body(f, options_, arm_ref, m);
  measure_hips_position(in, f, options_, m);
  // A body that is not a person's, or legs not seen: the lower body at rest (body_hold.hpp).
  if (options_.parts.body) hold_body(follow, options_.lower_body_rest, f, options_, m);
  measure_hands(f, options_, m);  // after the body: replaces its coarse wrists
  // Coupling body -> face: the neck turns relative to the upper chest, this frame's when
  // measured, else the one shown last.
  const bone_measurement& uc = m.bones[idx(bone::upper_chest)];
  const bool have_uc = uc.confidence > 0.f;
  measure_face(f, options_, have_uc ? uc.world : previous_world(idx(bone::upper_chest)), have_uc,
               *face_calibration_, features, m);
}

const glm::quat& frame_solver::previous_world(int b) const {
  // World rotation of bone b in the last output, computed on demand (few bones need it) and
  // memoised until the next output.
  if (world_stamp_[b] == world_generation_) return prev_world_[b];
  const int p = bone_parent(b);
  prev_world_[b] = p == k_no_parent ? bones_[b].output : previous_world(p) * bones_[b].output;
  world_stamp_[b] = world_generation_;
  return prev_world_[b];
}

void frame_solver::solve(const landmark_frame& in, proxy_pose& out) {
  const double t = std::isfinite(in.t) ? in.t : last_t_;
  if (started_ && t < last_t_) reset();  // a new take
  started_ = true;
  last_t_ = t;
  update_focal(in);

  frame_measurement& m = scratch_;
  prepared_frame f;
  prepare_frame(in, options_, focal_per_width_, f, fit_frame(in, true, *fit_));
  // Stage 1b: each hand fitted to the shape learnt so far, then learnt from (one alignment).
  for (int side = 0; side < 2; ++side)
    if (fits_hand(f, side)) hand_shapes_[side].fit_and_learn(f.hand[side].p, f.hand[side].c);
  body_follow follow = body_follow::all;
  if (options_.parts.body && options_.lower_body_rest != body_rest::off) {
    const body_verdict v = judge_body(in, options_.image_width, options_.image_height);
    follow = hold_.update(v, t);
    if (v.has_body) {
      ++hold_stats_.frames;
      if (follow != body_follow::all) {
        ++hold_stats_.held_frames;
        if (follow == body_follow::limbs_off) ++hold_stats_.limbs_off_frames;
        for (int i = 0; i < k_body_doubt_count; ++i)
          if ((v.doubts >> i) & 1u) ++hold_stats_.doubt_frames[i];
      }
    }
  }
  measure_prepared(in, f, follow, m, *face_features_);
  // The face's neutral learns from this frame (used from the next one on).
  face_calibration_->update(*face_features_);
  for (int side = 0; side < 2; ++side) {  // the next frame's straight-arm twist reference
    const bone_measurement& ua =
        m.bones[idx(side == 0 ? bone::left_upper_arm : bone::right_upper_arm)];
    if (ua.confidence > 0.f) {
      arm_reference_[side] = ua.world;
      have_arm_reference_[side] = true;
    }
  }
  gate_bones(m, t, out);
  out.hips_position = gate_hips_position(m, t);
  gate_expressions(m, t, out);
  out.t = t;
}

}  // namespace avatarmap
