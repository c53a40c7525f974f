// Stage 2c of the solver: head, eyes and expressions from the face mesh. See solve_face.hpp.
#include "solve/solve_face.hpp"

#include <algorithm>
#include <cmath>

#include "avatarmap/core/rotation.hpp"
#include "solve/solve_geometry.hpp"
#include "solve/solve_measurement.hpp"

namespace avatarmap::solve_detail {
namespace {

// Face thresholds. Ratios of distances measured on the face mesh (3-D, in pixels), so they
// hold for any image size, aspect ratio and moderate head turn. Unless said otherwise they
// are the project's population constants for an adult face, the same face the synthetic
// generator draws (src/synth/landmark_synth.cpp, 1.70 m person: eye width 30 mm, mouth 50 mm,
// cheek to cheek 140 mm); docs/solver.md lists them. A per-user calibration would sharpen
// them.

// Eye opening ratio (mean of the three lid gaps / corner-to-corner width, no unit) read as
// fully open at or above 0.18 and fully shut at or below 0.05. The generator's open and shut
// lids are 0.22 and 0.02: the margins keep an open or shut eye at 0 or 1 under a few percent
// of noise.
constexpr float k_eye_open_ratio = 0.18f;
constexpr float k_eye_closed_ratio = 0.05f;
// Above this eye closure (0..1) the iris is too hidden to read the gaze from that eye.
constexpr float k_gaze_max_closure = 0.7f;
// Iris centre at rest, in eye widths: 0.55 along the corner line from the inner corner and
// 0.06 above it; and the eyeball's radius, 0.4 eye widths (12 mm for a 30 mm eye): the iris
// moves by the radius times the sine of the eye's turn.
constexpr float k_iris_rest_u = 0.55f;
constexpr float k_iris_rest_v = 0.06f;
constexpr float k_eyeball_radius = 0.4f;
// Gaze limits, as sines: the eye bones turn at most 35 degrees sideways and 25 up or down;
// lookLeft/Right reach 1 at 25 degrees and lookUp/Down at 20 (VRM's lookAt presets are
// "looking fully" that way, not a physical angle: the project's choice).
constexpr float k_sin_max_gaze_yaw = 0.57357644f;    // sin 35 deg
constexpr float k_sin_max_gaze_pitch = 0.42261826f;  // sin 25 deg
constexpr float k_sin_full_look_side = 0.42261826f;  // sin 25 deg
constexpr float k_sin_full_look_vert = 0.34202014f;  // sin 20 deg
// Brow height above the middle of the upper lid, in eye widths: 0.4 at rest (12 mm); browUp
// reaches 1 at 0.267 (8 mm) above rest, browDown at 0.167 (5 mm) below.
constexpr float k_brow_rest = 0.4f;
constexpr float k_brow_up_range = 0.267f;
constexpr float k_brow_down_range = 0.167f;
// Share of the head's turn (relative to the upper chest) given to the neck: the face mesh
// does not see the neck, so it takes half (0.5 also keeps quat_fraction on its exact,
// trig-free path).
constexpr float k_neck_share = 0.5f;
// Mouth width at rest over the cheek-to-cheek width (50 mm / 140 mm).
constexpr float k_mouth_neutral_width = 0.05f / 0.14f;

// Mouth shapes: a viseme's openness (inner-lip gap / mouth width) and width (mouth width /
// neutral width). The project's shapes; the generator draws the same ones.
struct viseme_prototype {
  expression e;
  float open;   // inner-lip gap / mouth width
  float width;  // mouth width / neutral width
};
constexpr viseme_prototype k_visemes[] = {{expression::aa, 0.60f, 1.00f},
                                          {expression::ih, 0.20f, 1.10f},
                                          {expression::ou, 0.25f, 0.72f},
                                          {expression::ee, 0.25f, 1.22f},
                                          {expression::oh, 0.45f, 0.80f}};
// The closed, neutral mouth the visemes compete with.
constexpr float k_neutral_open = 0.f;
constexpr float k_neutral_width = 1.f;
// Soft assignment: a Gaussian kernel exp(-d^2 / r^2) on the distance d between the measured
// mouth and each shape, with openness scaled by 0.6 (aa's openness) and width by 0.5 so that
// both axes span about one unit, and r = 0.12 of those units: narrow enough that each
// viseme reaches >= 0.9 at its own shape (tests/solve/face_test.cpp).
constexpr float k_viseme_open_scale = 0.6f;
constexpr float k_viseme_width_scale = 0.5f;
constexpr float k_viseme_radius = 0.12f;
// Kernel exponents above 12 (weight exp(-12) = 6e-6) count as 0: skips the far shapes' exp.
constexpr float k_viseme_cutoff = 12.f;

}  // namespace

void measure_face(const prepared_frame& f, const solver_options& o, const glm::quat& upper_chest_w,
                  bool base_measured, frame_measurement& m) {
  if (!o.parts.face) return;
  const face_points& fp = f.face;
  glm::quat head_w;
  float c_head = 0.f;
  if (fp.valid) {
    glm::vec3 lateral = (fp.eye[0].outer - fp.eye[1].outer) + (fp.cheek[0] - fp.cheek[1]);
    head_w = frame_from_axes<k_px, k_py>(normalize_or(lateral, k_x), fp.forehead - fp.chin);
    c_head = 1.f;
  } else if (f.body.valid) {
    const body_points& b = f.body;
    using pl = pose_landmark;
    glm::vec3 lateral = b.p[idx(pl::left_ear)] - b.p[idx(pl::right_ear)];
    glm::vec3 up = 0.5f * (b.p[idx(pl::left_eye)] + b.p[idx(pl::right_eye)]) -
                   0.5f * (b.p[idx(pl::mouth_left)] + b.p[idx(pl::mouth_right)]);
    head_w = frame_from_axes<k_px, k_py>(normalize_or(lateral, k_x), up);
    c_head = min_conf(b, {idx(pl::left_ear), idx(pl::right_ear), idx(pl::left_eye),
                          idx(pl::right_eye), idx(pl::mouth_left), idx(pl::mouth_right)});
  }
  if (c_head > 0.f) {
    const glm::quat& base = upper_chest_w;
    const glm::quat neck_local = quat_fraction(glm::conjugate(base) * head_w, k_neck_share);
    const glm::quat neck_w = base * neck_local;
    // The neck's rotation is relative to the upper chest only when that was measured too.
    if (base_measured)
      set(m, bone::neck, neck_w, neck_local, c_head);
    else
      set(m, bone::neck, neck_w, c_head);
    set(m, bone::head, head_w, c_head);
  }
  if (!fp.valid) return;

  // Expressions. Distances are 3-D in pixel units, so they hold for any aspect ratio and for
  // moderate head turns.
  auto& ex = m.expressions;
  ex.fill(0.f);
  const glm::vec3 head_up = head_w * k_y;
  float closure[2];
  float yaw_sum = 0.f, pitch_sum = 0.f;
  int gaze_n = 0;
  for (int s = 0; s < 2; ++s) {
    const eye_points& e = fp.eye[s];
    glm::vec3 across = e.outer - e.inner;
    float width = glm::length(across);
    if (!(width > 1e-9f)) {
      closure[s] = 0.f;
      continue;
    }
    const float inv_width = 1.f / width;
    float gap = 0.f;
    for (int k = 0; k < 3; ++k) gap += glm::length(e.upper[k] - e.lower[k]);
    const float ratio = gap * (1.f / 3.f) * inv_width;
    closure[s] =
        glm::clamp((k_eye_open_ratio - ratio) / (k_eye_open_ratio - k_eye_closed_ratio), 0.f, 1.f);
    const glm::vec3 ax = across * inv_width;
    glm::vec3 up_dir = normalize_or(orth(head_up, ax), k_y);
    // Brows: height of the brow above the middle of the upper lid.
    const float brow = glm::dot(e.brow - e.upper[1], up_dir) * inv_width;
    ex[idx(s == 0 ? expression::brow_up_left : expression::brow_up_right)] =
        glm::clamp((brow - k_brow_rest) / k_brow_up_range, 0.f, 1.f);
    ex[idx(s == 0 ? expression::brow_down_left : expression::brow_down_right)] =
        glm::clamp((k_brow_rest - brow) / k_brow_down_range, 0.f, 1.f);
    if (e.has_iris && closure[s] < k_gaze_max_closure) {
      const float u = glm::dot(e.iris - e.inner, ax) * inv_width;
      const float v = glm::dot(e.iris - 0.5f * (e.inner + e.outer), up_dir) * inv_width;
      // The left eye's outer corner is on the avatar's left (+X): moving toward it is a
      // positive yaw. For the right eye the corner line points the other way.
      // The iris moves by the eyeball's radius times the sine of the eye's turn.
      yaw_sum += (u - k_iris_rest_u) / k_eyeball_radius * (s == 0 ? 1.f : -1.f);
      pitch_sum += (v - k_iris_rest_v) / k_eyeball_radius;
      ++gaze_n;
    }
  }
  const float both = std::min(closure[0], closure[1]);
  ex[idx(expression::blink)] = both;
  ex[idx(expression::blink_left)] = closure[0] - both;
  ex[idx(expression::blink_right)] = closure[1] - both;
  if (gaze_n > 0) {
    // Sines of the gaze angles, both eyes averaged, clamped to the gaze limits.
    const float sy = glm::clamp(yaw_sum / float(gaze_n), -k_sin_max_gaze_yaw, k_sin_max_gaze_yaw);
    const float sp =
        glm::clamp(pitch_sum / float(gaze_n), -k_sin_max_gaze_pitch, k_sin_max_gaze_pitch);
    // Eye bones: yaw about Y (toward +X), then pitch up (a negative turn about X).
    const glm::quat yq = axis_cos_sin(k_y, std::sqrt(1.f - sy * sy), sy);
    const glm::quat pq = axis_cos_sin(k_x, std::sqrt(1.f - sp * sp), -sp);
    // R_y * R_x of two single-axis quaternions: (a_w b_w, a_w b_x, a_y b_w, -a_y b_x).
    const glm::quat eye_local(yq.w * pq.w, yq.w * pq.x, yq.y * pq.w, -yq.y * pq.x);
    set(m, bone::left_eye, head_w * eye_local, eye_local, 1.f);
    set(m, bone::right_eye, head_w * eye_local, eye_local, 1.f);
    ex[idx(expression::look_left)] = glm::clamp(sy / k_sin_full_look_side, 0.f, 1.f);
    ex[idx(expression::look_right)] = glm::clamp(-sy / k_sin_full_look_side, 0.f, 1.f);
    ex[idx(expression::look_up)] = glm::clamp(sp / k_sin_full_look_vert, 0.f, 1.f);
    ex[idx(expression::look_down)] = glm::clamp(-sp / k_sin_full_look_vert, 0.f, 1.f);
  }
  // Mouth: a point in (openness, width) space, softly assigned to the nearest vowel shape.
  const float mouth_w = glm::length(fp.mouth[0] - fp.mouth[1]);
  const float face_w = glm::length(fp.cheek[0] - fp.cheek[1]);
  if (mouth_w > 1e-9f && face_w > 1e-9f) {
    float open = glm::length(fp.lip_upper - fp.lip_lower) / mouth_w;
    float width = (mouth_w / face_w) / k_mouth_neutral_width;
    auto kernel = [&](float po, float pw) {
      const float dox = (open - po) / k_viseme_open_scale,
                  dwx = (width - pw) / k_viseme_width_scale;
      const float e = (dox * dox + dwx * dwx) / (k_viseme_radius * k_viseme_radius);
      return e > k_viseme_cutoff ? 0.f : std::exp(-e);
    };
    float total = kernel(k_neutral_open, k_neutral_width);
    float k[5];
    for (int i = 0; i < 5; ++i) total += (k[i] = kernel(k_visemes[i].open, k_visemes[i].width));
    if (total > 0.f)
      for (int i = 0; i < 5; ++i) ex[idx(k_visemes[i].e)] = glm::clamp(k[i] / total, 0.f, 1.f);
  }
  m.expressions_valid = true;
}

}  // namespace avatarmap::solve_detail
