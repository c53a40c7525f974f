// Landmarks from a BVH take's own joints. See include/avatarmap/jobs/mocap_synth.hpp and
// docs/world-benchmark.md.
#include "avatarmap/jobs/mocap_synth.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>

#include "avatarmap/export/bvh.hpp"
#include "avatarmap/io/landmark_file.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = 3.14159265358979f / 180.f;
constexpr float k_outside_visibility = 0.02f;

std::string normalised_name(const std::string& name) {
  std::string s = name.substr(name.rfind(':') == std::string::npos ? 0 : name.rfind(':') + 1);
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Index of the first joint whose name is one of `bases` with a side prefix/suffix (side 0 =
// left, 1 = right, -1 = none); -1 when none.
int find_joint(const std::vector<std::string>& names, std::initializer_list<const char*> bases,
               int side) {
  for (const char* b : bases) {
    std::vector<std::string> forms;
    if (side < 0) {
      forms = {b};
    } else {
      const std::string base = b;
      const char* word = side == 0 ? "left" : "right";
      const char* letter = side == 0 ? "l" : "r";
      forms = {word + base,         letter + base,       std::string(letter) + "_" + base,
               base + "_" + letter, base + "." + letter, base + word};
    }
    for (const std::string& f : forms)
      for (std::size_t j = 0; j < names.size(); ++j)
        if (names[j] == f) return static_cast<int>(j);
  }
  return -1;
}

bool is_descendant(const bvh_clip& c, int joint, int ancestor) {
  for (int j = c.joints[joint].parent; j >= 0; j = c.joints[j].parent)
    if (j == ancestor) return true;
  return false;
}

struct joint_map {
  int hip[2], knee[2], ankle[2], toe[2], shoulder[2], elbow[2], wrist[2];
  int neck = -1, head = -1;
};

// Forward kinematics of one frame (frame < 0: the rest pose) into world positions/rotations.
void run_fk(const bvh_clip& c, int frame, float units, std::vector<glm::vec3>& pos,
            std::vector<glm::quat>& rot) {
  for (std::size_t j = 0; j < c.joints.size(); ++j) {
    const bvh_joint& jt = c.joints[j];
    const glm::quat local =
        frame < 0 ? glm::quat(1.f, 0.f, 0.f, 0.f) : c.local_rotation(frame, static_cast<int>(j));
    glm::vec3 offset = jt.offset * units;
    if (jt.parent < 0) {
      if (frame >= 0) offset += c.position(frame, static_cast<int>(j)) * units;
      pos[j] = offset;
      rot[j] = local;
    } else {
      pos[j] = pos[jt.parent] + rot[jt.parent] * offset;
      rot[j] = rot[jt.parent] * local;
    }
  }
}

struct tip_sites {
  int toe_site[2] = {-1, -1};  // joints whose End Site is the toe tip
  int hand_site[2] = {-1, -1}, thumb_site[2] = {-1, -1};
  int head_site = -1;
};

glm::vec3 end_site_of(const bvh_clip& c, int j, float units, const std::vector<glm::vec3>& pos,
                      const std::vector<glm::quat>& rot) {
  return pos[j] + rot[j] * (c.joints[j].end_site * units);
}

// The farthest End Site (in the rest pose) below `root`, with or without "thumb" in its name.
int farthest_site(const bvh_clip& c, int root, int thumb, const std::vector<glm::vec3>& rest_pos,
                  const std::vector<glm::quat>& rest_rot, float units) {
  int best = -1;
  float best_d = -1.f;
  for (std::size_t j = 0; j < c.joints.size(); ++j) {
    const int ji = static_cast<int>(j);
    if (!c.joints[j].has_end_site || (ji != root && !is_descendant(c, ji, root))) continue;
    bool in_thumb = false;
    for (int k = ji; k >= 0 && k != root; k = c.joints[k].parent)
      in_thumb = in_thumb || normalised_name(c.joints[k].name).find("thumb") != std::string::npos;
    if (thumb >= 0 && in_thumb != (thumb == 1)) continue;
    const float d = glm::length(end_site_of(c, ji, units, rest_pos, rest_rot) - rest_pos[root]);
    if (d > best_d) best_d = d, best = ji;
  }
  return best;
}

void make_points(const bvh_clip& c, const joint_map& m, const tip_sites& s, float units,
                 float heel_dy[2], float heel_back[2], const std::vector<glm::vec3>& pos,
                 const std::vector<glm::quat>& rot, mocap_frame& out) {
  auto P = [&](mocap_point q) -> glm::vec3& { return out.p[idx(q)]; };
  for (int side = 0; side < 2; ++side) {
    const int o = side;  // left points are even offsets from the left enumerator
    P(static_cast<mocap_point>(idx(mocap_point::left_hip) + o)) = pos[m.hip[side]];
    P(static_cast<mocap_point>(idx(mocap_point::left_knee) + o)) = pos[m.knee[side]];
    const glm::vec3 ankle = pos[m.ankle[side]];
    const glm::quat ankle_rot = rot[m.ankle[side]];
    P(static_cast<mocap_point>(idx(mocap_point::left_ankle) + o)) = ankle;
    const glm::vec3 toe =
        m.toe[side] >= 0 ? pos[m.toe[side]] : ankle + ankle_rot * glm::vec3(0.f, -0.05f, 0.12f);
    P(static_cast<mocap_point>(idx(mocap_point::left_toe) + o)) = toe;
    glm::vec3 tip;
    if (s.toe_site[side] >= 0) {
      tip = end_site_of(c, s.toe_site[side], units, pos, rot);
    } else {
      const glm::vec3 d = toe - ankle;
      const float l = glm::length(d);
      tip = l > 1e-6f ? toe + d * (0.05f / l) : toe;
    }
    P(static_cast<mocap_point>(idx(mocap_point::left_toe_tip) + o)) = tip;
    P(static_cast<mocap_point>(idx(mocap_point::left_heel) + o)) =
        ankle + ankle_rot * glm::vec3(0.f, heel_dy[side], -heel_back[side]);
    P(static_cast<mocap_point>(idx(mocap_point::left_shoulder) + o)) = pos[m.shoulder[side]];
    const glm::vec3 elbow = pos[m.elbow[side]], wrist = pos[m.wrist[side]];
    P(static_cast<mocap_point>(idx(mocap_point::left_elbow) + o)) = elbow;
    P(static_cast<mocap_point>(idx(mocap_point::left_wrist) + o)) = wrist;
    glm::vec3 fore = wrist - elbow;
    const float fl = glm::length(fore);
    fore = fl > 1e-6f ? fore / fl : glm::vec3(0.f, -1.f, 0.f);
    P(static_cast<mocap_point>(idx(mocap_point::left_hand_tip) + o)) =
        s.hand_site[side] >= 0 ? end_site_of(c, s.hand_site[side], units, pos, rot)
                               : wrist + fore * 0.08f;
    P(static_cast<mocap_point>(idx(mocap_point::left_thumb_tip) + o)) =
        s.thumb_site[side] >= 0 ? end_site_of(c, s.thumb_site[side], units, pos, rot)
                                : wrist + fore * 0.05f;
  }
  P(mocap_point::hip_mid) = 0.5f * (P(mocap_point::left_hip) + P(mocap_point::right_hip));
  const int head = m.head >= 0 ? m.head : m.neck;
  const int neck = m.neck >= 0 ? m.neck : m.head;
  P(mocap_point::neck) = pos[neck];
  P(mocap_point::head) = pos[head];
  out.head_rotation = rot[head];
  P(mocap_point::head_top) = s.head_site >= 0 ? end_site_of(c, s.head_site, units, pos, rot)
                                              : pos[head] + rot[head] * glm::vec3(0.f, 0.2f, 0.f);
}

float uniform(std::mt19937& rng, float lo, float hi) {
  return lo + (hi - lo) * std::uniform_real_distribution<float>(0.f, 1.f)(rng);
}

}  // namespace

status mocap_take::load(const std::string& path, float units) {
  path_ = path;
  frames_.clear();
  if (!(units > 0.f) || !std::isfinite(units))
    return status::invalid_argument("units must be a positive number (metres per BVH unit)");
  bvh_clip c;
  if (status st = read_bvh(path, c); !st) return st;
  if (c.frame_count < 1 || c.joints.empty())
    return status::parse_error(path + ": the BVH has no frames of motion");
  if (!(c.frame_time > 0.0) || !std::isfinite(c.frame_time))
    return status::parse_error(path + ": Frame Time must be positive");
  for (float v : c.values)
    if (!std::isfinite(v)) return status::parse_error(path + ": a motion value is not finite");
  std::vector<std::string> names;
  for (const bvh_joint& j : c.joints) names.push_back(normalised_name(j.name));
  joint_map m{};
  for (int side = 0; side < 2; ++side) {
    m.hip[side] = find_joint(names, {"upleg", "upperleg", "hip", "thigh"}, side);
    m.knee[side] = find_joint(names, {"leg", "lowerleg", "knee", "shin"}, side);
    m.ankle[side] = find_joint(names, {"foot", "ankle"}, side);
    m.toe[side] = find_joint(names, {"toebase", "toes", "toe"}, side);
    m.shoulder[side] = find_joint(names, {"arm", "upperarm"}, side);
    if (m.shoulder[side] < 0) m.shoulder[side] = find_joint(names, {"shoulder"}, side);
    m.elbow[side] = find_joint(names, {"forearm", "lowerarm", "elbow"}, side);
    m.wrist[side] = find_joint(names, {"hand", "wrist"}, side);
  }
  m.neck = find_joint(names, {"neck", "neck1", "upperneck"}, -1);
  m.head = find_joint(names, {"head"}, -1);
  const char* side_name[2] = {"left", "right"};
  for (int side = 0; side < 2; ++side) {
    const struct {
      int j;
      const char* what;
    } need[] = {{m.hip[side], "hip (upper leg)"}, {m.knee[side], "knee (lower leg)"},
                {m.ankle[side], "ankle (foot)"},  {m.shoulder[side], "shoulder (upper arm)"},
                {m.elbow[side], "elbow"},         {m.wrist[side], "wrist (hand)"}};
    for (const auto& n : need)
      if (n.j < 0)
        return status::parse_error(path + ": no " + side_name[side] + " " + n.what +
                                   " joint (the world benchmark needs both legs and arms; "
                                   "names: docs/world-benchmark.md)");
  }
  if (m.neck < 0 && m.head < 0) return status::parse_error(path + ": no Neck or Head joint");

  std::vector<glm::vec3> pos(c.joints.size());
  std::vector<glm::quat> rot(c.joints.size());
  run_fk(c, -1, units, pos, rot);
  tip_sites s;
  for (int side = 0; side < 2; ++side) {
    if (m.toe[side] >= 0) s.toe_site[side] = farthest_site(c, m.toe[side], -1, pos, rot, units);
    s.hand_site[side] = farthest_site(c, m.wrist[side], 0, pos, rot, units);
    s.thumb_site[side] = farthest_site(c, m.wrist[side], 1, pos, rot, units);
  }
  const int head = m.head >= 0 ? m.head : m.neck;
  s.head_site = farthest_site(c, head, -1, pos, rot, units);
  float heel_dy[2] = {0.f, 0.f}, heel_back[2] = {0.05f, 0.05f};
  make_points(c, m, s, units, heel_dy, heel_back, pos, rot, rest_);
  for (int side = 0; side < 2; ++side) {
    const glm::vec3 ankle = rest_.p[idx(mocap_point::left_ankle) + side];
    const glm::vec3 tip = rest_.p[idx(mocap_point::left_toe_tip) + side];
    heel_dy[side] = tip.y - ankle.y;
    heel_back[side] = 0.25f * glm::length(tip - ankle);
  }
  make_points(c, m, s, units, heel_dy, heel_back, pos, rot, rest_);

  frames_.resize(static_cast<std::size_t>(c.frame_count));
  std::vector<float> lows(frames_.size());
  for (int f = 0; f < c.frame_count; ++f) {
    run_fk(c, f, units, pos, rot);
    mocap_frame& out = frames_[static_cast<std::size_t>(f)];
    make_points(c, m, s, units, heel_dy, heel_back, pos, rot, out);
    float low = out.p[idx(mocap_point::left_toe_tip)].y;
    for (mocap_point q : {mocap_point::right_toe_tip, mocap_point::left_toe, mocap_point::right_toe,
                          mocap_point::left_heel, mocap_point::right_heel})
      low = std::min(low, out[q].y);
    lows[static_cast<std::size_t>(f)] = low;
  }
  const std::size_t k = lows.size() * 2 / 100;
  std::nth_element(lows.begin(), lows.begin() + static_cast<std::ptrdiff_t>(k), lows.end());
  floor_y_ = lows[k];
  frame_time_ = c.frame_time;
  return {};
}

void mocap_take::sample(double t, mocap_frame& out) const {
  if (frames_.empty()) return;
  double x = std::isfinite(t) ? t / frame_time_ : 0.0;
  x = std::clamp(x, 0.0, static_cast<double>(frames_.size() - 1));
  const std::size_t i = std::min(static_cast<std::size_t>(x), frames_.size() - 1);
  const std::size_t j = std::min(i + 1, frames_.size() - 1);
  const float a = static_cast<float>(x - static_cast<double>(i));
  for (int q = 0; q < k_mocap_point_count; ++q)
    out.p[q] = glm::mix(frames_[i].p[q], frames_[j].p[q], a);
  out.head_rotation = glm::slerp(frames_[i].head_rotation, frames_[j].head_rotation, a);
}

float mocap_take::rest_height() const {
  float low = rest_[mocap_point::left_toe_tip].y;
  for (mocap_point q : {mocap_point::right_toe_tip, mocap_point::left_heel, mocap_point::right_heel,
                        mocap_point::left_toe, mocap_point::right_toe})
    low = std::min(low, rest_[q].y);
  return rest_[mocap_point::head_top].y - low;
}

float mocap_camera::focal_pixels() const {
  return 0.5f * static_cast<float>(image_width) / std::tan(0.5f * horizontal_fov_degrees * k_deg);
}

glm::vec3 mocap_camera::to_camera(const glm::vec3& world) const {
  return glm::inverse(world_from_camera) * (world - position);
}

glm::vec2 mocap_camera::project(const glm::vec3& c) const {
  if (!(c.z > 1e-4f)) return glm::vec2(-10.f, -10.f);
  const float f = focal_pixels();
  return glm::vec2((f * c.x / c.z + 0.5f * image_width) / image_width,
                   (f * c.y / c.z + 0.5f * image_height) / image_height);
}

status mocap_camera_setup::validate() const {
  auto bad = [](float v, float lo, float hi) { return !std::isnan(v) && !(v >= lo && v <= hi); };
  if (bad(height, -10.f, 20.f))
    return status::invalid_argument("camera height must be in [-10, 20] m");
  if (bad(distance, 0.3f, 100.f))
    return status::invalid_argument("camera distance must be in [0.3, 100] m");
  if (bad(lateral, -100.f, 100.f))
    return status::invalid_argument("camera lateral offset must be in [-100, 100] m");
  if (bad(pitch_degrees, -89.f, 89.f))
    return status::invalid_argument("camera pitch must be in [-89, 89] degrees");
  if (bad(roll_degrees, -180.f, 180.f))
    return status::invalid_argument("camera roll must be in [-180, 180] degrees");
  if (bad(fov_degrees, 5.f, 170.f))
    return status::invalid_argument("field of view must be in [5, 170] degrees");
  if (!(image_width >= 16 && image_width <= 16384 && image_height >= 16 && image_height <= 16384))
    return status::invalid_argument("image size must be 16..16384 pixels each way");
  return {};
}

mocap_camera place_mocap_camera(const mocap_take& take, const mocap_camera_setup& setup) {
  std::mt19937 rng(setup.seed * 2654435761u + 1u);
  // Every draw is made, given or not, so that fixing one option leaves the others' draws.
  const float d_height = uniform(rng, 0.5f, 2.0f), d_distance = uniform(rng, 2.5f, 5.f),
              d_lateral = uniform(rng, -1.f, 1.f), d_fov = uniform(rng, 40.f, 90.f),
              d_roll = uniform(rng, -8.f, 8.f), d_pitch = uniform(rng, -0.2f, 0.2f);
  auto pick = [](float given, float drawn) { return std::isnan(given) ? drawn : given; };
  mocap_camera cam;
  cam.image_width = setup.image_width;
  cam.image_height = setup.image_height;
  cam.height = pick(setup.height, d_height);
  cam.distance = pick(setup.distance, d_distance);
  cam.lateral = pick(setup.lateral, d_lateral);
  cam.horizontal_fov_degrees = pick(setup.fov_degrees, d_fov);
  cam.roll_degrees = pick(setup.roll_degrees, d_roll);

  const glm::vec3 up(0.f, 1.f, 0.f);
  glm::vec3 mean(0.f), facing(0.f);
  const int n = take.frame_count();
  for (int i = 0; i < n; ++i) {
    const mocap_frame& f = take.frame(i);
    mean += f[mocap_point::hip_mid];
    glm::vec3 left = f[mocap_point::left_hip] - f[mocap_point::right_hip];
    left.y = 0.f;
    if (glm::length(left) > 1e-6f) facing += glm::cross(glm::normalize(left), up);
  }
  mean /= static_cast<float>(std::max(n, 1));
  facing.y = 0.f;
  facing = glm::length(facing) > 1e-6f ? glm::normalize(facing) : glm::vec3(0.f, 0.f, 1.f);
  const glm::vec3 left = glm::cross(up, facing);
  cam.position = glm::vec3(mean.x, take.floor_y() + cam.height, mean.z) + facing * cam.distance +
                 left * cam.lateral;
  glm::vec3 d = mean - cam.position;
  const float horizontal = std::sqrt(d.x * d.x + d.z * d.z);
  d.y = 0.f;
  d = horizontal > 1e-6f ? d / horizontal : -facing;
  const float vfov = 2.f *
                     std::atan(std::tan(0.5f * cam.horizontal_fov_degrees * k_deg) *
                               cam.image_height / cam.image_width) /
                     k_deg;
  const float look_pitch = std::atan2(mean.y - cam.position.y, horizontal) / k_deg;
  cam.pitch_degrees = std::isnan(setup.pitch_degrees)
                          ? std::clamp(look_pitch + d_pitch * vfov, -30.f, 20.f)
                          : setup.pitch_degrees;
  const float p = cam.pitch_degrees * k_deg, r = cam.roll_degrees * k_deg;
  const glm::vec3 z = std::cos(p) * d + std::sin(p) * up;
  glm::vec3 x = glm::normalize(glm::cross(z, up));
  glm::vec3 y = glm::cross(z, x);
  const glm::vec3 xr = std::cos(r) * x + std::sin(r) * y, yr = -std::sin(r) * x + std::cos(r) * y;
  cam.world_from_camera = glm::normalize(glm::quat_cast(glm::mat3(xr, yr, z)));
  return cam;
}

mocap_synth_options mocap_synth_options::preset(mocap_scenario s, unsigned seed) {
  mocap_synth_options o;
  o.scenario = s;
  o.seed = seed;
  if (s == mocap_scenario::clean) {
    o.lean_degrees = 0.f;
    o.world_noise_m = 0.f;
    o.image_noise = 0.f;
    o.visibility_model = false;
  }
  return o;
}

status mocap_synth_options::validate() const {
  if (!std::isnan(lean_degrees) && !(lean_degrees >= -60.f && lean_degrees <= 60.f))
    return status::invalid_argument("world lean must be in [-60, 60] degrees");
  if (!(world_noise_m >= 0.f && world_noise_m <= 1.f))
    return status::invalid_argument("world noise must be in [0, 1000] mm");
  if (!(image_noise >= 0.f && image_noise <= 0.2f))
    return status::invalid_argument("image noise must be in [0, 20] % of the image height");
  return {};
}

mocap_landmark_synth::mocap_landmark_synth(const mocap_take& take, const mocap_camera& camera,
                                           const mocap_synth_options& options)
    : take_(take), camera_(camera), options_(options), rng_(options.seed * 747796405u + 7u) {
  const float drawn = uniform(rng_, 10.f, 25.f);
  lean_degrees_ = std::isnan(options.lean_degrees) ? drawn : options.lean_degrees;
}

void mocap_landmark_synth::clean_world(const mocap_frame& f, const mocap_camera& cam,
                                       std::array<glm::vec3, 33>& out) {
  using mp = mocap_point;
  // Face: a head-local template (metres for a 0.30 m neck-to-vertex head, head rest axes: Y up,
  // facing +Z, left +X) hung from the head top, scaled to the take's head.
  static const glm::vec3 k_face[11] = {
      {0.f, -0.16f, 0.10f},      {0.015f, -0.12f, 0.085f},  {0.033f, -0.12f, 0.08f},
      {0.048f, -0.12f, 0.065f},  {-0.015f, -0.12f, 0.085f}, {-0.033f, -0.12f, 0.08f},
      {-0.048f, -0.12f, 0.065f}, {0.075f, -0.13f, 0.f},     {-0.075f, -0.13f, 0.f},
      {0.025f, -0.20f, 0.085f},  {-0.025f, -0.20f, 0.085f}};
  const float scale = std::clamp(glm::length(f[mp::head_top] - f[mp::neck]) / 0.30f, 0.5f, 1.5f);
  std::array<glm::vec3, 33> w;
  for (int i = 0; i < 11; ++i) w[i] = f[mp::head_top] + f.head_rotation * (k_face[i] * scale);
  for (int side = 0; side < 2; ++side) {
    auto P = [&](mp q) { return f.p[idx(q) + side]; };
    w[11 + side] = P(mp::left_shoulder);
    w[13 + side] = P(mp::left_elbow);
    const glm::vec3 wrist = P(mp::left_wrist);
    w[15 + side] = wrist;
    const glm::vec3 tip = P(mp::left_hand_tip), thumb = P(mp::left_thumb_tip);
    glm::vec3 along = tip - wrist;
    const float l = glm::length(along);
    along = l > 1e-6f ? along / l : glm::vec3(0.f, -1.f, 0.f);
    glm::vec3 t = thumb - wrist;
    t -= glm::dot(t, along) * along;
    glm::vec3 s = glm::length(t) > 1e-6f ? glm::normalize(t) : glm::vec3(0.f, 0.f, 1.f);
    const glm::vec3 knuckles = wrist + (tip - wrist) * 0.85f;
    w[17 + side] = knuckles - s * 0.025f;  // pinky
    w[19 + side] = knuckles + s * 0.02f;   // index
    w[21 + side] = thumb;
    w[23 + side] = P(mp::left_hip);
    w[25 + side] = P(mp::left_knee);
    w[27 + side] = P(mp::left_ankle);
    w[29 + side] = P(mp::left_heel);
    w[31 + side] = P(mp::left_toe_tip);
  }
  const glm::vec3 hips = cam.to_camera(f[mp::hip_mid]);
  for (int i = 0; i < 33; ++i) out[i] = cam.to_camera(w[i]) - hips;
}

void mocap_landmark_synth::generate(double t, landmark_frame& out) {
  mocap_frame f;
  take_.sample(t, f);
  std::array<glm::vec3, 33> world;
  clean_world(f, camera_, world);
  const glm::vec3 hips = camera_.to_camera(f[mocap_point::hip_mid]);
  out.clear();
  out.t = t;
  out.set(frame_part::pose, true);
  out.set(frame_part::pose_world, true);
  // Visibility: sided points fade as their side turns away, face points as the face does.
  glm::vec3 left = (world[23] - world[24]) + (world[11] - world[12]);
  left = glm::length(left) > 1e-6f ? glm::normalize(left) : glm::vec3(1.f, 0.f, 0.f);
  const glm::vec3 up_cam = glm::length(world[11] + world[12]) > 1e-6f
                               ? glm::normalize(world[11] + world[12])
                               : glm::vec3(0.f, -1.f, 0.f);
  // In camera axes (y down) the body's forward is up x left (left x up in a Y-up world).
  const glm::vec3 forward = glm::cross(-up_cam, left);
  const float c = std::cos(lean_degrees_ * k_deg), s = std::sin(lean_degrees_ * k_deg);
  const float f_px = camera_.focal_pixels();
  const float w = static_cast<float>(camera_.image_width);
  const float h = static_cast<float>(camera_.image_height);
  for (int i = 0; i < 33; ++i) {
    const glm::vec3 cam_point = world[i] + hips;
    glm::vec2 uv = camera_.project(cam_point);
    const bool inside = uv.x >= 0.f && uv.x <= 1.f && uv.y >= 0.f && uv.y <= 1.f;
    if (options_.image_noise > 0.f) {
      uv.x += normal_(rng_) * options_.image_noise * h / w;
      uv.y += normal_(rng_) * options_.image_noise;
    }
    landmark& im = out.pose[i];
    im.x = uv.x;
    im.y = uv.y;
    im.z = hips.z > 1e-4f ? (cam_point.z - hips.z) * f_px / (w * hips.z) : 0.f;
    // The lean: top toward the camera (rotation about the camera's x axis through the hips).
    const glm::vec3 p = world[i];
    glm::vec3 q(p.x, p.y * c - p.z * s, p.y * s + p.z * c);
    if (options_.world_noise_m > 0.f)
      q += glm::vec3(normal_(rng_), normal_(rng_), normal_(rng_)) * options_.world_noise_m;
    landmark& wl = out.pose_world[i];
    wl.x = q.x;
    wl.y = q.y;
    wl.z = q.z;
    float vis = 1.f, pres = 1.f;
    if (options_.visibility_model) {
      vis = pres = 0.98f;
      if (i >= 1) {
        const bool is_left = (i <= 10) ? (i <= 3 || i == 7 || i == 9) : (i % 2 == 1);
        const float away = std::clamp(is_left ? left.z : -left.z, 0.f, 1.f);
        vis -= 0.7f * away;
      }
      if (i <= 10) vis = std::min(vis, 0.98f - 0.8f * std::clamp(forward.z + 0.2f, 0.f, 1.f));
      vis = std::max(vis, 0.05f);
    }
    if (!inside) vis = pres = k_outside_visibility;
    im.visibility = wl.visibility = vis;
    im.presence = wl.presence = pres;
  }
}

status mocap_synth_job::run(mocap_synth_summary& out) const {
  out = {};
  if (!take || take->frame_count() < 1) return status::invalid_argument("no take to synthesise");
  if (!(fps > 0.0 && fps <= 1000.0)) return status::invalid_argument("fps must be in (0, 1000]");
  if (status st = options.validate(); !st) return st;
  mocap_landmark_synth synth(*take, camera, options);
  out.lean_degrees = synth.lean_degrees();
  landmark_writer writer;
  landmark_file_header hdr;
  hdr.present = true;
  hdr.image_width = camera.image_width;
  hdr.image_height = camera.image_height;
  hdr.fps = fps;
  if (status st = writer.open(output, hdr); !st) return st;
  const long n = static_cast<long>(std::floor(take->duration() * fps + 1e-6)) + 1;
  landmark_frame frame;
  long inside = 0;
  for (long k = 0; k < n; ++k) {
    synth.generate(static_cast<double>(k) / fps, frame);
    for (const landmark& l : frame.pose) inside += l.presence > k_outside_visibility ? 1 : 0;
    if (status st = writer.write(frame); !st) return st;
  }
  if (status st = writer.commit(); !st) return st;
  out.frames = n;
  out.inside_fraction = static_cast<double>(inside) / (33.0 * static_cast<double>(n));
  return {};
}

std::string mocap_camera_json(const mocap_camera& c, float lean) {
  char buf[768];
  const glm::quat q = c.world_from_camera;
  std::snprintf(buf, sizeof buf,
                "{\"position\":[%.5f,%.5f,%.5f],\"world_from_camera\":{\"x\":%.6f,\"y\":%.6f,"
                "\"z\":%.6f,\"w\":%.6f},\"horizontal_fov_degrees\":%.4f,\"image_width\":%d,"
                "\"image_height\":%d,\"height\":%.4f,\"distance\":%.4f,\"lateral\":%.4f,"
                "\"pitch_degrees\":%.4f,\"roll_degrees\":%.4f,\"world_lean_degrees\":%.4f}",
                c.position.x, c.position.y, c.position.z, q.x, q.y, q.z, q.w,
                c.horizontal_fov_degrees, c.image_width, c.image_height, c.height, c.distance,
                c.lateral, c.pitch_degrees, c.roll_degrees, lean);
  return buf;
}

}  // namespace avatarmap
