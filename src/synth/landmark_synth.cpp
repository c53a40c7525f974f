// Pose -> landmark frame generator of the synthetic ground truth. See
// include/avatarmap/synth/landmark_synth.hpp for the geometry and the output spaces.
//
// Face rules (head frame: VRM axes at rest, metres from the head joint, s = skeleton scale):
// - eye width w = 0.03 s (outer - inner corner); the corner lines are parallel to X.
// - the face's own proportions and the reach of each shape: synth_face_shape (the population
//   face by default, drawn per seed with synth_options::face_variation).
// - build_face() deforms the template for each ARKit shape the solver measures (lids, brows,
//   cheeks, mouth corners and lips, chin, nose wings, irises); docs/expressions.md ("The
//   generator") writes the rules out. They are the generator's own, written apart from the solver's
//   measurements.
// - irises (478 only): rest centre at inner + 0.5 (outer - inner) + 0.02 w up (+ the face's
//   own offset); gaze moves it by the eyeball radius (0.012 s) times (sin yaw, -sin pitch)
//   along the head's X / Y axes, where (pitch, yaw) = euler_from_quat(eye bone local
//   rotation, YXZ): positive yaw turns the gaze toward +X, positive pitch (right-handed about
//   +X) turns it down, so the iris moves down. Ring points 469-472 / 474-477 = centre +
//   0.0058 s * (+X, +Y, -X, -Y).
// - every other index: a deterministic point on the front half of an ellipsoid on the head.
#include "avatarmap/synth/landmark_synth.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <random>

#include "avatarmap/core/euler.hpp"
#include "avatarmap/core/rotation.hpp"

namespace avatarmap {

namespace {

// Head-frame geometry at 1.70 m (metres).
constexpr float k_eye_y = 0.11f;
constexpr float k_eye_z = 0.088f;
constexpr float k_eye_inner_x = 0.016f;
constexpr float k_eye_width = 0.03f;
constexpr float k_lid_open = 0.22f;                        // lid gap / eye width, open
constexpr float k_lid_z = 0.003f;                          // lids bulge forward over the eyeball
constexpr float k_lid_fraction[3] = {0.25f, 0.5f, 0.75f};  // from outer to inner corner
constexpr float k_mouth_y = 0.045f;
constexpr float k_mouth_z = k_eye_z;  // mouth corners at the eye corners' depth
constexpr float k_mouth_width = 0.05f;
constexpr float k_brow_above_lid = 0.012f;
constexpr float k_iris_along = 0.5f;
constexpr float k_iris_above = 0.02f;  // * eye width
constexpr float k_iris_radius = 0.0058f;

// Per eye, right side listed; the left side is its mirror image.
struct eye_indices {
  int inner, outer, outer2;  // outer2: a second index at the outer corner
  int upper[3], lower[3];
  int brow[5];                // outer -> inner
  int under[3];               // below the lower lid (outer -> inner)
  int corner_out, corner_in;  // points just outside each corner
  int iris;                   // centre; ring = iris + 1 .. iris + 4
};
constexpr eye_indices k_right_eye{
    133, 130, 33, {160, 159, 158}, {144, 145, 153}, {70, 63, 105, 66, 107}, {229, 230, 231},
    35,  244, 468};
constexpr eye_indices k_left_eye{
    362, 263, 359, {387, 386, 385}, {373, 374, 380}, {300, 293, 334, 296, 336}, {449, 450, 451},
    265, 464, 473};
constexpr float k_brow_fraction[5] = {-0.15f, 0.15f, 0.5f, 0.85f, 1.1f};
// Shares of a brow's moves along it (outer -> inner) and of the lid gap along the lid.
constexpr float k_brow_inner_share[5] = {0.f, 0.2f, 0.5f, 0.85f, 1.f};
constexpr float k_brow_outer_share[5] = {1.f, 0.85f, 0.5f, 0.2f, 0.f};
constexpr float k_brow_down_share[5] = {0.6f, 0.8f, 1.f, 1.f, 1.f};
constexpr float k_lid_arc[3] = {0.85f, 1.f, 0.9f};
constexpr float k_brow_shape[5] = {0.007f, 0.010f, 0.012f, 0.011f, 0.009f};

// Fixed points: right side (x < 0) or the midline; mirrored pairs below.
struct fixed_point {
  int index;
  int mirror;  // -1 on the midline
  glm::vec3 p;
};
const fixed_point k_fixed[] = {
    {1, -1, {0.f, 0.075f, 0.115f}},        // nose tip
    {4, -1, {0.f, 0.080f, 0.113f}},        // nose tip (upper)
    {2, -1, {0.f, 0.063f, 0.103f}},        // below the nose
    {6, -1, {0.f, 0.110f, 0.098f}},        // nose bridge
    {168, -1, {0.f, 0.120f, 0.096f}},      // between the brows
    {10, -1, {0.f, 0.185f, 0.085f}},       // forehead
    {152, -1, {0.f, 0.000f, 0.085f}},      // chin
    {234, 454, {-0.07f, 0.09f, 0.035f}},   // cheeks
    {21, 251, {-0.065f, 0.145f, 0.04f}},   // temples
    {172, 397, {-0.055f, 0.025f, 0.03f}},  // jaw angles
    {127, 356, {-0.072f, 0.105f, 0.02f}},  // beside the eyes
    {93, 323, {-0.068f, 0.065f, 0.03f}},
    {132, 361, {-0.062f, 0.045f, 0.03f}},
    {58, 288, {-0.06f, 0.035f, 0.03f}},
    {98, 327, {-0.016f, 0.068f, 0.097f}},  // nose wings, beside the nostrils
};

void set_eye_rest(std::array<glm::vec3, k_face_mesh_iris_count>& t, const eye_indices& e,
                  float side, float s) {
  const float w = k_eye_width * s;
  const glm::vec3 inner(side * k_eye_inner_x * s, k_eye_y * s, k_eye_z * s);
  const glm::vec3 outer = inner + glm::vec3(side * w, 0.f, 0.f);
  t[e.inner] = inner;
  t[e.outer] = outer;
  t[e.outer2] = outer;
  for (int i = 0; i < 3; ++i) {
    glm::vec3 on_line = outer + k_lid_fraction[i] * (inner - outer);
    on_line.z += k_lid_z * s;
    t[e.upper[i]] = on_line + glm::vec3(0.f, 0.5f * k_lid_open * w, 0.f);
    t[e.lower[i]] = on_line - glm::vec3(0.f, 0.5f * k_lid_open * w, 0.f);
    glm::vec3 under = outer + k_lid_fraction[i] * (inner - outer);
    under.y -= 0.010f * s;
    t[e.under[i]] = under;
  }
  const float lid_top = k_eye_y * s + 0.5f * k_lid_open * w;
  for (int i = 0; i < 5; ++i) {
    glm::vec3 b = outer + k_brow_fraction[i] * (inner - outer);
    b.y = lid_top + k_brow_shape[i] * s;
    b.z = (k_eye_z + 0.006f) * s;
    t[e.brow[i]] = b;
  }
  t[e.corner_out] = outer + glm::vec3(side * 0.004f * s, -0.002f * s, -0.002f * s);
  t[e.corner_in] = inner + glm::vec3(-side * 0.003f * s, -0.001f * s, 0.f);
  const glm::vec3 iris =
      inner + k_iris_along * (outer - inner) + glm::vec3(0.f, k_iris_above * w, 0.004f * s);
  t[e.iris] = iris;
  const float r = k_iris_radius * s;
  t[e.iris + 1] = iris + glm::vec3(r, 0.f, 0.f);
  t[e.iris + 2] = iris + glm::vec3(0.f, r, 0.f);
  t[e.iris + 3] = iris + glm::vec3(-r, 0.f, 0.f);
  t[e.iris + 4] = iris + glm::vec3(0.f, -r, 0.f);
}

// The outer lips' side points (upper 39 / 269, lower 181 / 405, two out from the middle):
// k_lip_side_along of the way from the lip's outer middle (0, 17) to the corner, the upper
// k_upper_bow above that line, the lower k_lower_bow below it (the lips' curves; MediaPipe's
// mesh of portrait.jpg puts them 0.04 and 0.08 face widths off), moved up / down by
// `up_r`/`up_l` and `down_r`/`down_l` (metres, the person's right / left).
constexpr float k_lip_side_along = 0.6f;
constexpr float k_upper_bow = 0.0035f;
constexpr float k_lower_bow = 0.004f;
void set_lip_sides(std::array<glm::vec3, k_face_mesh_iris_count>& t, float s, float up_r,
                   float up_l, float down_r, float down_l) {
  t[39] = glm::mix(t[0], t[61], k_lip_side_along) + glm::vec3(0.f, k_upper_bow * s + up_r, 0.f);
  t[269] = glm::mix(t[0], t[291], k_lip_side_along) + glm::vec3(0.f, k_upper_bow * s + up_l, 0.f);
  t[181] = glm::mix(t[17], t[61], k_lip_side_along) - glm::vec3(0.f, k_lower_bow * s + down_r, 0.f);
  t[405] =
      glm::mix(t[17], t[291], k_lip_side_along) - glm::vec3(0.f, k_lower_bow * s + down_l, 0.f);
}

// Mouth points for a given width and inner-lip gap (metres).
void set_mouth(std::array<glm::vec3, k_face_mesh_iris_count>& t, float width, float gap, float s) {
  const float y = k_mouth_y * s;
  const float h = 0.5f * width;
  t[61] = glm::vec3(-h, y, k_mouth_z * s);
  t[291] = glm::vec3(h, y, k_mouth_z * s);
  t[78] = glm::vec3(-0.9f * h, y, (k_mouth_z + 0.003f) * s);
  t[308] = glm::vec3(0.9f * h, y, (k_mouth_z + 0.003f) * s);
  t[13] = glm::vec3(0.f, y + 0.25f * gap, 0.095f * s);
  t[14] = glm::vec3(0.f, y - 0.75f * gap, 0.095f * s);
  t[0] = glm::vec3(0.f, y + 0.008f * s + 0.25f * gap, 0.099f * s);
  t[17] = glm::vec3(0.f, y - 0.010f * s - 0.75f * gap, 0.097f * s);
  set_lip_sides(t, s, 0.f, 0.f, 0.f, 0.f);
}

void build_template(std::array<glm::vec3, k_face_mesh_iris_count>& t, float s) {
  // Filler: golden-angle spiral on the front half of an ellipsoid around the head.
  const glm::vec3 centre(0.f, 0.095f, 0.01f);
  const glm::vec3 radii(0.075f, 0.11f, 0.09f);
  constexpr float k_golden = 2.39996323f;
  for (int i = 0; i < k_face_mesh_iris_count; ++i) {
    float nz = (static_cast<float>(i) + 0.5f) / static_cast<float>(k_face_mesh_iris_count);
    float r = std::sqrt(std::max(0.f, 1.f - nz * nz));
    float phi = k_golden * static_cast<float>(i);
    glm::vec3 n(r * std::cos(phi), r * std::sin(phi), nz);
    t[i] = (centre + radii * n) * s;
  }
  for (const fixed_point& f : k_fixed) {
    t[f.index] = f.p * s;
    if (f.mirror >= 0) t[f.mirror] = mirror_x(f.p) * s;
  }
  set_eye_rest(t, k_right_eye, -1.f, s);
  set_eye_rest(t, k_left_eye, 1.f, s);
  set_mouth(t, k_mouth_width * s, 0.f, s);
}

float clamp01(float v) { return std::isfinite(v) ? std::min(1.f, std::max(0.f, v)) : 0.f; }

}  // namespace

glm::vec3 face_template_point(int index, float scale) {
  assert(index >= 0 && index < k_face_mesh_iris_count);
  std::array<glm::vec3, k_face_mesh_iris_count> t;
  build_template(t, scale);
  return t[std::min(std::max(index, 0), k_face_mesh_iris_count - 1)];
}

synth_viseme_shape blend_visemes(const proxy_pose& pose) {
  float w[5];
  float sum = 0.f;
  for (int i = 0; i < 5; ++i) {
    w[i] = clamp01(pose.expressions[idx(expression::aa) + i]);
    sum += w[i];
  }
  float norm = sum > 1.f ? 1.f / sum : 1.f;
  synth_viseme_shape out{0.f, 0.f};
  float used = 0.f;
  for (int i = 0; i < 5; ++i) {
    float wi = w[i] * norm;
    out.open += wi * k_synth_visemes[i].open;
    out.width_scale += wi * k_synth_visemes[i].width_scale;
    used += wi;
  }
  out.width_scale += std::max(0.f, 1.f - used);  // neutral (0, 1)
  return out;
}

synth_face_shape draw_face_shape(std::uint32_t seed) {
  // Its own generator: the face must not shift the camera, noise or burst sequences.
  std::mt19937 g(seed ^ 0xface5u);
  auto u = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(g); };
  synth_face_shape f;
  const float open = u(0.17f, 0.28f);
  f.eye_open[0] = open * u(0.95f, 1.05f);
  f.eye_open[1] = open * u(0.95f, 1.05f);
  f.shut_fraction = u(0.05f, 0.14f);
  f.wide_gain = u(0.34f, 0.46f);
  const float brow = u(-0.002f, 0.002f);
  f.brow_offset[0] = brow + u(-0.0005f, 0.0005f);
  f.brow_offset[1] = brow + u(-0.0005f, 0.0005f);
  f.brow_raise = u(0.0068f, 0.0082f);
  f.brow_lower = u(0.0045f, 0.0055f);
  f.cheek_raise = u(0.003f, 0.004f);
  f.mouth_width = u(0.045f, 0.056f);
  f.jaw_drop = u(0.027f, 0.031f);
  f.corner_follow = u(0.46f, 0.54f);
  f.narrow = u(0.27f, 0.33f);
  f.funnel_open = u(0.005f, 0.007f);
  f.smile_rise = u(0.0082f, 0.0098f);
  f.smile_out = u(0.5f, 0.7f);
  f.stretch_out = u(0.0065f, 0.0075f);
  f.frown_drop = u(0.0045f, 0.0055f);
  f.shift = u(0.0065f, 0.0075f);
  f.eyeball_radius = u(0.0112f, 0.0128f);
  f.iris_u = u(-0.03f, 0.03f);
  f.iris_v = u(-0.03f, 0.03f);
  f.jaw_side = u(0.0085f, 0.0105f);
  f.roll_upper = u(0.0045f, 0.0055f);
  f.roll_lower = u(0.006f, 0.007f);
  f.chin_ratio = u(1.12f, 1.22f);
  f.upper_up = u(0.0035f, 0.0045f);
  f.lower_down = u(0.0035f, 0.0045f);
  f.sneer = u(0.0025f, 0.0035f);
  return f;
}

void set_truth_expressions(proxy_pose& pose) {
  for (int side = 0; side < 2; ++side) {
    const glm::quat q = glm::normalize(pose[side == 0 ? bone::left_eye : bone::right_eye]);
    const glm::vec3 pyr = euler_from_quat(q, euler_order::yxz);  // x = pitch (+ = down), y = yaw
    eye_look_blendshapes(side == 0, std::sin(pyr.y), -std::sin(pyr.x), pose.blendshapes);
  }
  expressions_from_blendshapes(pose.blendshapes, pose.expressions);
}

void blendshapes_from_expressions(const proxy_pose& pose, blendshape_weights& out) {
  out.fill(0.f);
  auto e = [&](expression x) { return clamp01(pose[x]); };
  const float blink = e(expression::blink);
  out[idx(blendshape::eye_blink_left)] = clamp01(blink + e(expression::blink_left));
  out[idx(blendshape::eye_blink_right)] = clamp01(blink + e(expression::blink_right));
  out[idx(blendshape::jaw_open)] =
      clamp01(e(expression::aa) + e(expression::ih) + e(expression::oh));
  const float stretch = clamp01(e(expression::ih) + e(expression::ee));
  out[idx(blendshape::mouth_stretch_left)] = stretch;
  out[idx(blendshape::mouth_stretch_right)] = stretch;
  out[idx(blendshape::mouth_funnel)] = e(expression::oh);
  out[idx(blendshape::mouth_pucker)] = e(expression::ou);
  const float up_l = e(expression::brow_up_left), up_r = e(expression::brow_up_right);
  out[idx(blendshape::brow_outer_up_left)] = up_l;
  out[idx(blendshape::brow_outer_up_right)] = up_r;
  out[idx(blendshape::brow_inner_up)] = std::min(up_l, up_r);
  out[idx(blendshape::brow_down_left)] = e(expression::brow_down_left);
  out[idx(blendshape::brow_down_right)] = e(expression::brow_down_right);
}

status synth_options::validate() const {
  if (!(image_width > 0) || !(image_height > 0))
    return status::error("synth_options.image_width/image_height must be > 0");
  if (!(horizontal_fov_degrees > 1.f && horizontal_fov_degrees < 179.f))
    return status::error("synth_options.horizontal_fov_degrees must be in (1, 179)");
  if (!std::isfinite(camera_position.x) || !std::isfinite(camera_position.y) ||
      !std::isfinite(camera_position.z))
    return status::error("synth_options.camera_position must be finite");
  if (!(person_height > 0.f) || !std::isfinite(person_height))
    return status::error("synth_options.person_height must be finite and > 0 metres");
  auto bad_sigma = [](float v) { return !(v >= 0.f) || !std::isfinite(v); };
  if (bad_sigma(body_noise_sigma) || bad_sigma(hand_noise_sigma) || bad_sigma(face_noise_sigma))
    return status::error("synth_options.*_noise_sigma must be finite and >= 0 metres");
  if (random_camera) {
    if (!(fov_min_degrees > 1.f && fov_max_degrees < 179.f && fov_min_degrees <= fov_max_degrees))
      return status::error(
          "synth_options.fov_min_degrees/fov_max_degrees must satisfy 1 < min <= max < 179");
    if (!(distance_min > 0.f && distance_min <= distance_max && std::isfinite(distance_max)))
      return status::error(
          "synth_options.distance_min/distance_max must satisfy 0 < min <= max (metres, finite)");
    if (!(camera_height_min <= camera_height_max) || !std::isfinite(camera_height_min) ||
        !std::isfinite(camera_height_max))
      return status::error(
          "synth_options.camera_height_min/camera_height_max must be finite with min <= max");
    if (!(off_centre_max >= 0.f && off_centre_max <= 1.f))
      return status::error("synth_options.off_centre_max must be in [0, 1]");
  }
  if (!(low_visibility_fraction >= 0.f && low_visibility_fraction <= 0.9f))
    return status::error("synth_options.low_visibility_fraction must be in [0, 0.9]");
  if (!(low_visibility_seconds > 0.f && low_visibility_seconds <= 3600.f))
    return status::error("synth_options.low_visibility_seconds must be in (0, 3600]");
  if (!(low_visibility_min >= 0.f && low_visibility_min <= low_visibility_max &&
        low_visibility_max <= 1.f))
    return status::error(
        "synth_options.low_visibility_min/low_visibility_max must satisfy 0 <= min <= max <= 1");
  if (bad_sigma(low_visibility_noise_sigma))
    return status::error("synth_options.low_visibility_noise_sigma must be finite and >= 0 metres");
  if (!(max_wrist_speed > 0.f && max_wrist_speed <= 100.f))
    return status::error("synth_options.max_wrist_speed must be in (0, 100] rad/s");
  if (!(finger_side_bend_degrees >= 0.f && finger_side_bend_degrees <= 45.f))
    return status::error("synth_options.finger_side_bend_degrees must be in [0, 45]");
  return {};
}

int synth_limb_of(bone b) {
  switch (b) {
    case bone::left_upper_leg:
    case bone::left_lower_leg:
    case bone::left_foot:
    case bone::left_toes:
      return static_cast<int>(synth_limb::left_leg);
    case bone::right_upper_leg:
    case bone::right_lower_leg:
    case bone::right_foot:
    case bone::right_toes:
      return static_cast<int>(synth_limb::right_leg);
    case bone::left_upper_arm:
    case bone::left_lower_arm:
    case bone::left_hand:
      return static_cast<int>(synth_limb::left_arm);
    case bone::right_upper_arm:
    case bone::right_lower_arm:
    case bone::right_hand:
      return static_cast<int>(synth_limb::right_arm);
    default:
      break;
  }
  const int i = idx(b);
  if (i >= idx(bone::left_thumb_metacarpal) && i <= idx(bone::left_little_distal))
    return static_cast<int>(synth_limb::left_arm);
  if (i >= idx(bone::right_thumb_metacarpal) && i <= idx(bone::right_little_distal))
    return static_cast<int>(synth_limb::right_arm);
  return -1;
}

landmark_synth::landmark_synth(const synth_options& options)
    : skeleton_(make_proxy_skeleton(options.validate().ok() ? options.person_height
                                                            : k_proxy_reference_height)),
      options_(options) {
  init();
}

landmark_synth::landmark_synth(const proxy_skeleton& skeleton, const synth_options& options)
    : skeleton_(skeleton), options_(options) {
  init();
}

void landmark_synth::init() {
  assert(options_.validate().ok());
  if (!options_.validate().ok()) {
    synth_options defaults;
    defaults.person_height = options_.person_height;
    options_ = defaults;
  }
  camera_ = options_.camera_position;
  fov_degrees_ = options_.horizontal_fov_degrees;
  if (options_.random_camera) {
    // A generator of its own (seed mixed with a constant), so the noise sequence of a seed is
    // the same with and without the random camera.
    std::mt19937 g(options_.seed ^ 0x5eed0cafu);
    auto draw = [&g](float lo, float hi) {
      return lo + (hi - lo) * std::uniform_real_distribution<float>(0.f, 1.f)(g);
    };
    fov_degrees_ = draw(options_.fov_min_degrees, options_.fov_max_degrees);
    const float distance = draw(options_.distance_min, options_.distance_max);
    const float height = draw(options_.camera_height_min, options_.camera_height_max);
    const float half_width = distance * std::tan(0.5f * fov_degrees_ * k_pi / 180.f);
    // The camera moves sideways so that the origin appears off the image centre.
    const float offset = draw(-options_.off_centre_max, options_.off_centre_max) * half_width;
    camera_ = glm::vec3(offset, height, distance);
  }
  if (options_.camera_y_scales_with_height) camera_.y *= skeleton_.scale;
  const float half_fov = 0.5f * fov_degrees_ * k_pi / 180.f;
  focal_ = 0.5f * static_cast<float>(options_.image_width) / std::tan(half_fov);
  build_template(face_template_, skeleton_.scale);
  face_shape_ = options_.face_variation ? draw_face_shape(options_.seed) : synth_face_shape{};
  reseed(options_.seed);
}

void landmark_synth::reseed(std::uint32_t seed) {
  rng_.seed(seed);
  normal_.reset();
  burst_rng_.seed(seed ^ 0xb0a57u);
  bursts_started_ = false;
  in_burst_.fill(false);
}

void landmark_synth::update_bursts(double t) {
  in_burst_.fill(false);
  const double f = options_.low_visibility_fraction;
  if (!(f > 0.0) || !std::isfinite(t)) return;
  const double mean_burst = options_.low_visibility_seconds;
  // Gaps uniform in [0.2 G, 1.8 G] with G = mean_burst (1 - f) / f: bursts take f of the time
  // on average (renewal process: E[burst] / (E[burst] + E[gap])) and never run into each other.
  const double mean_gap = mean_burst * (1.0 - f) / f;
  auto uniform = [this](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(burst_rng_);
  };
  auto schedule_from = [&](int l, double from) {
    burst_start_[l] = from + uniform(0.2 * mean_gap, 1.8 * mean_gap);
    burst_end_[l] = burst_start_[l] + mean_burst * uniform(0.6, 1.4);
  };
  if (!bursts_started_ || t < last_t_) {
    for (int l = 0; l < k_synth_limb_count; ++l) schedule_from(l, t);
    bursts_started_ = true;
  }
  last_t_ = t;
  for (int l = 0; l < k_synth_limb_count; ++l) {
    // Bounded: a jump far ahead skips the missed bursts rather than drawing all of them.
    for (int guard = 0; t >= burst_end_[l] && guard < 1000; ++guard)
      schedule_from(l, burst_end_[l]);
    if (t >= burst_end_[l]) schedule_from(l, t);
    in_burst_[l] = t >= burst_start_[l] && t < burst_end_[l];
  }
}

float landmark_synth::draw_visibility() {
  return std::uniform_real_distribution<float>(options_.low_visibility_min,
                                               options_.low_visibility_max)(burst_rng_);
}

void landmark_synth::add_noise_at(glm::vec3* points, const int* indices, int count, float sigma) {
  if (!(sigma > 0.f)) return;
  // The burst generator, so the regular noise sequence does not shift with the bursts.
  std::normal_distribution<float> n(0.f, sigma);
  for (int i = 0; i < count; ++i) {
    glm::vec3& p = points[indices[i]];
    p.x += n(burst_rng_);
    p.y += n(burst_rng_);
    p.z += n(burst_rng_);
  }
}

namespace {
glm::vec3 project_with(const glm::vec3& camera, float focal, float width, float height,
                       const glm::vec3& p, float z_ref) {
  const float xc = p.x - camera.x;
  const float yc = -(p.y - camera.y);
  const float zc = std::max(camera.z - p.z, 1e-3f);
  const float zr = std::max(z_ref, 1e-3f);
  const float u = 0.5f * width + focal * xc / zc;
  const float v = 0.5f * height + focal * yc / zc;
  return glm::vec3(u / width, v / height, (zc - zr) * focal / (zr * width));
}

void put(landmark& l, const glm::vec3& v) {
  l.x = v.x;
  l.y = v.y;
  l.z = v.z;
  l.visibility = 1.f;
  l.presence = 1.f;
}

glm::vec3 to_mediapipe(const glm::vec3& v) { return glm::vec3(v.x, -v.y, -v.z); }

void swap_expressions(proxy_pose& p, expression a, expression b) {
  std::swap(p.expressions[idx(a)], p.expressions[idx(b)]);
}
}  // namespace

glm::vec3 landmark_synth::project(const glm::vec3& vrm_point, float z_ref) const {
  return project_with(camera_, focal_, static_cast<float>(options_.image_width),
                      static_cast<float>(options_.image_height), vrm_point, z_ref);
}

void landmark_synth::add_noise(glm::vec3* points, int count, float sigma) {
  if (!(sigma > 0.f)) return;
  for (int i = 0; i < count; ++i) {
    points[i].x += sigma * normal_(rng_);
    points[i].y += sigma * normal_(rng_);
    points[i].z += sigma * normal_(rng_);
  }
}

void landmark_synth::build_face(const proxy_pose& pose) {
  // Deformed head-frame template into points_.face, then to VRM space. The shapes are drawn
  // from the pose's blendshapes (those of its expressions when it carries none).
  std::array<glm::vec3, k_face_mesh_iris_count>& f = points_.face;
  f = face_template_;
  const float s = skeleton_.scale;
  const float w = k_eye_width * s;
  const synth_face_shape& fs = face_shape_;
  blendshape_weights bw = pose.blendshapes;
  bool any = false;
  for (float v : bw) any = any || v > 0.f;
  if (!any) blendshapes_from_expressions(pose, bw);
  auto B = [&](blendshape x, int side = 0) { return clamp01(bw[idx(x) + side]); };

  // Eyes. side 0 = the person's left (+X).
  for (int side = 0; side < 2; ++side) {
    const eye_indices& e = side == 0 ? k_left_eye : k_right_eye;
    const float sx = side == 0 ? 1.f : -1.f;
    const float open = fs.eye_open[side] * w;
    const float blink = B(blendshape::eye_blink_left, side);
    const float wide = B(blendshape::eye_wide_left, side);
    // The lid gap closes to shut_fraction of it and opens by wide_gain; the upper lid makes
    // 80 % of the change. The three lid pairs stand apart on an arc (0.85, 1, 0.9 of the gap).
    const float gap = open * (1.f - (1.f - fs.shut_fraction) * blink) +
                      fs.wide_gain * open * wide * (1.f - blink);
    const float change = open - gap;
    const float line_y = face_template_[e.inner].y;
    for (int i = 0; i < 3; ++i) {
      f[e.upper[i]].y = line_y + k_lid_arc[i] * (0.5f * open - 0.8f * change);
      f[e.lower[i]].y = line_y - k_lid_arc[i] * (0.5f * open - 0.2f * change);
    }
    // Brows (outer -> inner): the inner raise lifts the inner end, the outer raise the outer
    // end, each fading along the brow; browDown lowers it, the inner end most, and draws the
    // inner end toward the nose.
    const float inner_up = B(blendshape::brow_inner_up);
    const float outer_up = B(blendshape::brow_outer_up_left, side);
    const float down = B(blendshape::brow_down_left, side);
    for (int i = 0; i < 5; ++i) {
      glm::vec3& p = f[e.brow[i]];
      p.y += fs.brow_offset[side] * s +
             fs.brow_raise * s *
                 (inner_up * k_brow_inner_share[i] + outer_up * k_brow_outer_share[i]) -
             fs.brow_lower * s * down * k_brow_down_share[i];
      p.x -= sx * 0.001f * s * down * k_brow_inner_share[i];
    }
    const float cheek = B(blendshape::cheek_squint_left, side);
    for (int i = 0; i < 3; ++i)
      f[e.under[i]].y += fs.cheek_raise * s * cheek * (i == 1 ? 1.f : 0.8f);
    // Iris: its own rest place, moved by the eyeball's radius times the sines of the turn.
    glm::quat q = glm::normalize(pose[side == 0 ? bone::left_eye : bone::right_eye]);
    glm::vec3 pyr = euler_from_quat(q, euler_order::yxz);  // x = pitch, y = yaw
    glm::vec3 move(sx * fs.iris_u * w + fs.eyeball_radius * s * std::sin(pyr.y),
                   fs.iris_v * w - fs.eyeball_radius * s * std::sin(pyr.x), 0.f);
    if (!is_finite(move)) move = glm::vec3(0.f);
    for (int i = 0; i < 5; ++i) f[e.iris + i] += move;
  }

  // Mouth: the corners (291 left, 61 right) from the width, smile, stretch, frown and the
  // jaw; the lips' middles (13/14 inner, 0/17 outer) from the jaw and the funnel.
  const float round = std::max(B(blendshape::mouth_funnel), B(blendshape::mouth_pucker));
  const float half_w = 0.5f * fs.mouth_width * s * (1.f - fs.narrow * round);
  // The jaw drops the chin; the lips follow it but for what mouthClose keeps together (the
  // lower lip rises back by that share of the jaw's drop).
  const float jaw_open = B(blendshape::jaw_open);
  const float closed = std::min(B(blendshape::mouth_close), jaw_open);
  const float drop = fs.jaw_drop * s * (jaw_open - closed);
  const float part = fs.funnel_open * s * B(blendshape::mouth_funnel);
  const float shift = fs.shift * s * (B(blendshape::mouth_left) - B(blendshape::mouth_right));
  const float y = k_mouth_y * s, z = k_mouth_z * s;
  for (int side = 0; side < 2; ++side) {
    const float sx = side == 0 ? 1.f : -1.f;
    const float smile = B(blendshape::mouth_smile_left, side);
    const float out = half_w + fs.smile_out * fs.smile_rise * s * smile +
                      fs.stretch_out * s * B(blendshape::mouth_stretch_left, side);
    const float up = fs.smile_rise * s * smile -
                     fs.frown_drop * s * B(blendshape::mouth_frown_left, side) -
                     fs.corner_follow * drop;
    f[side == 0 ? 291 : 61] = glm::vec3(shift + sx * out, y + up, z);
    f[side == 0 ? 308 : 78] = glm::vec3(shift + sx * 0.9f * out, y + up, z + 0.003f * s);
  }
  // The jaw's sideways move carries the chin and the lower lip; a lip rolled in brings its
  // outer edge (0 upper, 17 lower) toward the lip line.
  const float jaw = fs.jaw_side * s * (B(blendshape::jaw_left) - B(blendshape::jaw_right));
  const float roll_up = fs.roll_upper * s * B(blendshape::mouth_roll_upper);
  const float roll_down = fs.roll_lower * s * B(blendshape::mouth_roll_lower);
  const float forward = 0.006f * s * round;
  f[13] = glm::vec3(shift, y + 0.5f * part, 0.095f * s + forward);
  f[14] = glm::vec3(shift + jaw, y - 0.5f * part - drop, 0.095f * s + forward);
  f[0] = glm::vec3(shift, y + 0.008f * s + 0.5f * part - roll_up, 0.099f * s + forward);
  f[17] =
      glm::vec3(shift + jaw, y - 0.010f * s - 0.5f * part - drop + roll_down, 0.097f * s + forward);
  f[152].x += jaw;
  f[152].y -= fs.chin_ratio * fs.jaw_drop * s * jaw_open;
  // The lips' sides ride on the corners and middles just set; mouthUpperUp / mouthLowerDown
  // move them off. noseSneer lifts the nose's wings.
  set_lip_sides(f, s, fs.upper_up * s * B(blendshape::mouth_upper_up_left, 1),
                fs.upper_up * s * B(blendshape::mouth_upper_up_left, 0),
                fs.lower_down * s * B(blendshape::mouth_lower_down_left, 1),
                fs.lower_down * s * B(blendshape::mouth_lower_down_left, 0));
  f[327].y += fs.sneer * s * B(blendshape::nose_sneer_left, 0);
  f[98].y += fs.sneer * s * B(blendshape::nose_sneer_left, 1);

  const glm::quat& head = fk_.world[idx(bone::head)];
  const glm::vec3& origin = fk_.joints[idx(bone::head)];
  points_.head_joint = origin;
  for (glm::vec3& p : f) p = origin + head * p;
}

void landmark_synth::generate(const proxy_pose& pose, landmark_frame& out) {
  const proxy_pose* p = &pose;
  glm::vec3 camera = camera_;
  if (options_.mirror) {
    for (int b = 0; b < k_bone_count; ++b) {
      int m = idx(mirror_bone(static_cast<bone>(b)));
      mirrored_.rotations[m] = mirror_x(pose.rotations[b]);
      mirrored_.confidence[m] = pose.confidence[b];
    }
    mirrored_.t = pose.t;
    mirrored_.hips_position = mirror_x(pose.hips_position);
    mirrored_.expressions = pose.expressions;
    mirrored_.blendshapes = pose.blendshapes;
    mirror_blendshapes(mirrored_.blendshapes);
    swap_expressions(mirrored_, expression::blink_left, expression::blink_right);
    swap_expressions(mirrored_, expression::look_left, expression::look_right);
    swap_expressions(mirrored_, expression::brow_up_left, expression::brow_up_right);
    swap_expressions(mirrored_, expression::brow_down_left, expression::brow_down_right);
    p = &mirrored_;
    camera.x = -camera.x;
  }
  compute_proxy_fk(skeleton_, *p, fk_);
  update_bursts(pose.t);
  // Bursts are the person's limbs; mirrored output swaps the labels of the points they hit.
  auto burst_on_output_side = [&](bool arm, int output_side) {
    const int person_side = options_.mirror ? 1 - output_side : output_side;
    return in_burst_[(arm ? 0 : 2) + person_side];
  };

  out.clear();
  out.t = pose.t;
  const float width = static_cast<float>(options_.image_width);
  const float height = static_cast<float>(options_.image_height);
  auto project = [&](const glm::vec3& v, float z_ref) {
    return project_with(camera, focal_, width, height, v, z_ref);
  };
  auto depth = [&](const glm::vec3& v) { return camera.z - v.z; };

  const bool want_pose = options_.pose_image || options_.pose_world;
  const bool want_face = options_.face != synth_face::none;
  if (want_pose || want_face) build_face(*p);  // the pose's face points need the mouth

  if (want_pose) {
    std::array<glm::vec3, k_pose_landmark_count>& P = points_.pose;
    const auto& J = fk_.joints;
    const glm::quat& head = fk_.world[idx(bone::head)];
    const glm::vec3& hj = J[idx(bone::head)];
    const float s = skeleton_.scale;
    auto head_point = [&](const glm::vec3& local) { return hj + head * local; };
    // Face points: nose, eye corners (as the mesh) and centres, ears, mouth corners (live).
    const glm::vec3 eye_centre(
        0.5f * (face_template_[k_left_eye.inner].x + face_template_[k_left_eye.outer].x),
        face_template_[k_left_eye.inner].y, face_template_[k_left_eye.inner].z);
    const glm::vec3 ear = glm::vec3(0.075f, 0.10f, -0.005f) * s;
    P[0] = head_point(face_template_[1]);
    P[1] = head_point(face_template_[k_left_eye.inner]);
    P[2] = head_point(eye_centre);
    P[3] = head_point(face_template_[k_left_eye.outer]);
    P[4] = head_point(face_template_[k_right_eye.inner]);
    P[5] = head_point(mirror_x(eye_centre));
    P[6] = head_point(face_template_[k_right_eye.outer]);
    P[7] = head_point(ear);
    P[8] = head_point(mirror_x(ear));
    P[9] = points_.face[291];
    P[10] = points_.face[61];
    const bone body[22] = {bone::left_upper_arm,
                           bone::right_upper_arm,
                           bone::left_lower_arm,
                           bone::right_lower_arm,
                           bone::left_hand,
                           bone::right_hand,
                           bone::left_little_proximal,
                           bone::right_little_proximal,
                           bone::left_index_proximal,
                           bone::right_index_proximal,
                           bone::left_thumb_proximal,
                           bone::right_thumb_proximal,
                           bone::left_upper_leg,
                           bone::right_upper_leg,
                           bone::left_lower_leg,
                           bone::right_lower_leg,
                           bone::left_foot,
                           bone::right_foot,
                           bone::left_foot,
                           bone::right_foot,
                           bone::left_toes,
                           bone::right_toes};
    for (int i = 0; i < 18; ++i) P[11 + i] = J[idx(body[i])];
    P[29] = fk_.heels[0];
    P[30] = fk_.heels[1];
    P[31] = fk_.tips[idx(bone::left_toes)];
    P[32] = fk_.tips[idx(bone::right_toes)];
    add_noise(P.data(), k_pose_landmark_count, options_.body_noise_sigma);
    // Limb points of each output side: [arm: left, right][leg: left, right].
    static constexpr int k_arm_points[2][5] = {{13, 15, 17, 19, 21}, {14, 16, 18, 20, 22}};
    static constexpr int k_leg_points[2][4] = {{25, 27, 29, 31}, {26, 28, 30, 32}};
    const float lv_sigma = options_.low_visibility_noise_sigma;
    for (int side = 0; side < 2; ++side) {
      if (burst_on_output_side(true, side)) add_noise_at(P.data(), k_arm_points[side], 5, lv_sigma);
      if (burst_on_output_side(false, side))
        add_noise_at(P.data(), k_leg_points[side], 4, lv_sigma);
    }

    const glm::vec3 hip_mid = 0.5f * (P[23] + P[24]);
    if (options_.pose_image) {
      const float z_ref = depth(hip_mid);
      for (int i = 0; i < k_pose_landmark_count; ++i) put(out.pose[i], project(P[i], z_ref));
      out.set(frame_part::pose, true);
    }
    if (options_.pose_world) {
      const glm::vec3 origin = to_mediapipe(hip_mid);
      for (int i = 0; i < k_pose_landmark_count; ++i)
        put(out.pose_world[i], to_mediapipe(P[i]) - origin);
      out.set(frame_part::pose_world, true);
    }
    // One visibility per point and frame, the same in the image and world lists (as
    // MediaPipe reports them).
    auto dim = [&](const int* indices, int count) {
      for (int i = 0; i < count; ++i) {
        const float v = draw_visibility();
        out.pose[indices[i]].visibility = v;
        out.pose_world[indices[i]].visibility = v;
      }
    };
    for (int side = 0; side < 2; ++side) {
      if (burst_on_output_side(true, side)) dim(k_arm_points[side], 5);
      if (burst_on_output_side(false, side)) dim(k_leg_points[side], 4);
    }
  }

  if (options_.hands_image || options_.hands_world) {
    for (int side = 0; side < 2; ++side) {
      std::array<glm::vec3, k_hand_landmark_count>& H =
          side == 0 ? points_.left_hand : points_.right_hand;
      const int hand = idx(side == 0 ? bone::left_hand : bone::right_hand);
      const int first = idx(side == 0 ? bone::left_thumb_metacarpal : bone::right_thumb_metacarpal);
      H[0] = fk_.joints[hand];
      for (int finger = 0; finger < 5; ++finger) {
        const int b = first + 3 * finger;
        const int l = finger_base_landmark(finger);
        H[l] = fk_.joints[b];
        H[l + 1] = fk_.joints[b + 1];
        H[l + 2] = fk_.joints[b + 2];
        H[l + 3] = fk_.tips[b + 2];
      }
      add_noise(H.data(), k_hand_landmark_count, options_.hand_noise_sigma);
      static constexpr int k_all_hand_points[k_hand_landmark_count] = {
          0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20};
      const bool burst = burst_on_output_side(true, side);
      if (burst)
        add_noise_at(H.data(), k_all_hand_points, k_hand_landmark_count,
                     options_.low_visibility_noise_sigma);
      std::array<landmark, k_hand_landmark_count>& img = side == 0 ? out.left_hand : out.right_hand;
      std::array<landmark, k_hand_landmark_count>& wld =
          side == 0 ? out.left_hand_world : out.right_hand_world;
      if (options_.hands_image) {
        const float z_ref = depth(H[0]);
        for (int i = 0; i < k_hand_landmark_count; ++i) put(img[i], project(H[i], z_ref));
        out.set(side == 0 ? frame_part::left_hand : frame_part::right_hand, true);
      }
      if (options_.hands_world) {
        const glm::vec3 centre = to_mediapipe((H[0] + H[5] + H[9] + H[13] + H[17]) * 0.2f);
        for (int i = 0; i < k_hand_landmark_count; ++i) put(wld[i], to_mediapipe(H[i]) - centre);
        out.set(side == 0 ? frame_part::left_hand_world : frame_part::right_hand_world, true);
      }
      if (burst) {
        for (int i = 0; i < k_hand_landmark_count; ++i) {
          const float v = draw_visibility();
          img[i].visibility = v;
          wld[i].visibility = v;
        }
      }
    }
  }

  if (want_face) {
    const int count =
        options_.face == synth_face::mesh_478 ? k_face_mesh_iris_count : k_face_mesh_count;
    add_noise(points_.face.data(), count, options_.face_noise_sigma);
    const float z_ref = depth(points_.head_joint);
    for (int i = 0; i < count; ++i) put(out.face[i], project(points_.face[i], z_ref));
    out.face_count = count;
    out.set(frame_part::face, true);
  }
}

}  // namespace avatarmap
