// Stage 2c of the solver: head, eyes and expressions from the face mesh. See solve_face.hpp.
#include "solve/solve_face.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/solve/face_expressions.hpp"
#include "solve/solve_geometry.hpp"
#include "solve/solve_measurement.hpp"

namespace avatarmap::solve_detail {
namespace {

// The body-to-mesh head offset (face_calibration::body_to_mesh): learnt from frames whose
// pose face points all have at least this confidence, averaged with weight 1/n down to 2 %.
constexpr float k_head_offset_min_confidence = 0.5f;
constexpr float k_head_offset_rate = 0.02f;

// Every measurement is a ratio of 3-D distances between mesh points (in pixel units, after
// the perspective correction of solve_prepare.cpp), normalised by the eye's width (eye
// features) or by the face width between the outer eye corners (mouth features), so it holds
// at any image size and aspect ratio and for moderate head turns. A blendshape is the change
// of its measurement from the face's neutral value (face_calibration) over the change that
// reads as 1 ("full" below). docs/expressions.md has the table.

struct feature_info {
  float population;  // neutral value before calibration: the project's population face
  float quantile;    // which quantile of the face's own values is its neutral
  float full;        // a blendshape's full change (step size of the slow refinement)
  float lo, hi;      // plausible neutral values: a calibration is clamped to them
};
// The population face is the synthetic generator's default face (landmark_synth.cpp: eye
// 30 mm wide with a lid gap of 0.20 of it on average, brows 10-12 mm above the corners, mouth
// 50 mm wide, outer eye corners 92 mm apart; the iris at rest half-way along the corner line
// and 0.02 eye widths above it, as MediaPipe's meshes of two real faces looking at the
// camera put it: 0.47-0.51 along, -0.02-0.03 above). Eye gap: the 0.6 quantile, so that blinks
// (brief, below) do not pull it down; mouth gap: the 0.2 quantile (the mouth rests closed,
// talking opens it most of the time), and so the chin's drop (the jaw's rest is closed); the
// others the median.
constexpr feature_info k_features[k_face_feature_count] = {
    {0.20f, 0.6f, 0.18f, 0.08f, 0.40f},      // eye gap l
    {0.20f, 0.6f, 0.18f, 0.08f, 0.40f},      // eye gap r
    {0.41f, 0.5f, 0.25f, 0.10f, 0.90f},      // brow inner l
    {0.41f, 0.5f, 0.25f, 0.10f, 0.90f},      // brow inner r
    {0.343f, 0.5f, 0.25f, 0.f, 0.90f},       // brow outer l
    {0.343f, 0.5f, 0.25f, 0.f, 0.90f},       // brow outer r
    {-0.333f, 0.5f, 0.117f, -0.9f, 0.1f},    // cheek l
    {-0.333f, 0.5f, 0.117f, -0.9f, 0.1f},    // cheek r
    {0.f, 0.2f, 0.315f, 0.f, 0.1f},          // mouth gap
    {0.543f, 0.5f, 0.163f, 0.35f, 0.80f},    // mouth width
    {0.011f, 0.5f, 0.10f, -0.12f, 0.12f},    // corner up l
    {0.011f, 0.5f, 0.10f, -0.12f, 0.12f},    // corner up r
    {0.272f, 0.5f, 0.076f, 0.17f, 0.40f},    // corner out l
    {0.272f, 0.5f, 0.076f, 0.17f, 0.40f},    // corner out r
    {0.f, 0.5f, 0.076f, -0.15f, 0.15f},      // mouth shift
    {0.f, 0.5f, 0.10f, -0.4f, 0.4f},         // jaw shift
    {0.087f, 0.5f, 0.054f, 0.02f, 0.20f},    // upper lip height
    {0.109f, 0.5f, 0.071f, 0.02f, 0.25f},    // lower lip height
    {1.196f, 0.2f, 0.37f, 0.8f, 1.6f},       // chin drop
    {0.038f, 0.5f, 0.0435f, -0.05f, 0.15f},  // upper side l
    {0.038f, 0.5f, 0.0435f, -0.05f, 0.15f},  // upper side r
    {0.0435f, 0.5f, 0.0435f, -0.05f, 0.2f},  // lower side l
    {0.0435f, 0.5f, 0.0435f, -0.05f, 0.2f},  // lower side r
    {0.054f, 0.5f, 0.0326f, -0.1f, 0.25f},   // nose wing l
    {0.054f, 0.5f, 0.0326f, -0.1f, 0.25f},   // nose wing r
    {0.50f, 0.5f, 0.17f, 0.35f, 0.65f},      // iris u l
    {0.50f, 0.5f, 0.17f, 0.35f, 0.65f},      // iris u r
    {0.02f, 0.5f, 0.14f, -0.12f, 0.16f},     // iris v l
    {0.02f, 0.5f, 0.14f, -0.12f, 0.16f},     // iris v r
};
// After the window: a stochastic quantile estimate (Robbins-Monro). Each frame the neutral
// moves up by step * q when the value is above it, down by step * (1 - q) below, with
// step = full * max(k_refine_floor, k_refine_gain / n) after n values: a decreasing step that
// makes it the quantile of the whole take so far (a take that starts with a smile or an open
// mouth is corrected as the face comes to rest), then, after about 250 values, a floor that
// follows slow changes (at most 0.06 of a full change per second at 30 frames/s: a smile
// held two seconds moves the neutral by about 0.06).
constexpr float k_refine_gain = 0.5f;
constexpr float k_refine_floor = 0.002f;
// The iris's rest place has no window and no decreasing step: the eyes wander in any short
// window and early in a take, so its neutral starts at the population's and follows the
// take's median gaze (people look at the screen or camera most of the time) at a constant,
// small step: 0.002 of a full look per value, about 4 degrees in 10 s. (On the generator's
// tuning seeds: 2.66 degrees mean error with the population's neutral kept, 2.35 with this;
// a window, a decreasing step or the mode of a histogram all followed early fixations and
// did worse, 3.0-5.2 degrees; so did the take's gaze mode, below, learnt live from 3 s on:
// 4.02 degrees, from 10 s on 2.69.)
constexpr float k_gaze_refine_rate = 0.002f;
// An eye counts as open for the irises' calibration over a take when its lid gap is above
// this share of its neutral (a closing lid pushes MediaPipe's iris down).
constexpr float k_take_iris_open = 0.6f;

// Full changes (see the table in docs/expressions.md). Eyes: the lids shut at 0.1 of the
// neutral gap (a shut eye's lid points still stand a little apart), eyeWide full at 1.4
// times it. Brows: raised 0.25 eye widths (7.5 mm), lowered 0.133 (4 mm). Cheek: the point
// below the lid rises 0.117 eye widths (3.5 mm). Mouth, in face widths: the lower lip drops
// 0.315 (29 mm) for jawOpen; the mouth narrows to 0.7 of its neutral width for funnel/pucker,
// funnel parting the lips by 0.065 (6 mm); the corner rises 0.10 (9 mm) for a smile, which
// also moves it out by 0.6 of its rise; drops 0.054 (5 mm) for a frown; moves out 0.076
// (7 mm) beyond the smile's share for a stretch; the lips move 0.076 sideways for
// mouthLeft/Right.
constexpr float k_shut_fraction = 0.1f;
constexpr float k_wide_fraction = 0.4f;
constexpr float k_brow_up_full = 0.25f;
constexpr float k_brow_down_full = 0.133f;
constexpr float k_cheek_full = 0.117f;
constexpr float k_jaw_full = 0.315f;
constexpr float k_narrow_full = 0.3f;
constexpr float k_funnel_open = 0.065f;
constexpr float k_smile_full = 0.10f;
constexpr float k_smile_out = 0.6f;
constexpr float k_frown_full = 0.054f;
constexpr float k_stretch_full = 0.076f;
constexpr float k_shift_full = 0.076f;
// The chin moves 0.10 face widths (9 mm) sideways for jawLeft/Right (the lower lip rides on
// the jaw: the mouth's sideways measurements are taken from the upper lip alone).
// A lip rolled in (mouthRollUpper/Lower) shows 0.054 (5 mm) less of the upper lip's height,
// 0.071 (6.5 mm) less of the lower's; its outer point moves toward the lip line, so half of
// it moves the outer lips' middle the corners' height is measured from (taken back out).
constexpr float k_jaw_side_full = 0.10f;
// The chin drops 0.37 face widths (34 mm) at jawOpen 1 (more than the lower lip's 0.315: it
// is further from the jaw's hinge). The jaw read from the chin beyond the one read from the
// lips is mouthClose (the lips kept together); a difference within k_close_margin of a full
// opening reads as none (the chin's drop per lip's drop differs between faces).
constexpr float k_chin_full = 0.37f;
constexpr float k_close_margin = 0.05f;
constexpr float k_roll_upper_full = 0.054f;
// mouthUpperUp / mouthLowerDown: a lip's side point 0.0435 face widths (4 mm) off its line;
// noseSneer: the nose's wing 0.0326 (3 mm) up.
constexpr float k_upper_up_full = 0.0435f;
constexpr float k_lower_down_full = 0.0435f;
constexpr float k_sneer_full = 0.0326f;
constexpr float k_roll_lower_full = 0.071f;
// Eyeball radius in eye widths (12 mm for a 30 mm eye): the iris moves by the radius times
// the sine of the eye's turn.
constexpr float k_eyeball_radius = 0.4f;
// Gaze: above a blink of 0.7 the iris is too hidden to read; from 0.3 on its vertical turn
// fades to 0 (a closing lid pushes MediaPipe's iris down: a blink is not a look down).
constexpr float k_gaze_max_blink = 0.7f;
constexpr float k_gaze_fade_blink = 0.3f;
// Eye bones turn at most 35 degrees sideways and 25 up or down.
constexpr float k_sin_max_gaze_yaw = 0.57357644f;    // sin 35 deg
constexpr float k_sin_max_gaze_pitch = 0.42261826f;  // sin 25 deg
// The calibration learns from faces turned less than 45 degrees (a webcam sees many faces 20-35
// degrees off) from the camera; past 65 degrees the far eye and mouth corner are hidden and
// MediaPipe guesses them: no expressions are read (the gate holds the last ones, then eases them to
// 0).
constexpr float k_cos_frontal = 0.70710678f;   // cos 45 deg
constexpr float k_cos_readable = 0.42261826f;  // cos 65 deg
// Share of the head's turn (relative to the upper chest) given to the neck: the face mesh
// does not see the neck, so it takes half (0.5 also keeps quat_fraction on its exact,
// trig-free path).
constexpr float k_neck_share = 0.5f;

float clamp01(float v) { return v > 0.f ? (v < 1.f ? v : 1.f) : 0.f; }  // NaN -> 0

// `to_camera`: the unit way from the face back to the camera.
void measure_features(const face_points& fp, const glm::quat& head_w, const glm::vec3& to_camera,
                      face_features& ff) {
  auto& v = ff.v;
  const glm::vec3 head_x = head_w * k_x, head_up = head_w * k_y;
  const float facing = glm::dot(head_w * k_z, to_camera);
  ff.frontal = facing > k_cos_frontal;
  ff.readable = facing > k_cos_readable;
  ff.camera_x = glm::dot(head_x, to_camera);
  ff.camera_y = glm::dot(head_up, to_camera);
  const float face_w = glm::length(fp.eye[0].outer - fp.eye[1].outer);
  ff.valid = face_w > 1e-6f;
  ff.iris[0] = ff.iris[1] = false;
  if (!ff.valid) return;
  const float inv_face = 1.f / face_w;
  for (int s = 0; s < 2; ++s) {
    const eye_points& e = fp.eye[s];
    const glm::vec3 across = e.outer - e.inner;
    const float width = glm::length(across);
    if (!(width > 1e-6f)) {
      ff.valid = false;
      return;
    }
    const float inv_w = 1.f / width;
    const glm::vec3 ax = across * inv_w;
    const glm::vec3 up = normalize_or(orth(head_up, ax), k_y);
    float gap = 0.f;
    for (int k = 0; k < 3; ++k) gap += glm::length(e.upper[k] - e.lower[k]);
    const glm::vec3 mid = 0.5f * (e.inner + e.outer);
    v[ff_eye_gap_l + s] = gap * (1.f / 3.f) * inv_w;
    v[ff_brow_inner_l + s] = glm::dot(e.brow_inner - e.inner, up) * inv_w;
    v[ff_brow_outer_l + s] = glm::dot(e.brow_outer - e.outer, up) * inv_w;
    v[ff_cheek_l + s] = glm::dot(e.under - mid, up) * inv_w;
    if (e.has_iris) {
      v[ff_iris_u_l + s] = glm::dot(e.iris - e.inner, ax) * inv_w;
      v[ff_iris_v_l + s] = glm::dot(e.iris - mid, up) * inv_w;
      ff.iris[s] = true;
    }
  }
  const glm::vec3 up = normalize_or(orth(head_up, head_x), k_y);
  const glm::vec3 centre = 0.5f * (fp.lip_top + fp.lip_bottom);
  // The lips' opening, its sideways part left out (a jaw moved sideways carries the lower lip
  // with it: that is not an opening).
  const glm::vec3 lip_gap = fp.lip_upper - fp.lip_lower;
  v[ff_mouth_gap] = glm::length(lip_gap - glm::dot(lip_gap, head_x) * head_x) * inv_face;
  v[ff_mouth_width] = glm::length(fp.mouth[0] - fp.mouth[1]) * inv_face;
  // The upper lip's middle (outer 0 and inner 13): the mouth's sideways place, which the jaw
  // (carrying the lower lip) does not move.
  const glm::vec3 upper_lip = 0.5f * (fp.lip_top + fp.lip_upper);
  for (int s = 0; s < 2; ++s) {
    const glm::vec3 d = fp.mouth[s] - centre;
    v[ff_corner_up_l + s] = glm::dot(d, up) * inv_face;
    // The person's left corner lies toward +X, the right one toward -X.
    v[ff_corner_out_l + s] =
        glm::dot(fp.mouth[s] - upper_lip, head_x) * (s == 0 ? inv_face : -inv_face);
  }
  v[ff_mouth_shift] = glm::dot(upper_lip - fp.nose_base, head_x) * inv_face;
  // The chin against the face's midline (the line from the outer eye corners' midpoint through
  // the forehead, followed down to the chin's height): a field of view other than the
  // camera's unprojects the mesh with a sideways shear in proportion to depth, which a
  // pitched head gives the chin (docs/expressions.md). The head's X axis comes from the eye
  // corners and cheeks, which the jaw does not move, and its up axis is made perpendicular
  // to X, so a sideways chin leaves both.
  {
    const glm::vec3 eyes = 0.5f * (fp.eye[0].outer + fp.eye[1].outer);
    const glm::vec3 to_chin = fp.chin - eyes, to_forehead = fp.forehead - eyes;
    const float along = glm::dot(to_forehead, up);
    const float t = std::abs(along) > 1e-6f ? glm::dot(to_chin, up) / along : 0.f;
    v[ff_jaw_shift] = glm::dot(to_chin - t * to_forehead, head_x) * inv_face;
  }
  // The lips' visible (vermilion) heights along the head's up axis: a lip rolled in shows
  // less of it.
  v[ff_lip_upper_h] = glm::dot(fp.lip_top - fp.lip_upper, up) * inv_face;
  v[ff_lip_lower_h] = glm::dot(fp.lip_lower - fp.lip_bottom, up) * inv_face;
  // The chin below the eyes: the jaw's opening whether the lips part or not.
  v[ff_chin_drop] = glm::dot(0.5f * (fp.eye[0].outer + fp.eye[1].outer) - fp.chin, up) * inv_face;
  // A lip's side point against the line from the lip's outer middle to the corner, at the
  // point's own place across the face (along the head's X: a point moved up or down keeps its
  // place): the corners and the middle (a smile, the jaw, a roll) carry the line,
  // mouthUpperUp / mouthLowerDown move the point off it. The nose's wing against the point below
  // the nose (2, near its depth: the nose's tip stands far in front, and MediaPipe's depth is
  // not to scale): noseSneer lifts it.
  auto off_line = [&](const glm::vec3& middle, const glm::vec3& corner, const glm::vec3& p) {
    const glm::vec3 along = corner - middle;
    const float across = glm::dot(along, head_x);
    const float t = std::abs(across) > 1e-6f
                        ? glm::clamp(glm::dot(p - middle, head_x) / across, 0.f, 1.f)
                        : 0.f;
    return glm::dot(p - (middle + t * along), up) * inv_face;
  };
  for (int s = 0; s < 2; ++s) {
    v[ff_upper_side_l + s] = off_line(fp.lip_top, fp.mouth[s], fp.upper_side[s]);
    v[ff_lower_side_l + s] = -off_line(fp.lip_bottom, fp.mouth[s], fp.lower_side[s]);
    v[ff_nose_wing_l + s] = glm::dot(fp.nose_wing[s] - fp.nose_base, up) * inv_face;
  }
}

}  // namespace

void face_calibration::reset() {
  for (int i = 0; i < k_face_feature_count; ++i) neutral[i] = k_features[i].population;
  slope_x.fill(0.f);
  slope_y.fill(0.f);
  dead_zone.fill(0.f);
  from_take = false;
  iris_from_take[0] = iris_from_take[1] = false;
  filled.fill(0);
  seen.fill(0);
  settled.fill(false);
  frames = 0;
  body_to_mesh = glm::quat(1.f, 0.f, 0.f, 0.f);
  head_pairs = 0;
}

void face_calibration::learn_gaze(int i, float x) {
  // The median of the take's values at a constant, small step (no window, no decreasing
  // step): the population's neutral moves toward the face's own only as the take shows it.
  const feature_info& fi = k_features[i];
  const float step = k_gaze_refine_rate * fi.full;
  neutral[i] += x < neutral[i] ? -step * (1.f - fi.quantile) : step * fi.quantile;
  neutral[i] = glm::clamp(neutral[i], fi.lo, fi.hi);
  ++seen[i];
  settled[i] = true;
}

bool face_calibration::calibrated() const {
  for (int i = 0; i < ff_iris_u_l; ++i)
    if (!settled[i]) return false;
  return true;
}

void face_calibration::update(const face_features& f) {
  if (f.mesh_head_valid && f.body_head_valid) {
    // A running mean of the offset (nlerp with weight 1/n, at least k_head_offset_rate so a
    // change of posture or person is followed).
    glm::quat off = glm::conjugate(f.body_head) * f.mesh_head;
    if (glm::dot(off, body_to_mesh) < 0.f) off = -off;
    const float w = std::max(1.f / static_cast<float>(++head_pairs), k_head_offset_rate);
    body_to_mesh = glm::normalize(glm::mix(body_to_mesh, off, w));
  }
  if (!f.valid || !f.frontal) return;
  if (!from_take) ++frames;
  // Calibrated over the take: only the irises still learn (slowly, as live).
  for (int i = from_take ? int(ff_iris_u_l) : 0; i < k_face_feature_count; ++i) {
    if (i >= ff_iris_u_l && !f.iris[(i - ff_iris_u_l) & 1]) continue;
    const float x = f.v[i];
    if (!std::isfinite(x)) continue;
    const feature_info& fi = k_features[i];
    if (i >= ff_iris_u_l) {
      if (!iris_from_take[(i - ff_iris_u_l) & 1]) learn_gaze(i, x);
      continue;
    }
    if (!settled[i]) {
      window[i][filled[i]++] = x;
      if (filled[i] < k_window) continue;
      // The window's quantile (a copy sorted in place: fixed size, no allocation).
      std::array<float, k_window> sorted = window[i];
      const int at = std::min(k_window - 1, static_cast<int>(fi.quantile * k_window));
      std::nth_element(sorted.begin(), sorted.begin() + at, sorted.end());
      neutral[i] = glm::clamp(sorted[at], fi.lo, fi.hi);
      settled[i] = true;
      continue;
    }
    settled[i] = true;
    const float n = static_cast<float>(++seen[i] + k_window);
    const float step = fi.full * std::max(k_refine_floor, k_refine_gain / n);
    neutral[i] += x < neutral[i] ? -step * (1.f - fi.quantile) : step * fi.quantile;
    neutral[i] = glm::clamp(neutral[i], fi.lo, fi.hi);
  }
}

float face_calibration::neutral_at(int i, const face_features& f) const {
  if (!from_take) return neutral[i];
  const feature_info& fi = k_features[i];
  return glm::clamp(neutral[i] + slope_x[i] * f.camera_x + slope_y[i] * f.camera_y, fi.lo, fi.hi);
}

float face_calibration::change(int i, const face_features& f) const {
  const float c = f.v[i] - neutral_at(i, f);
  const float z = dead_zone[i];
  return c > z ? c - z : (c < -z ? c + z : 0.f);
}

namespace {

// Calibration over a take. The slopes: iteratively reweighted least squares of the value on
// (1, camera_x, camera_y) with Huber's weights (k_huber robust deviations; expressions are the
// outliers), the slopes pulled toward 0 as if k_slope_prior more frames sat at the take's mean
// turn k_slope_prior_spread away from it on each axis (a take that hardly turns gets no slope).
constexpr int k_fit_iterations = 6;
constexpr double k_huber = 1.345;
constexpr double k_slope_prior_spread = 0.05;  // about 3 degrees
// A slope moves the neutral at most this many full changes over a turn of 0.5 (30 degrees).
constexpr float k_max_slope_fulls = 2.f;
// The dead zone: this many standard deviations of the frame-to-frame noise (from the median
// absolute change between consecutive read frames, what the fit leaves), at most this share
// of a full change.
constexpr float k_dead_zone_sd = 1.5f;
constexpr float k_max_dead_zone_fulls = 0.3f;
// The gaze's mode: a Gaussian kernel's densest place over every 1 in 256 of the frames, then
// mean shifts from it. The kernel's width, 0.02 eye widths (about 3 degrees of gaze), is the
// spread of a look at the screen: a wider one merges the looks around a keyboard, say, into
// one place denser than the camera's.
constexpr float k_take_iris_bandwidth = 0.02f;
constexpr int k_take_iris_shifts = 30;
constexpr std::size_t k_take_iris_candidates = 256;

// The q-quantile of `v` (reordered).
float quantile(std::vector<float>& v, float q) {
  const std::size_t at = std::min(v.size() - 1, static_cast<std::size_t>(q * float(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(at), v.end());
  return v[at];
}

// Solves the 3x3 symmetric system a x = b (Cramer's rule); false when singular.
bool solve3(const double a[3][3], const double b[3], double x[3]) {
  auto det = [](const double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double d = det(a);
  if (!(std::abs(d) > 1e-300)) return false;
  for (int c = 0; c < 3; ++c) {
    double m[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) m[r][k] = k == c ? b[r] : a[r][k];
    x[c] = det(m) / d;
  }
  return true;
}

// One frame's iris places (u, v) of the two eyes, and their mean gaze (the right eye's u runs
// the other way).
struct eyes_at {
  glm::vec2 eye[2];
  glm::vec2 both() const { return 0.5f * glm::vec2(eye[0].x - eye[1].x, eye[0].y + eye[1].y); }
};

// The mode of the frames' mean gaze (Gaussian kernel, k_take_iris_bandwidth): the densest of
// the median and every 1 in k_take_iris_candidates frames, then mean shifts; `rest` gets each
// eye's place averaged with the kernel's weights about the mode.
void gaze_mode(const std::vector<eyes_at>& at, glm::vec2 mode, glm::vec2 rest[2]) {
  const float inv2h2 = 1.f / (2.f * k_take_iris_bandwidth * k_take_iris_bandwidth);
  auto weight = [&](const eyes_at& e, glm::vec2 p) {
    const glm::vec2 d = e.both() - p;
    return std::exp(-glm::dot(d, d) * inv2h2);
  };
  auto density = [&](glm::vec2 p) {
    float sum = 0.f;
    for (const eyes_at& e : at) sum += weight(e, p);
    return sum;
  };
  float best = density(mode);
  const std::size_t stride = std::max<std::size_t>(1, at.size() / k_take_iris_candidates);
  for (std::size_t k = 0; k < at.size(); k += stride) {
    const float dk = density(at[k].both());
    if (dk > best) {
      best = dk;
      mode = at[k].both();
    }
  }
  rest[0] = rest[1] = glm::vec2(std::numeric_limits<float>::quiet_NaN());
  for (int it = 0; it < k_take_iris_shifts; ++it) {
    glm::vec2 sum(0.f), eye0(0.f), eye1(0.f);
    float wsum = 0.f;
    for (const eyes_at& e : at) {
      const float w = weight(e, mode);
      sum += w * e.both();
      eye0 += w * e.eye[0];
      eye1 += w * e.eye[1];
      wsum += w;
    }
    if (!(wsum > 1e-6f)) return;
    mode = sum / wsum;
    rest[0] = eye0 / wsum;
    rest[1] = eye1 / wsum;
  }
}

}  // namespace

bool calibrate_take(const face_take& take, face_calibration& c) {
  std::vector<const face_features*> read;
  read.reserve(take.frames.size());
  for (const face_features& f : take.frames)
    if (f.valid && f.readable) read.push_back(&f);
  if (static_cast<int>(read.size()) < k_take_min_frames) return false;
  const std::size_t n = read.size();
  double mx = 0.0, my = 0.0;
  for (const face_features* f : read) {
    mx += f->camera_x;
    my += f->camera_y;
  }
  mx /= double(n);
  my /= double(n);
  std::vector<double> w(n);
  std::vector<float> res(n), tmp;
  tmp.reserve(n);
  for (int i = 0; i < ff_iris_u_l; ++i) {
    const feature_info& fi = k_features[i];
    // Fit in turns relative to the take's mean (the prior's centre).
    double beta[3] = {0.0, 0.0, 0.0};
    std::fill(w.begin(), w.end(), 1.0);
    for (int it = 0; it < k_fit_iterations; ++it) {
      double a[3][3] = {}, b[3] = {};
      double wsum = 0.0;
      for (std::size_t k = 0; k < n; ++k) {
        const double r[3] = {1.0, read[k]->camera_x - mx, read[k]->camera_y - my};
        for (int p = 0; p < 3; ++p) {
          b[p] += w[k] * r[p] * read[k]->v[i];
          for (int q = 0; q < 3; ++q) a[p][q] += w[k] * r[p] * r[q];
        }
        wsum += w[k];
      }
      const double prior = wsum * k_slope_prior_spread * k_slope_prior_spread;
      a[1][1] += prior;
      a[2][2] += prior;
      if (!solve3(a, b, beta)) break;
      // Huber's weights from the residuals' robust spread.
      tmp.clear();
      for (std::size_t k = 0; k < n; ++k) {
        res[k] = static_cast<float>(read[k]->v[i] - beta[0] - beta[1] * (read[k]->camera_x - mx) -
                                    beta[2] * (read[k]->camera_y - my));
        tmp.push_back(std::abs(res[k]));
      }
      const double spread = std::max(1.4826 * quantile(tmp, 0.5), 1e-4 * fi.full);
      for (std::size_t k = 0; k < n; ++k) {
        const double u = std::abs(res[k]) / (k_huber * spread);
        w[k] = u > 1.0 ? 1.0 / u : 1.0;
      }
    }
    const float max_slope = k_max_slope_fulls * fi.full / 0.5f;
    const float sx = glm::clamp(static_cast<float>(beta[1]), -max_slope, max_slope);
    const float sy = glm::clamp(static_cast<float>(beta[2]), -max_slope, max_slope);
    // The neutral: the table's quantile of what the slopes leave, at a face looking straight
    // at the camera (turns 0).
    tmp.clear();
    for (std::size_t k = 0; k < n; ++k)
      tmp.push_back(read[k]->v[i] - sx * read[k]->camera_x - sy * read[k]->camera_y);
    c.neutral[i] = quantile(tmp, fi.quantile);
    c.slope_x[i] = sx;
    c.slope_y[i] = sy;
    // The noise: the median absolute change between consecutive read frames of the take.
    tmp.clear();
    for (std::size_t k = 1; k < take.frames.size(); ++k) {
      const face_features& p = take.frames[k - 1];
      const face_features& q = take.frames[k];
      if (!(p.valid && p.readable && q.valid && q.readable)) continue;
      tmp.push_back(std::abs((q.v[i] - sx * q.camera_x - sy * q.camera_y) -
                             (p.v[i] - sx * p.camera_x - sy * p.camera_y)));
    }
    // Median |difference| of two frames' noise: 0.954 sd of one frame (normal noise).
    const float sd = tmp.empty() ? 0.f : quantile(tmp, 0.5f) / 0.954f;
    c.dead_zone[i] = std::min(k_dead_zone_sd * sd, k_max_dead_zone_fulls * fi.full);
    c.settled[i] = true;
  }
  // The irises' rest places (people look at the screen or the camera much of the time): the
  // densest place of the gaze over the read frames with both eyes open and seen (a closing lid
  // pushes MediaPipe's iris down), no slope on the head's turn (the eyes turn back toward the
  // camera as the head turns: that is gaze, not the face's proportions). The eyes turn
  // together, so the mode is sought in the two eyes' mean gaze (half each eye's noise); each
  // eye's rest is then its own mean over the frames of that mode, weighted by the kernel.
  // (Median over frontal frames before: 3.06 / 3.52 degrees mean error, clean / noisy, on the
  // held-out seeds; docs/expressions.md has the figures.)
  std::vector<eyes_at> at;
  at.reserve(n);
  for (const face_features* f : read) {
    bool open = true;
    for (int s = 0; s < 2; ++s) {
      const int gap = ff_eye_gap_l + s;
      const float rest =
          c.neutral[gap] + c.slope_x[gap] * f->camera_x + c.slope_y[gap] * f->camera_y;
      open = open && f->iris[s] && f->v[gap] > k_take_iris_open * rest;
    }
    if (open)
      at.push_back({{glm::vec2(f->v[ff_iris_u_l], f->v[ff_iris_v_l]),
                     glm::vec2(f->v[ff_iris_u_r], f->v[ff_iris_v_r])}});
  }
  if (static_cast<int>(at.size()) >= k_take_min_frames) {
    glm::vec2 start;
    for (int k = 0; k < 2; ++k) {
      tmp.clear();
      for (const eyes_at& e : at) tmp.push_back(e.both()[k]);
      start[k] = quantile(tmp, 0.5f);
    }
    glm::vec2 rest[2];
    gaze_mode(at, start, rest);
    for (int s = 0; s < 2; ++s) {
      const int iu = ff_iris_u_l + s, iv = ff_iris_v_l + s;
      if (!(std::isfinite(rest[s].x) && std::isfinite(rest[s].y))) continue;
      c.neutral[iu] = glm::clamp(rest[s].x, k_features[iu].lo, k_features[iu].hi);
      c.neutral[iv] = glm::clamp(rest[s].y, k_features[iv].lo, k_features[iv].hi);
      c.settled[iu] = c.settled[iv] = true;
      c.iris_from_take[s] = true;
    }
  }
  c.frames = static_cast<long>(n);
  c.from_take = true;
  return true;
}

bool read_face_features(const prepared_frame& f, const solver_options& o, face_features& out) {
  out.valid = out.readable = false;
  const face_points& fp = f.face;
  if (!o.parts.face || !fp.valid) return false;
  // The head from the mesh, as measure_face reads it.
  const glm::vec3 lateral = (fp.eye[0].outer - fp.eye[1].outer) + (fp.cheek[0] - fp.cheek[1]);
  const glm::quat head_w =
      frame_from_axes<k_px, k_py>(normalize_or(lateral, k_x), fp.forehead - fp.chin);
  const glm::vec3 centre = 0.5f * (fp.forehead + fp.chin);
  const glm::vec3 to_camera = normalize_or(glm::vec3(-centre.x, -centre.y, f.focal), k_z);
  measure_features(fp, head_w, to_camera, out);
  return out.valid;
}

void measure_face(const prepared_frame& f, const solver_options& o, const glm::quat& upper_chest_w,
                  bool base_measured, const face_calibration& calibration, face_features& features,
                  frame_measurement& m) {
  features.valid = false;
  features.mesh_head_valid = features.body_head_valid = false;
  if (!o.parts.face) return;
  const face_points& fp = f.face;
  glm::quat head_w;
  float c_head = 0.f;
  float c_body = 0.f;
  if (f.body.valid) {
    const body_points& b = f.body;
    using pl = pose_landmark;
    glm::vec3 lateral = b.p[idx(pl::left_ear)] - b.p[idx(pl::right_ear)];
    glm::vec3 up = 0.5f * (b.p[idx(pl::left_eye)] + b.p[idx(pl::right_eye)]) -
                   0.5f * (b.p[idx(pl::mouth_left)] + b.p[idx(pl::mouth_right)]);
    features.body_head = frame_from_axes<k_px, k_py>(normalize_or(lateral, k_x), up);
    c_body = min_conf(b, {idx(pl::left_ear), idx(pl::right_ear), idx(pl::left_eye),
                          idx(pl::right_eye), idx(pl::mouth_left), idx(pl::mouth_right)});
    features.body_head_valid = c_body >= k_head_offset_min_confidence;
  }
  if (fp.valid) {
    glm::vec3 lateral = (fp.eye[0].outer - fp.eye[1].outer) + (fp.cheek[0] - fp.cheek[1]);
    head_w = frame_from_axes<k_px, k_py>(normalize_or(lateral, k_x), fp.forehead - fp.chin);
    c_head = 1.f;
    features.mesh_head = head_w;
    features.mesh_head_valid = true;
  } else if (c_body > 0.f) {
    // The mesh is lost: the pose's face points, turned by the offset learnt between the two.
    head_w = glm::normalize(features.body_head * calibration.body_to_mesh);
    c_head = c_body;
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

  // How far the face turns from the camera: from the ray to it, not from the optical axis (a
  // face off the image's centre faces the camera when it faces along its ray). Prepared points
  // are camera coordinates in units of depth / focal length (x, y, then depth ahead as -z).
  const glm::vec3 centre = 0.5f * (fp.forehead + fp.chin);
  const glm::vec3 to_camera = normalize_or(glm::vec3(-centre.x, -centre.y, f.focal), k_z);
  const float facing = glm::dot(head_w * k_z, to_camera);
  measure_features(fp, head_w, to_camera, features);
  if (!features.valid || !(facing > k_cos_readable)) return;
  // Each measurement's change from its neutral (less the take's dead zone), and the neutral
  // itself where a shape's full change is relative to it.
  auto d = [&](int i) { return calibration.change(i, features); };
  auto neutral = [&](int i) { return calibration.neutral_at(i, features); };
  auto& b = m.blendshapes;
  b.fill(0.f);
  using bs = blendshape;
  auto set_pair = [&](bs left, int s, float w) { b[idx(left) + s] = clamp01(w); };
  // The lips' rolls move the outer lips' middle, (0 + 17) / 2, the corners' height is taken
  // from: their share comes back out.
  const float jaw_side = d(ff_jaw_shift);
  const float d_upper_h = d(ff_lip_upper_h), d_lower_h = d(ff_lip_lower_h);
  const float centre_up = 0.5f * (d_upper_h - d_lower_h);
  float blink[2];
  float inner_up = 0.f;
  for (int s = 0; s < 2; ++s) {
    const float dg = d(ff_eye_gap_l + s), gn = neutral(ff_eye_gap_l + s);
    blink[s] = clamp01(-dg / ((1.f - k_shut_fraction) * gn));
    set_pair(bs::eye_blink_left, s, blink[s]);
    set_pair(bs::eye_wide_left, s, dg / (k_wide_fraction * gn));
    const float di = d(ff_brow_inner_l + s);
    const float dout = d(ff_brow_outer_l + s);
    inner_up += 0.5f * di / k_brow_up_full;
    set_pair(bs::brow_outer_up_left, s, dout / k_brow_up_full);
    set_pair(bs::brow_down_left, s, -0.5f * (di + dout) / k_brow_down_full);
    set_pair(bs::cheek_squint_left, s, d(ff_cheek_l + s) / k_cheek_full);
    const float up = d(ff_corner_up_l + s) + centre_up;
    const float out = d(ff_corner_out_l + s);
    set_pair(bs::mouth_smile_left, s, up / k_smile_full);
    set_pair(bs::mouth_frown_left, s, -up / k_frown_full);
    set_pair(bs::mouth_stretch_left, s, (out - k_smile_out * std::max(0.f, up)) / k_stretch_full);
  }
  b[idx(bs::brow_inner_up)] = clamp01(inner_up);
  // Mouth: the lips' opening beyond neutral, less what the funnel parts them, is the jaw.
  const float open = d(ff_mouth_gap);
  const float narrow = clamp01(-d(ff_mouth_width) / (k_narrow_full * neutral(ff_mouth_width)));
  // A funnel parts the lips by k_funnel_open at full narrowing: of the narrowing, the share
  // the opening accounts for is the funnel, the rest (lips together) the pucker.
  const float funnel = std::min(narrow, clamp01(open / k_funnel_open));
  b[idx(bs::mouth_funnel)] = funnel;
  b[idx(bs::mouth_pucker)] = narrow - funnel;
  const float jaw_lips = clamp01((open - k_funnel_open * funnel) / k_jaw_full);
  const float jaw_chin = d(ff_chin_drop) / k_chin_full;
  const float close = clamp01((jaw_chin - jaw_lips - k_close_margin) / (1.f - k_close_margin));
  b[idx(bs::jaw_open)] = clamp01(jaw_lips + close);
  b[idx(bs::mouth_close)] = close;
  const float shift = d(ff_mouth_shift);
  b[idx(bs::mouth_left)] = clamp01(shift / k_shift_full);
  b[idx(bs::mouth_right)] = clamp01(-shift / k_shift_full);
  b[idx(bs::jaw_left)] = clamp01(jaw_side / k_jaw_side_full);
  b[idx(bs::jaw_right)] = clamp01(-jaw_side / k_jaw_side_full);
  b[idx(bs::mouth_roll_upper)] = clamp01(-d_upper_h / k_roll_upper_full);
  b[idx(bs::mouth_roll_lower)] = clamp01(-d_lower_h / k_roll_lower_full);
  for (int s = 0; s < 2; ++s) {
    b[idx(bs::mouth_upper_up_left) + s] = clamp01(d(ff_upper_side_l + s) / k_upper_up_full);
    b[idx(bs::mouth_lower_down_left) + s] = clamp01(d(ff_lower_side_l + s) / k_lower_down_full);
    b[idx(bs::nose_sneer_left) + s] = clamp01(d(ff_nose_wing_l + s) / k_sneer_full);
  }

  // Gaze: the iris's move from its own neutral place, over the eyeball's radius, is the sine
  // of the eye's turn. The left eye's outer corner is on the person's left (+X): moving toward
  // it is a turn toward +X; for the right eye the corner line points the other way.
  float sin_yaw[2], sin_pitch[2];
  bool seen[2] = {false, false};
  float yaw_sum = 0.f, pitch_sum = 0.f;
  int gaze_n = 0;
  for (int s = 0; s < 2; ++s) {
    if (!features.iris[s] || blink[s] >= k_gaze_max_blink) continue;
    sin_yaw[s] = d(ff_iris_u_l + s) / k_eyeball_radius * (s == 0 ? 1.f : -1.f);
    const float fade =
        clamp01((k_gaze_max_blink - blink[s]) / (k_gaze_max_blink - k_gaze_fade_blink));
    sin_pitch[s] = d(ff_iris_v_l + s) / k_eyeball_radius * fade;
    seen[s] = true;
    yaw_sum += sin_yaw[s];
    pitch_sum += sin_pitch[s];
    ++gaze_n;
  }
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
    // An eye not seen turns with the other (conjugate gaze).
    for (int s = 0; s < 2; ++s)
      eye_look_blendshapes(s == 0, seen[s] ? sin_yaw[s] : sy, seen[s] ? sin_pitch[s] : sp, b);
  }
  expressions_from_blendshapes(b, m.expressions);
  m.expressions_valid = true;
}

}  // namespace avatarmap::solve_detail
