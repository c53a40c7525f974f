// The world benchmark's scorer. See include/avatarmap/jobs/world_score.hpp and
// docs/world-benchmark.md.
#include "avatarmap/jobs/world_score.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/retarget_clip.hpp"

namespace avatarmap {
namespace {

using mp = mocap_point;

// The joints of MPJPE / PA-MPJPE (hip_mid first).
constexpr mp k_scored[] = {mp::hip_mid,     mp::left_hip,      mp::right_hip,      mp::left_knee,
                           mp::right_knee,  mp::left_ankle,    mp::right_ankle,    mp::left_toe,
                           mp::right_toe,   mp::left_shoulder, mp::right_shoulder, mp::left_elbow,
                           mp::right_elbow, mp::left_wrist,    mp::right_wrist,    mp::neck,
                           mp::head};
constexpr int k_scored_count = sizeof(k_scored) / sizeof(k_scored[0]);
constexpr mp k_skate[] = {mp::left_ankle, mp::right_ankle, mp::left_toe, mp::right_toe};
constexpr mp k_floor_points[] = {mp::left_toe_tip, mp::right_toe_tip, mp::left_heel,
                                 mp::right_heel};

glm::vec3 rotate_y(const glm::vec3& v, float c, float s) {
  return glm::vec3(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Largest-eigenvalue eigenvector of a symmetric 4x4 matrix (cyclic Jacobi).
void top_eigenvector(double a[4][4], double out[4]) {
  double v[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  for (int sweep = 0; sweep < 50; ++sweep) {
    double off = 0;
    for (int p = 0; p < 4; ++p)
      for (int q = p + 1; q < 4; ++q) off += a[p][q] * a[p][q];
    if (off < 1e-24) break;
    for (int p = 0; p < 4; ++p)
      for (int q = p + 1; q < 4; ++q) {
        if (std::fabs(a[p][q]) < 1e-300) continue;
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t = (theta >= 0 ? 1 : -1) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 4; ++k) {
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 4; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 4; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  int best = 0;
  for (int i = 1; i < 4; ++i)
    if (a[i][i] > a[best][best]) best = i;
  for (int k = 0; k < 4; ++k) out[k] = v[k][best];
}

// Mean distance after the similarity transform (Horn's quaternion method) that best maps `a`
// onto `b`.
double procrustes_error(const glm::dvec3* a, const glm::dvec3* b, int n) {
  glm::dvec3 ca(0.0), cb(0.0);
  for (int i = 0; i < n; ++i) ca += a[i], cb += b[i];
  ca /= n;
  cb /= n;
  double s[3][3] = {};
  double aa = 0;
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 x = a[i] - ca, y = b[i] - cb;
    aa += glm::dot(x, x);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) s[r][c] += x[r] * y[c];
  }
  double nm[4][4] = {
      {s[0][0] + s[1][1] + s[2][2], s[1][2] - s[2][1], s[2][0] - s[0][2], s[0][1] - s[1][0]},
      {s[1][2] - s[2][1], s[0][0] - s[1][1] - s[2][2], s[0][1] + s[1][0], s[2][0] + s[0][2]},
      {s[2][0] - s[0][2], s[0][1] + s[1][0], -s[0][0] + s[1][1] - s[2][2], s[1][2] + s[2][1]},
      {s[0][1] - s[1][0], s[2][0] + s[0][2], s[1][2] + s[2][1], -s[0][0] - s[1][1] + s[2][2]}};
  double q[4];
  top_eigenvector(nm, q);
  const glm::dquat r = glm::normalize(glm::dquat(q[0], q[1], q[2], q[3]));
  double ab = 0;
  for (int i = 0; i < n; ++i) ab += glm::dot(b[i] - cb, r * (a[i] - ca));
  const double scale = aa > 1e-12 ? ab / aa : 1.0;
  double err = 0;
  for (int i = 0; i < n; ++i) err += glm::length(scale * (r * (a[i] - ca)) + cb - b[i]);
  return err / n;
}

// (cos, sin) of the yaw about Y that best turns the `a` vectors onto the `b` vectors.
void best_yaw(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b, float& c,
              float& s) {
  double sc = 0, ss = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sc += b[i].x * a[i].x + b[i].z * a[i].z;
    ss += b[i].x * a[i].z - b[i].z * a[i].x;
  }
  const double th = (sc == 0 && ss == 0) ? 0.0 : std::atan2(ss, sc);
  c = static_cast<float>(std::cos(th));
  s = static_cast<float>(std::sin(th));
}

double lean_deg(const mocap_frame& f) {
  const glm::vec3 d = f[mp::neck] - f[mp::hip_mid];
  const float l = glm::length(d);
  if (!(l > 1e-6f)) return 0;
  return std::acos(std::clamp(d.y / l, -1.f, 1.f)) * 180.0 / 3.14159265358979;
}

}  // namespace

proxy_skeleton proxy_skeleton_like(const mocap_take& truth) {
  const mocap_frame& r = truth.rest();
  proxy_skeleton s = make_proxy_skeleton(std::clamp(truth.rest_height(), 0.5f, 3.f));
  auto len = [&](mp a, mp b) { return glm::length(r[b] - r[a]); };
  auto set_chain = [&](bone b, bone child, float l) {
    if (!(l > 1e-4f)) return;
    s.lengths[idx(b)] = l;
    s.offsets[idx(child)] = l * bone_rest_direction(b);
  };
  const float half = 0.5f * len(mp::right_hip, mp::left_hip);
  s.offsets[idx(bone::left_upper_leg)] = glm::vec3(half, 0.f, 0.f);
  s.offsets[idx(bone::right_upper_leg)] = glm::vec3(-half, 0.f, 0.f);
  const float spine_truth = len(mp::hip_mid, mp::neck);
  const float spine_proxy = s.lengths[idx(bone::hips)] + s.lengths[idx(bone::spine)] +
                            s.lengths[idx(bone::chest)] + s.lengths[idx(bone::upper_chest)];
  if (spine_truth > 1e-3f && spine_proxy > 1e-6f) {
    const float k = spine_truth / spine_proxy;
    const bone chain[4][2] = {{bone::hips, bone::spine},
                              {bone::spine, bone::chest},
                              {bone::chest, bone::upper_chest},
                              {bone::upper_chest, bone::neck}};
    for (const auto& c : chain) set_chain(c[0], c[1], s.lengths[idx(c[0])] * k);
  }
  set_chain(bone::neck, bone::head, len(mp::neck, mp::head));
  if (len(mp::head, mp::head_top) > 1e-3f) s.lengths[idx(bone::head)] = len(mp::head, mp::head_top);
  for (int side = 0; side < 2; ++side) {
    const float sign = side == 0 ? 1.f : -1.f;
    auto P = [&](mp q) { return r.p[idx(q) + side]; };
    const bone shoulder = side == 0 ? bone::left_shoulder : bone::right_shoulder;
    const bone upper_arm = side == 0 ? bone::left_upper_arm : bone::right_upper_arm;
    const bone lower_arm = side == 0 ? bone::left_lower_arm : bone::right_lower_arm;
    const bone hand = side == 0 ? bone::left_hand : bone::right_hand;
    const glm::vec3 d = P(mp::left_shoulder) - r[mp::neck];
    const glm::vec3 socket(sign * std::fabs(d.x), d.y, 0.f);  // from the neck joint
    s.offsets[idx(shoulder)] = s.offsets[idx(bone::neck)] + socket - s.offsets[idx(upper_arm)];
    set_chain(upper_arm, lower_arm, glm::length(P(mp::left_elbow) - P(mp::left_shoulder)));
    set_chain(lower_arm, hand, glm::length(P(mp::left_wrist) - P(mp::left_elbow)));
    const float hl = glm::length(P(mp::left_hand_tip) - P(mp::left_wrist));
    if (hl > 1e-3f) s.lengths[idx(hand)] = hl;
    const bone ul = side == 0 ? bone::left_upper_leg : bone::right_upper_leg;
    const bone ll = side == 0 ? bone::left_lower_leg : bone::right_lower_leg;
    const bone foot = side == 0 ? bone::left_foot : bone::right_foot;
    const bone toes = side == 0 ? bone::left_toes : bone::right_toes;
    set_chain(ul, ll, glm::length(P(mp::left_knee) - P(mp::left_hip)));
    set_chain(ll, foot, glm::length(P(mp::left_ankle) - P(mp::left_knee)));
    set_chain(foot, toes, glm::length(P(mp::left_toe) - P(mp::left_ankle)));
    const float tl = glm::length(P(mp::left_toe_tip) - P(mp::left_toe));
    if (tl > 1e-3f) s.lengths[idx(toes)] = tl;
  }
  // Heel: on the sole at the rest toe tip's level, a quarter of the foot behind the ankle.
  const float foot_total = s.lengths[idx(bone::left_foot)] + s.lengths[idx(bone::left_toes)];
  const float tip_dy = foot_total * bone_rest_direction(bone::left_foot).y;
  s.heel_offset = glm::vec3(0.f, tip_dy, -0.25f * foot_total);
  return s;
}

status read_world_take_poses(const std::string& path, const proxy_skeleton& skeleton,
                             world_take& out) {
  out = {};
  pose_reader reader;
  if (status st = reader.open(path); !st) return st;
  std::vector<proxy_pose> poses;
  for (proxy_pose pose;;) {
    const read_result r = reader.next(pose);
    if (r == read_result::end) break;
    if (r == read_result::error)
      return status::failure(reader.error_code(),
                             path + ":" + std::to_string(reader.line()) + ": " + reader.error());
    if (std::isfinite(pose.t) && finite(pose.hips_position)) poses.push_back(pose);
  }
  if (poses.empty()) return status::parse_error(path + ": no poses");
  // The hips translation scaled as `convert` scales it onto a rig: the skeleton's standing hips
  // height over the performer's (the clip's 90th percentile).
  float performer = 0.f;
  if (status st = standing_hips_height(poses, path, performer); !st) return st;
  const float k = standing_hips_height(skeleton) / performer;
  proxy_fk fk;
  for (proxy_pose& pose : poses) {
    pose.hips_position *= k;
    compute_proxy_fk(skeleton, pose, fk);
    mocap_frame f;
    auto J = [&](bone b) { return fk.joints[idx(b)]; };
    f.p[idx(mp::hip_mid)] = J(bone::hips);
    for (int side = 0; side < 2; ++side) {
      auto B = [&](bone left) { return side == 0 ? left : mirror_bone(left); };
      f.p[idx(mp::left_hip) + side] = J(B(bone::left_upper_leg));
      f.p[idx(mp::left_knee) + side] = J(B(bone::left_lower_leg));
      f.p[idx(mp::left_ankle) + side] = J(B(bone::left_foot));
      f.p[idx(mp::left_toe) + side] = J(B(bone::left_toes));
      f.p[idx(mp::left_toe_tip) + side] = fk.tips[idx(B(bone::left_toes))];
      f.p[idx(mp::left_heel) + side] = fk.heels[side];
      f.p[idx(mp::left_shoulder) + side] = J(B(bone::left_upper_arm));
      f.p[idx(mp::left_elbow) + side] = J(B(bone::left_lower_arm));
      f.p[idx(mp::left_wrist) + side] = J(B(bone::left_hand));
      f.p[idx(mp::left_hand_tip) + side] = fk.tips[idx(B(bone::left_hand))];
      f.p[idx(mp::left_thumb_tip) + side] = fk.tips[idx(B(bone::left_thumb_distal))];
    }
    f.p[idx(mp::neck)] = J(bone::neck);
    f.p[idx(mp::head)] = J(bone::head);
    f.p[idx(mp::head_top)] = fk.tips[idx(bone::head)];
    f.head_rotation = fk.world[idx(bone::head)];
    out.t.push_back(pose.t);
    out.frames.push_back(f);
  }
  return {};
}

status read_world_take_bvh(const std::string& path, float units, world_take& out) {
  out = {};
  mocap_take take;
  if (status st = take.load(path, units); !st) return st;
  for (int i = 0; i < take.frame_count(); ++i) {
    out.t.push_back(i * take.frame_time());
    out.frames.push_back(take.frame(i));
  }
  return {};
}

status score_world(const mocap_take& truth, const world_take& solved, const world_score_options& o,
                   world_scores& out) {
  out = {};
  out.feet_only = o.feet_only;
  // Matched frames: solved frames inside the truth's span, with finite points.
  std::vector<double> t;
  std::vector<mocap_frame> s, g;
  const double span = truth.duration() + 1e-6;
  for (std::size_t i = 0; i < solved.frames.size() && i < solved.t.size(); ++i) {
    const double ti = solved.t[i];
    if (!(ti >= -1e-6 && ti <= span)) continue;
    bool ok = true;
    for (const glm::vec3& p : solved.frames[i].p) ok = ok && finite(p);
    if (!ok) continue;
    mocap_frame truth_frame;
    truth.sample(ti, truth_frame);
    t.push_back(ti);
    s.push_back(solved.frames[i]);
    g.push_back(truth_frame);
  }
  const std::size_t n = t.size();
  if (n < 3)
    return status::invalid_argument(
        "fewer than 3 solved frames fall in the truth's time span (0.." +
        std::to_string(truth.duration()) + " s): is it the right truth file and --fps?");
  out.frames = static_cast<long>(n);
  const float floor_truth = truth.floor_y();

  // Foot skate: the truth's planted (point, frame) pairs, central differences.
  {
    float lowest[4];
    for (int k = 0; k < 4; ++k) {
      std::vector<float> ys(n);
      for (std::size_t i = 0; i < n; ++i) ys[i] = g[i][k_skate[k]].y;
      const std::size_t q = n * 2 / 100;
      std::nth_element(ys.begin(), ys.begin() + static_cast<std::ptrdiff_t>(q), ys.end());
      lowest[k] = ys[q];
    }
    double sum = 0, truth_sum = 0;
    long count = 0;
    for (std::size_t i = 1; i + 1 < n; ++i) {
      const double dt = t[i + 1] - t[i - 1];
      if (!(dt > 1e-9)) continue;
      for (int k = 0; k < 4; ++k) {
        const glm::vec3 dg = g[i + 1][k_skate[k]] - g[i - 1][k_skate[k]];
        const double vg = std::sqrt(dg.x * dg.x + dg.z * dg.z) / dt;
        if (!(vg < o.planted_speed && g[i][k_skate[k]].y < lowest[k] + o.planted_height)) continue;
        const glm::vec3 ds = s[i + 1][k_skate[k]] - s[i - 1][k_skate[k]];
        sum += std::sqrt(ds.x * ds.x + ds.z * ds.z) / dt;
        truth_sum += vg;
        ++count;
      }
    }
    out.planted = count;
    out.skate_cm_s = count ? 100.0 * sum / count : 0.0;
    out.truth_skate_cm_s = count ? 100.0 * truth_sum / count : 0.0;
  }
  // Penetration and the lowest toe (solved floor: Y = 0).
  {
    double sum = 0;
    float low = 1e9f;
    for (std::size_t i = 0; i < n; ++i) {
      for (mp q : k_floor_points) sum += std::max(0.f, -s[i][q].y);
      low = std::min({low, s[i][mp::left_toe_tip].y, s[i][mp::right_toe_tip].y});
    }
    out.penetration_cm = 100.0 * sum / (4.0 * n);
    out.lowest_toe_cm = 100.0 * low;
  }
  (void)floor_truth;
  if (o.feet_only) return {};

  // One yaw for the take from the hips-relative joints.
  std::vector<glm::dvec3> a, b;
  for (std::size_t i = 0; i < n; ++i)
    for (mp q : k_scored) {
      a.push_back(glm::dvec3(s[i][q] - s[i][mp::hip_mid]));
      b.push_back(glm::dvec3(g[i][q] - g[i][mp::hip_mid]));
    }
  float c = 1.f, sn = 0.f;
  best_yaw(a, b, c, sn);
  double mpjpe = 0, pa = 0, lean = 0;
  std::vector<glm::vec3> rel_s(n * k_scored_count), rel_g(n * k_scored_count);
  for (std::size_t i = 0; i < n; ++i) {
    glm::dvec3 sa[k_scored_count], gb[k_scored_count];
    for (int k = 0; k < k_scored_count; ++k) {
      const glm::vec3 rs = rotate_y(s[i][k_scored[k]] - s[i][mp::hip_mid], c, sn);
      const glm::vec3 rg = g[i][k_scored[k]] - g[i][mp::hip_mid];
      rel_s[i * k_scored_count + k] = rs;
      rel_g[i * k_scored_count + k] = rg;
      mpjpe += glm::length(rs - rg);
      sa[k] = glm::dvec3(rs);
      gb[k] = glm::dvec3(rg);
    }
    pa += procrustes_error(sa, gb, k_scored_count);
    lean += std::fabs(lean_deg(s[i]) - lean_deg(g[i]));
  }
  out.mpjpe_mm = 1000.0 * mpjpe / (n * k_scored_count);
  out.pa_mpjpe_mm = 1000.0 * pa / n;
  out.lean_deg = lean / n;
  double acc = 0;
  for (std::size_t i = 1; i + 1 < n; ++i)
    for (int k = 0; k < k_scored_count; ++k) {
      auto at = [&](const std::vector<glm::vec3>& v, std::size_t f) {
        return v[f * k_scored_count + k];
      };
      const glm::vec3 as = at(rel_s, i + 1) - 2.f * at(rel_s, i) + at(rel_s, i - 1);
      const glm::vec3 ag = at(rel_g, i + 1) - 2.f * at(rel_g, i) + at(rel_g, i - 1);
      acc += glm::length(as - ag);
    }
  out.accel_mm = 1000.0 * acc / ((n - 2) * k_scored_count);
  // Root: best yaw about the centroids, then translation.
  glm::dvec3 cs(0.0), cg(0.0);
  for (std::size_t i = 0; i < n; ++i)
    cs += glm::dvec3(s[i][mp::hip_mid]), cg += glm::dvec3(g[i][mp::hip_mid]);
  cs /= static_cast<double>(n);
  cg /= static_cast<double>(n);
  a.clear();
  b.clear();
  for (std::size_t i = 0; i < n; ++i) {
    a.push_back(glm::dvec3(s[i][mp::hip_mid]) - cs);
    b.push_back(glm::dvec3(g[i][mp::hip_mid]) - cg);
  }
  best_yaw(a, b, c, sn);
  double root = 0;
  for (std::size_t i = 0; i < n; ++i)
    root += glm::length(glm::dvec3(rotate_y(glm::vec3(a[i]), c, sn)) - b[i]);
  out.root_cm = 100.0 * root / n;
  return {};
}

std::string world_scores_json(const world_scores& s) {
  char buf[640];
  if (s.feet_only) {
    std::snprintf(buf, sizeof buf,
                  "{\"frames\":%ld,\"planted\":%ld,\"skate_cm_s\":%.3f,\"truth_skate_cm_s\":%.3f,"
                  "\"penetration_cm\":%.3f,\"lowest_toe_cm\":%.3f}",
                  s.frames, s.planted, s.skate_cm_s, s.truth_skate_cm_s, s.penetration_cm,
                  s.lowest_toe_cm);
  } else {
    std::snprintf(buf, sizeof buf,
                  "{\"frames\":%ld,\"planted\":%ld,\"mpjpe_mm\":%.3f,\"pa_mpjpe_mm\":%.3f,"
                  "\"lean_deg\":%.3f,\"accel_mm\":%.3f,\"root_cm\":%.3f,\"skate_cm_s\":%.3f,"
                  "\"truth_skate_cm_s\":%.3f,\"penetration_cm\":%.3f,\"lowest_toe_cm\":%.3f}",
                  s.frames, s.planted, s.mpjpe_mm, s.pa_mpjpe_mm, s.lean_deg, s.accel_mm, s.root_cm,
                  s.skate_cm_s, s.truth_skate_cm_s, s.penetration_cm, s.lowest_toe_cm);
  }
  return buf;
}

}  // namespace avatarmap
