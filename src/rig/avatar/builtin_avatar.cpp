// The built-in avatar's geometry: tubes with elliptic cross-sections along chains of joints
// (torso, limbs, fingers, feet), ellipsoids (head, eyes, nose, mouth, brows) and spherical sheets
// (eyelids), skinned to the proxy skeleton's joints with weights blended across each joint, and
// the face's morph targets as the difference between the face built with an expression's
// parameters and the neutral face. Lengths are those of the 1.70 m design, scaled. See
// include/avatarmap/avatar/builtin_avatar.hpp and docs/avatar.md.
#include "avatarmap/avatar/builtin_avatar.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <new>
#include <utility>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/blendshape.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/time/seconds_text.hpp"

namespace avatarmap {
namespace {

// Materials (linear colours).
enum material_id { k_skin, k_shirt, k_trousers, k_shoes, k_face };
const glm::vec3 k_skin_colour{0.80f, 0.56f, 0.44f};
const glm::vec3 k_hair_colour{0.07f, 0.04f, 0.025f};
const glm::vec3 k_lid_colour{0.74f, 0.50f, 0.39f};
const glm::vec3 k_eye_white{0.90f, 0.90f, 0.88f};
const glm::vec3 k_iris_colour{0.03f, 0.05f, 0.10f};
const glm::vec3 k_mouth_colour{0.32f, 0.05f, 0.06f};
const glm::vec3 k_tongue_colour{0.80f, 0.36f, 0.38f};

// Influence of up to two bones on a vertex.
struct skin2 {
  int bone[2] = {0, 0};
  float weight[2] = {1.f, 0.f};
};

skin2 rigid(bone b) {
  skin2 s;
  s.bone[0] = s.bone[1] = idx(b);
  return s;
}

float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

// Vertices and triangles of one primitive being built.
class mesh_builder {
 public:
  int vertex(const glm::vec3& p, const glm::vec3& colour, const skin2& s) {
    positions_.push_back(p);
    colours_.push_back(colour);
    skins_.push_back(s);
    return static_cast<int>(positions_.size()) - 1;
  }
  void triangle(int a, int b, int c) {
    indices_.push_back(static_cast<std::uint32_t>(a));
    indices_.push_back(static_cast<std::uint32_t>(b));
    indices_.push_back(static_cast<std::uint32_t>(c));
  }
  // Joins ring `a` to ring `b` (same size; `b` further along the axis that the rings turn
  // counter-clockwise about), outward-facing.
  void join(int a, int b, int sides) {
    for (int k = 0; k < sides; ++k) {
      const int k1 = (k + 1) % sides;
      triangle(a + k, a + k1, b + k1);
      triangle(a + k, b + k1, b + k);
    }
  }
  // A fan from `pole` to ring `r`: the pole lies behind the ring (before it along the axis)
  // when `before`, else beyond it.
  void fan(int pole, int r, int sides, bool before) {
    for (int k = 0; k < sides; ++k) {
      const int k1 = (k + 1) % sides;
      if (before)
        triangle(pole, r + k1, r + k);
      else
        triangle(r + k, r + k1, pole);
    }
  }

  std::vector<glm::vec3>& positions() { return positions_; }
  std::vector<glm::vec3>& colours() { return colours_; }
  std::vector<skin2>& skins() { return skins_; }

  // The finished primitive: normals from the faces around each vertex (area-weighted).
  avatar_primitive finish(int material, bool with_colours) const {
    avatar_primitive p;
    p.material = material;
    p.positions = positions_;
    p.indices = indices_;
    p.normals.assign(positions_.size(), glm::vec3(0.f));
    for (std::size_t t = 0; t + 2 < indices_.size(); t += 3) {
      const glm::vec3 &a = positions_[indices_[t]], &b = positions_[indices_[t + 1]],
                      &c = positions_[indices_[t + 2]];
      const glm::vec3 n = glm::cross(b - a, c - a);
      for (int k = 0; k < 3; ++k) p.normals[indices_[t + static_cast<std::size_t>(k)]] += n;
    }
    for (glm::vec3& n : p.normals) {
      const float len = glm::length(n);
      n = len > 0.f ? n / len : glm::vec3(0.f, 1.f, 0.f);
    }
    if (with_colours) p.colors = colours_;
    p.joints.resize(positions_.size());
    p.weights.resize(positions_.size());
    for (std::size_t v = 0; v < positions_.size(); ++v) {
      const skin2& s = skins_[v];
      // Unused slots keep joint 0 and weight 0 (validators flag a zero weight on any other).
      std::array<std::uint8_t, 4> j{};
      glm::vec4 w(0.f);
      if (s.bone[0] == s.bone[1] || s.weight[1] <= 0.f || s.weight[0] <= 0.f) {
        j[0] = static_cast<std::uint8_t>(s.weight[1] > s.weight[0] ? s.bone[1] : s.bone[0]);
        w[0] = 1.f;
      } else {
        j[0] = static_cast<std::uint8_t>(s.bone[0]);
        j[1] = static_cast<std::uint8_t>(s.bone[1]);
        w[0] = s.weight[0];
        w[1] = 1.f - s.weight[0];
      }
      p.joints[v] = j;
      p.weights[v] = w;
    }
    return p;
  }

 private:
  std::vector<glm::vec3> positions_;
  std::vector<glm::vec3> colours_;
  std::vector<skin2> skins_;
  std::vector<std::uint32_t> indices_;
};

// A right-handed frame (u, v, t) for a tube along `t`, v as close to `v_hint` as possible.
void frame(const glm::vec3& t, const glm::vec3& v_hint, glm::vec3& u, glm::vec3& v) {
  u = glm::cross(v_hint, t);
  if (glm::length(u) < 1e-6f) u = glm::cross(glm::vec3(0.f, 0.f, 1.f), t);
  u = glm::normalize(u);
  v = glm::cross(t, u);
}

// Appends a ring of `sides` vertices (centre c, frame u, v, radii ru, rv); returns its first index.
int ring(mesh_builder& m, const glm::vec3& c, const glm::vec3& u, const glm::vec3& v, float ru,
         float rv, int sides, const glm::vec3& colour, const skin2& s) {
  int first = -1;
  for (int k = 0; k < sides; ++k) {
    const float a = 2.f * k_pi * float(k) / float(sides);
    const int i = m.vertex(c + ru * std::cos(a) * u + rv * std::sin(a) * v, colour, s);
    if (first < 0) first = i;
  }
  return first;
}

// A point of a chain: position and the half-widths of the cross-section there.
struct chain_point {
  glm::vec3 p;
  float ru, rv;  // along u (cross(v_hint, t)) and v (as close to v_hint as possible)
};

struct chain_style {
  glm::vec3 v_hint{0.f, 1.f, 0.f};
  float blend = 0.f;           // half-width of the weight blend across a joint (metres)
  float ring_spacing = 0.02f;  // metres between rings
  int sides = 16;
  float cap_start = 0.f;  // length of the rounded caps along the axis (0: left open)
  float cap_end = 0.f;
  int cap_rings = 4;
};

// A closed tube along points[0..n-1]; segment i (points i -> i+1) belongs to bones[i]; across
// each interior point where the bone changes, weights go smoothly from one bone to the next over
// +-blend. Rounded caps at both ends.
void add_chain(mesh_builder& m, const std::vector<chain_point>& pts, const std::vector<bone>& bones,
               const chain_style& st, const glm::vec3& colour) {
  const std::size_t segs = pts.size() - 1;
  std::vector<float> start(pts.size(), 0.f), length(segs);
  for (std::size_t i = 0; i < segs; ++i) {
    length[i] = glm::length(pts[i + 1].p - pts[i].p);
    start[i + 1] = start[i] + length[i];
  }
  auto tangent_of = [&](std::size_t i) { return (pts[i + 1].p - pts[i].p) / length[i]; };
  auto skin_at = [&](std::size_t seg, float s) {
    skin2 out = rigid(bones[seg]);
    // Blend with the previous segment's bone near this segment's start, or with the next one's
    // near its end (the blend is at most 0.45 of either segment, so only one applies).
    if (seg > 0 && bones[seg - 1] != bones[seg]) {
      const float b = std::min({st.blend, 0.45f * length[seg], 0.45f * length[seg - 1]});
      if (b > 0.f && s - start[seg] < b) {
        const float a = smoothstep(start[seg] - b, start[seg] + b, s);
        out.bone[0] = idx(bones[seg - 1]);
        out.weight[0] = 1.f - a;
        out.bone[1] = idx(bones[seg]);
        out.weight[1] = a;
      }
    }
    if (seg + 1 < segs && bones[seg + 1] != bones[seg]) {
      const float b = std::min({st.blend, 0.45f * length[seg], 0.45f * length[seg + 1]});
      if (b > 0.f && start[seg + 1] - s < b) {
        const float a = smoothstep(start[seg + 1] - b, start[seg + 1] + b, s);
        out.bone[0] = idx(bones[seg]);
        out.weight[0] = 1.f - a;
        out.bone[1] = idx(bones[seg + 1]);
        out.weight[1] = a;
      }
    }
    return out;
  };

  std::vector<int> rings;
  glm::vec3 u, v;
  // Start cap: pole first, then rings growing to the first point's cross-section.
  const glm::vec3 t0 = tangent_of(0);
  frame(t0, st.v_hint, u, v);
  int start_pole = -1;
  if (st.cap_start > 0.f) {
    start_pole = m.vertex(pts[0].p - st.cap_start * t0, colour, skin_at(0, 0.f));
    for (int k = st.cap_rings - 1; k >= 1; --k) {
      const float a = 0.5f * k_pi * float(k) / float(st.cap_rings);
      rings.push_back(ring(m, pts[0].p - st.cap_start * std::sin(a) * t0, u, v,
                           pts[0].ru * std::cos(a), pts[0].rv * std::cos(a), st.sides, colour,
                           skin_at(0, 0.f)));
    }
  }
  for (std::size_t i = 0; i < segs; ++i) {
    const int n = std::max(1, static_cast<int>(std::ceil(length[i] / st.ring_spacing)));
    for (int k = 0; k < n; ++k) {
      const float f = float(k) / float(n);
      glm::vec3 t = tangent_of(i);
      if (k == 0 && i > 0) t = glm::normalize(t + tangent_of(i - 1));  // no pinch at a bend
      frame(t, st.v_hint, u, v);
      const glm::vec3 c = glm::mix(pts[i].p, pts[i + 1].p, f);
      rings.push_back(ring(m, c, u, v, glm::mix(pts[i].ru, pts[i + 1].ru, f),
                           glm::mix(pts[i].rv, pts[i + 1].rv, f), st.sides, colour,
                           skin_at(i, start[i] + f * length[i])));
    }
  }
  const glm::vec3 tn = tangent_of(segs - 1);
  frame(tn, st.v_hint, u, v);
  const chain_point& last = pts.back();
  const skin2 end_skin = skin_at(segs - 1, start[segs]);
  rings.push_back(ring(m, last.p, u, v, last.ru, last.rv, st.sides, colour, end_skin));
  int end_pole = -1;
  if (st.cap_end > 0.f) {
    for (int k = 1; k < st.cap_rings; ++k) {
      const float a = 0.5f * k_pi * float(k) / float(st.cap_rings);
      rings.push_back(ring(m, last.p + st.cap_end * std::sin(a) * tn, u, v, last.ru * std::cos(a),
                           last.rv * std::cos(a), st.sides, colour, end_skin));
    }
    end_pole = m.vertex(last.p + st.cap_end * tn, colour, end_skin);
  }
  if (start_pole >= 0) m.fan(start_pole, rings.front(), st.sides, true);
  for (std::size_t r = 0; r + 1 < rings.size(); ++r) m.join(rings[r], rings[r + 1], st.sides);
  if (end_pole >= 0) m.fan(end_pole, rings.back(), st.sides, false);
}

// An ellipsoid (centre c, axes u, v, t right-handed, radii) from pole -t to pole +t. `shape`
// may move each vertex after it is placed (used to bend the mouth and brows); `paint` gives
// each vertex its colour from its position on the unit sphere.
template <class shape_fn, class paint_fn>
void add_ellipsoid(mesh_builder& m, const glm::vec3& c, const glm::vec3& u, const glm::vec3& v,
                   const glm::vec3& t, const glm::vec3& radii, int rings_count, int sides,
                   const skin2& s, shape_fn shape, paint_fn paint) {
  auto put = [&](const glm::vec3& unit) {
    const glm::vec3 p = c + radii.x * unit.x * u + radii.y * unit.y * v + radii.z * unit.z * t;
    return m.vertex(shape(p, unit), paint(unit), s);
  };
  const int south = put(glm::vec3(0.f, 0.f, -1.f));
  std::vector<int> rings;
  for (int r = 1; r < rings_count; ++r) {
    const float b = k_pi * float(r) / float(rings_count);
    int first = -1;
    for (int k = 0; k < sides; ++k) {
      const float a = 2.f * k_pi * float(k) / float(sides);
      const int i =
          put(glm::vec3(std::sin(b) * std::cos(a), std::sin(b) * std::sin(a), -std::cos(b)));
      if (first < 0) first = i;
    }
    rings.push_back(first);
  }
  const int north = put(glm::vec3(0.f, 0.f, 1.f));
  m.fan(south, rings.front(), sides, true);
  for (std::size_t r = 0; r + 1 < rings.size(); ++r) m.join(rings[r], rings[r + 1], sides);
  m.fan(north, rings.back(), sides, false);
}

const auto k_no_shape = [](const glm::vec3& p, const glm::vec3&) { return p; };

// ---------------------------------------------------------------------------------------------
// The body (mesh 0): one primitive per material.

struct body_parts {
  mesh_builder skin, shirt, trousers, shoes;
};

void add_torso(body_parts& b, const builtin_avatar& a) {
  const float s = a.skeleton.scale;
  // A cross-section `dy` (1.70 m design metres) above the joint of `j`, half-width rx, half-depth
  // rz: the bone changes at the joints themselves, so the weights blend across them.
  auto at = [&](bone j, float dy, float rx, float rz) {
    return chain_point{a.joints[idx(j)] + glm::vec3(0.f, dy * s, 0.f), rx * s, rz * s};
  };
  // The torso runs along +Y with u = cross(Z, Y) = -X (width) and v = Z (depth).
  chain_style st;
  st.v_hint = {0.f, 0.f, 1.f};
  st.blend = 0.05f * s;
  st.ring_spacing = 0.02f * s;
  st.sides = 32;
  st.cap_start = 0.05f * s;
  st.cap_end = 0.02f * s;
  // Pelvis (trousers): below the hips joint to just above the spine joint.
  add_chain(b.trousers,
            {at(bone::hips, -0.10f, 0.14f, 0.10f), at(bone::hips, 0.f, 0.16f, 0.11f),
             at(bone::spine, 0.f, 0.145f, 0.10f), at(bone::spine, 0.03f, 0.14f, 0.098f)},
            {bone::hips, bone::hips, bone::spine}, st, k_skin_colour);
  // Chest (shirt): from the waist to the base of the neck; its hem overlaps the pelvis.
  st.cap_start = 0.02f * s;
  mesh_builder& m = b.shirt;
  const std::size_t first = m.positions().size();
  add_chain(
      m,
      {at(bone::spine, -0.02f, 0.152f, 0.107f), at(bone::spine, 0.f, 0.15f, 0.105f),
       at(bone::chest, 0.f, 0.152f, 0.106f), at(bone::upper_chest, 0.f, 0.165f, 0.11f),
       at(bone::upper_chest, 0.13f, 0.172f, 0.10f), at(bone::upper_chest, 0.19f, 0.15f, 0.085f),
       at(bone::upper_chest, 0.215f, 0.075f, 0.06f)},
      {bone::spine, bone::spine, bone::chest, bone::upper_chest, bone::upper_chest,
       bone::upper_chest},
      st, k_skin_colour);
  // The top of the chest toward each shoulder follows the shoulder (clavicle) bones.
  const float uc_y = a.joints[idx(bone::upper_chest)].y;
  for (std::size_t i = first; i < m.positions().size(); ++i) {
    const glm::vec3& p = m.positions()[i];
    const float w = smoothstep(0.08f * s, 0.15f * s, std::fabs(p.x)) *
                    smoothstep(uc_y + 0.06f * s, uc_y + 0.12f * s, p.y);
    if (w <= 0.f) continue;
    skin2& sk = m.skins()[i];
    sk.bone[0] = idx(bone::upper_chest);
    sk.weight[0] = 1.f - w;
    sk.bone[1] = idx(p.x > 0.f ? bone::left_shoulder : bone::right_shoulder);
    sk.weight[1] = w;
  }
  // Neck (skin): from inside the chest into the head.
  const glm::vec3 neck = a.joints[idx(bone::neck)], head = a.joints[idx(bone::head)];
  chain_style ns;
  ns.v_hint = {0.f, 0.f, 1.f};
  ns.blend = 0.03f * s;
  ns.ring_spacing = 0.015f * s;
  ns.sides = 20;
  ns.cap_start = 0.02f * s;
  ns.cap_end = 0.02f * s;
  add_chain(b.skin,
            {{neck - glm::vec3(0.f, 0.05f * s, 0.f), 0.05f * s, 0.05f * s},
             {neck, 0.047f * s, 0.047f * s},
             {head, 0.045f * s, 0.045f * s},
             {head + glm::vec3(0.f, 0.05f * s, 0.f), 0.043f * s, 0.043f * s}},
            {bone::upper_chest, bone::neck, bone::head}, ns, k_skin_colour);
}

// One side's limbs; side = +1 (left, +X) or -1 (right).
void add_limbs(body_parts& b, const builtin_avatar& a, float side) {
  const float s = a.skeleton.scale;
  auto B = [side](bone left) { return side > 0.f ? left : mirror_bone(left); };
  auto J = [&](bone left) { return a.joints[idx(B(left))]; };
  const glm::vec3 x_dir(side, 0.f, 0.f);

  // Arm (shirt, long sleeves) from inside the shoulder to the wrist; u = Z (width), v = Y.
  chain_style arm;
  arm.v_hint = {0.f, 1.f, 0.f};
  arm.blend = 0.05f * s;
  arm.ring_spacing = 0.02f * s;
  arm.sides = 16;
  arm.cap_start = 0.02f * s;
  arm.cap_end = 0.02f * s;
  const glm::vec3 shoulder = J(bone::left_shoulder), upper = J(bone::left_upper_arm),
                  lower = J(bone::left_lower_arm), hand = J(bone::left_hand);
  add_chain(b.shirt,
            {{shoulder + 0.06f * s * x_dir, 0.05f * s, 0.052f * s},
             {upper, 0.05f * s, 0.05f * s},
             {lower, 0.038f * s, 0.036f * s},
             {hand, 0.03f * s, 0.026f * s}},
            {B(bone::left_shoulder), B(bone::left_upper_arm), B(bone::left_lower_arm)}, arm,
            k_skin_colour);
  // Palm (skin): wrist to knuckles, wide along Z, thin along Y.
  chain_style palm = arm;
  palm.blend = 0.02f * s;
  palm.ring_spacing = 0.012f * s;
  palm.cap_start = 0.01f * s;
  palm.cap_end = 0.012f * s;
  const glm::vec3 z_shift(0.f, 0.f, -0.006f * s);
  add_chain(b.skin,
            {{hand - 0.025f * s * x_dir, 0.027f * s, 0.022f * s},
             {hand, 0.03f * s, 0.021f * s},
             {hand + 0.05f * s * x_dir + z_shift, 0.042f * s, 0.016f * s},
             {hand + 0.082f * s * x_dir + z_shift, 0.041f * s, 0.013f * s}},
            {B(bone::left_lower_arm), B(bone::left_hand), B(bone::left_hand)}, palm, k_skin_colour);
  // Fingers: from inside the palm through the three joints to the tip.
  chain_style finger;
  finger.v_hint = {0.f, 1.f, 0.f};
  finger.blend = 0.006f * s;
  finger.ring_spacing = 0.008f * s;
  finger.sides = 8;
  finger.cap_rings = 3;
  const float radius[5] = {0.0115f, 0.0095f, 0.0098f, 0.009f, 0.008f};
  for (int f = 0; f < 5; ++f) {
    const bone first = static_cast<bone>(idx(bone::left_thumb_metacarpal) + 3 * f);
    const bone b1 = B(first), b2 = B(static_cast<bone>(idx(first) + 1)),
               b3 = B(static_cast<bone>(idx(first) + 2));
    const glm::vec3 p1 = a.joints[idx(b1)], p2 = a.joints[idx(b2)], p3 = a.joints[idx(b3)];
    const glm::vec3 dir = glm::normalize(p3 - p2);
    const float r = radius[f] * s;
    const glm::vec3 tip = p3 + a.skeleton.lengths[idx(b3)] * dir;
    finger.cap_start = 0.6f * r;
    finger.cap_end = r;
    if (f == 0) {  // thumb: the metacarpal starts at the palm's edge
      add_chain(b.skin,
                {{p1, 1.2f * r, r},
                 {p2, r, 0.95f * r},
                 {p3, 0.9f * r, 0.88f * r},
                 {tip - r * dir, 0.8f * r, 0.8f * r}},
                {b1, b2, b3}, finger, k_skin_colour);
      continue;
    }
    const glm::vec3 d1 = glm::normalize(p2 - p1);
    finger.cap_end = 0.8f * r;
    add_chain(b.skin,
              {{p1 - 0.015f * s * d1, r, r},
               {p1, r, r},
               {p2, 0.93f * r, 0.93f * r},
               {p3, 0.86f * r, 0.86f * r},
               {tip - 0.8f * r * dir, 0.8f * r, 0.8f * r}},
              {B(bone::left_hand), b1, b2, b3}, finger, k_skin_colour);
  }

  // Leg (trousers): from inside the pelvis to just below the ankle; u = X, v = Z.
  chain_style leg;
  leg.v_hint = {0.f, 0.f, 1.f};
  leg.blend = 0.06f * s;
  leg.ring_spacing = 0.025f * s;
  leg.sides = 20;
  leg.cap_start = 0.03f * s;
  leg.cap_end = 0.02f * s;
  const glm::vec3 thigh = J(bone::left_upper_leg), knee = J(bone::left_lower_leg),
                  ankle = J(bone::left_foot);
  add_chain(b.trousers,
            {{thigh + glm::vec3(0.f, 0.07f * s, 0.f), 0.08f * s, 0.085f * s},
             {thigh, 0.082f * s, 0.085f * s},
             {knee, 0.052f * s, 0.055f * s},
             {ankle, 0.043f * s, 0.045f * s},
             {ankle - glm::vec3(0.f, 0.02f * s, 0.f), 0.043f * s, 0.045f * s}},
            {B(bone::hips), B(bone::left_upper_leg), B(bone::left_lower_leg), B(bone::left_foot)},
            leg, k_skin_colour);
  // Foot (shoes): heel to toe tip along +Z with a flat sole on the floor; u = X, v = Y.
  chain_style foot;
  foot.v_hint = {0.f, 1.f, 0.f};
  foot.blend = 0.015f * s;
  foot.ring_spacing = 0.015f * s;
  foot.sides = 16;
  foot.cap_start = 0.025f * s;
  foot.cap_end = 0.015f * s;
  const glm::vec3 toe = J(bone::left_toes);
  const float toe_tip_z =
      toe.z + a.skeleton.lengths[idx(bone::left_toes)] * bone_rest_direction(bone::left_toes).z;
  const float g = 0.f;  // the floor
  auto fp = [&](float z, float height, float rx) {
    return chain_point{glm::vec3(ankle.x, g + height * s, z), rx * s, height * s};
  };
  add_chain(b.shoes,
            {fp(ankle.z - 0.045f * s, 0.035f, 0.038f), fp(ankle.z + 0.03f * s, 0.042f, 0.045f),
             fp(toe.z, 0.026f, 0.046f), fp(toe_tip_z - 0.015f * s, 0.018f, 0.04f)},
            {B(bone::left_foot), B(bone::left_foot), B(bone::left_toes)}, foot, k_skin_colour);
}

// ---------------------------------------------------------------------------------------------
// The face (mesh 1): head, eyes, eyelids, brows, nose and mouth in one primitive with vertex
// colours; built from parameters so that each expression is the same vertices moved.

struct face_params {
  // Index 0 is the avatar's (= the person's) left, +X; 1 its right.
  float upper_lid[2] = {55.f, 55.f};     // degrees from the top of the eye to the upper lid's edge
  float lower_lid[2] = {125.f, 125.f};   // degrees from the top to the lower lid's edge
  float brow_raise[2] = {0.f, 0.f};      // metres (1.70 m design) up
  float brow_tilt[2] = {0.f, 0.f};       // metres the inner end goes down (the outer end up)
  float mouth_width = 1.f;               // times the neutral width
  float mouth_open = 0.004f;             // half-height (metres)
  float mouth_forward = 0.f;             // lips pushed forward (metres)
  float mouth_shift = 0.f;               // whole mouth toward +X (metres)
  float smile[2] = {0.f, 0.f};           // each corner up (metres; negative: down)
  float corner_out[2] = {0.f, 0.f};      // each corner outward (metres)
  float upper_lip_up[2] = {0.f, 0.f};    // each half of the upper lip up (metres)
  float lower_lip_down[2] = {0.f, 0.f};  // each half of the lower lip down (metres)
  float jaw_open = 0.f;                  // lower lip down, the chin half as much (metres)
  float jaw_side = 0.f;                  // lower lip and chin toward +X (metres)
  float jaw_forward = 0.f;               // lower lip and chin forward (metres)
  float cheek_puff = 0.f;                // cheeks outward (metres)
  float cheek_raise[2] = {0.f, 0.f};     // each cheek up (metres)
  float sneer[2] = {0.f, 0.f};           // each side of the nose up (metres)
  float tongue_out = 0.f;                // tongue forward out of the head (metres)
};

// Closed eyelids meet at this angle from the top of the eye (degrees).
constexpr float k_lids_closed = 103.f;

mesh_builder build_face(const builtin_avatar& a, const face_params& fp) {
  mesh_builder m;
  const float s = a.skeleton.scale;
  const glm::vec3 head = a.joints[idx(bone::head)];
  const glm::vec3 X(1.f, 0.f, 0.f), Y(0.f, 1.f, 0.f), Z(0.f, 0.f, 1.f);
  // The head: an ellipsoid whose top is the proxy's head tip (0.23 m above the head joint).
  const glm::vec3 hc = head + s * glm::vec3(0.f, 0.115f, -0.008f);
  const glm::vec3 hr = s * glm::vec3(0.078f, 0.118f, 0.094f);
  auto surface_z = [&](float x, float y) {
    const float dx = (x - hc.x) / hr.x, dy = (y - hc.y) / hr.y;
    return hc.z + hr.z * std::sqrt(std::max(0.f, 1.f - dx * dx - dy * dy));
  };
  const skin2 on_head = rigid(bone::head);
  const float mouth_y = head.y + 0.045f * s;
  const float eye_y = a.joints[idx(bone::left_eye)].y;
  // The head's skin moves with the jaw (below the mouth), the cheeks (puffed, raised). Only
  // the front of the head moves.
  auto head_shape = [&](const glm::vec3& p, const glm::vec3&) {
    glm::vec3 q = p;
    const float front = smoothstep(0.1f, 0.5f, (p.z - hc.z) / hr.z);
    if (front <= 0.f) return q;
    const float chin = front * smoothstep(mouth_y - 0.01f * s, mouth_y - 0.045f * s, p.y);
    q += chin * s * glm::vec3(fp.jaw_side, -0.5f * fp.jaw_open, fp.jaw_forward);
    for (int e = 0; e < 2; ++e) {
      const float side = e == 0 ? 1.f : -1.f;
      auto bump = [&](float cy, float r) {
        const float dx = p.x - (hc.x + side * 0.045f * s), dy = p.y - cy;
        return front * std::exp(-(dx * dx + dy * dy) / (r * r * s * s));
      };
      q += bump(mouth_y + 0.015f * s, 0.022f) * fp.cheek_puff * s * glm::normalize(p - hc);
      q.y += bump(eye_y - 0.03f * s, 0.018f) * fp.cheek_raise[e] * s;
    }
    return q;
  };
  // Axes (u, v, t) = (X, -Z, Y): the poles on the Y axis, so the rings are horizontal.
  add_ellipsoid(m, hc, X, -Z, Y, glm::vec3(hr.x, hr.z, hr.y), 24, 32, on_head, head_shape,
                [](const glm::vec3& n) {
                  // n = (x, -z, y) on the unit sphere: hair on the top and the back.
                  const float y = n.z, z = -n.y;
                  return (y > 0.45f || (z < -0.25f && y > -0.35f)) ? k_hair_colour : k_skin_colour;
                });
  // Nose: each side (n.x > 0 is +X, the avatar's left) lifts with its sneer.
  const float nose_y = head.y + 0.085f * s;
  add_ellipsoid(
      m, glm::vec3(hc.x, nose_y, surface_z(hc.x, nose_y) + 0.002f * s), X, -Z, Y,
      s * glm::vec3(0.011f, 0.012f, 0.016f), 8, 12, on_head,
      [&](const glm::vec3& p, const glm::vec3& n) {
        glm::vec3 q = p;
        q.y += s * (fp.sneer[0] * std::max(0.f, n.x) + fp.sneer[1] * std::max(0.f, -n.x));
        return q;
      },
      [](const glm::vec3&) { return k_skin_colour; });
  // Eyes (on the eye bones), lids and brows (on the head); e = 0 left, 1 right.
  for (int e = 0; e < 2; ++e) {
    const float side = e == 0 ? 1.f : -1.f;
    const bone eye_bone = e == 0 ? bone::left_eye : bone::right_eye;
    const glm::vec3 ec = a.joints[idx(eye_bone)];
    const skin2 on_eye = rigid(eye_bone);
    add_ellipsoid(m, ec, X, Y, Z, glm::vec3(0.0155f * s), 12, 16, on_eye, k_no_shape,
                  [](const glm::vec3&) { return k_eye_white; });
    add_ellipsoid(m, ec + 0.0147f * s * Z, X, Y, Z, s * glm::vec3(0.0078f, 0.0078f, 0.0025f), 6, 16,
                  on_eye, k_no_shape, [](const glm::vec3&) { return k_iris_colour; });
    // Lids: sheets of a sphere around the eye, over the front (azimuth -100..100 degrees from
    // +Z); the upper from 15 degrees below the top to its edge, the lower from 15 degrees
    // above the bottom up to its edge. Seen from outside they face away from the eye.
    const float lid_r = 0.0195f * s;
    constexpr int k_lid_rings = 8, k_lid_cols = 14;
    auto lid = [&](float from_deg, float to_deg) {
      const int first = static_cast<int>(m.positions().size());
      for (int r = 0; r <= k_lid_rings; ++r) {
        const float th = (from_deg + (to_deg - from_deg) * float(r) / k_lid_rings) * k_pi / 180.f;
        for (int c = 0; c <= k_lid_cols; ++c) {
          const float ph = (-100.f + 200.f * float(c) / k_lid_cols) * k_pi / 180.f;
          const glm::vec3 d(std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph));
          m.vertex(ec + lid_r * d, k_lid_colour, on_head);
        }
      }
      // Rows go down (upper lid) or up (lower lid); keep every triangle facing outward.
      const bool down = to_deg > from_deg;
      for (int r = 0; r < k_lid_rings; ++r)
        for (int c = 0; c < k_lid_cols; ++c) {
          const int p = first + r * (k_lid_cols + 1) + c, q = p + k_lid_cols + 1;
          if (down) {
            m.triangle(p, q, q + 1);
            m.triangle(p, q + 1, p + 1);
          } else {
            m.triangle(p, q + 1, q);
            m.triangle(p, p + 1, q + 1);
          }
        }
    };
    lid(15.f, fp.upper_lid[e]);
    lid(165.f, fp.lower_lid[e]);
    // Brow: a flat ellipsoid above the eye, bent onto the head's surface.
    const glm::vec3 bc(ec.x + 0.002f * side * s, ec.y + (0.026f + fp.brow_raise[e]) * s, 0.f);
    const float brow_rx = 0.017f * s;
    const glm::vec3 brow_c(bc.x, bc.y, surface_z(bc.x, bc.y) + 0.0015f * s);
    const float tilt = fp.brow_tilt[e] * s;
    add_ellipsoid(
        m, brow_c, Y, Z, X, glm::vec3(0.0035f * s, 0.004f * s, brow_rx), 6, 8, on_head,
        [&](const glm::vec3& p, const glm::vec3& n) {
          const float inner = -side * n.z;  // +1 at the end nearer the middle of the face
          glm::vec3 q = p;
          q.y -= tilt * inner;
          q.z += surface_z(p.x, brow_c.y) - surface_z(brow_c.x, brow_c.y);
          return q;
        },
        [](const glm::vec3&) { return k_hair_colour; });
  }
  // Mouth: a dark flat ellipsoid in the face, opened, widened, rounded and curved by the
  // parameters, bent onto the head's surface. On the unit sphere n.x is up (the upper lip),
  // n.z toward +X (the avatar's left corner).
  const glm::vec3 mc(hc.x, mouth_y, surface_z(hc.x, mouth_y) - 0.002f * s + fp.mouth_forward * s);
  const float mrx = 0.021f * fp.mouth_width * s;
  add_ellipsoid(
      m, mc, Y, Z, X, glm::vec3(fp.mouth_open * s, 0.008f * s, mrx), 8, 16, on_head,
      [&](const glm::vec3& p, const glm::vec3& n) {
        glm::vec3 q = p;
        const float left = std::max(0.f, n.z), right = std::max(0.f, -n.z);
        const float upper = std::max(0.f, n.x), lower = std::max(0.f, -n.x);
        const float to_left = 0.5f + 0.5f * n.z, to_right = 0.5f - 0.5f * n.z;
        q.y += s * (fp.smile[0] * left * left + fp.smile[1] * right * right);
        q.x += s * (fp.corner_out[0] * left * left - fp.corner_out[1] * right * right);
        q.y += s * upper * (fp.upper_lip_up[0] * to_left + fp.upper_lip_up[1] * to_right);
        q.y -= s * lower * (fp.lower_lip_down[0] * to_left + fp.lower_lip_down[1] * to_right);
        q += s * lower * glm::vec3(fp.jaw_side, -fp.jaw_open, fp.jaw_forward);
        q.x += s * fp.mouth_shift;
        q.z += surface_z(q.x, mouth_y) - surface_z(mc.x, mouth_y);
        return q;
      },
      [](const glm::vec3&) { return k_mouth_colour; });
  // Tongue: hidden inside the head behind the mouth until tongue_out pushes it out, forward
  // and a little down.
  add_ellipsoid(m,
                glm::vec3(hc.x, mouth_y - (0.001f + 0.3f * fp.tongue_out) * s,
                          surface_z(hc.x, mouth_y) - 0.016f * s + fp.tongue_out * s),
                Y, Z, X, s * glm::vec3(0.004f, 0.012f, 0.011f), 6, 12, on_head, k_no_shape,
                [](const glm::vec3&) { return k_tongue_colour; });
  return m;
}

// ARKit's 52 blendshapes (skeleton/blendshape.hpp) as face parameters, in that order: each a
// morph target named by ARKit's name. The eyeLook* ones leave the face as it is (the gaze turns
// the eye bones: lookAt is of type bone).
std::array<face_params, k_blendshape_count> arkit_shapes() {
  std::array<face_params, k_blendshape_count> out{};
  using B = blendshape;
  auto at = [&](B b) -> face_params& { return out[static_cast<std::size_t>(idx(b))]; };
  for (int e = 0; e < 2; ++e) {
    const bool l = e == 0;
    at(l ? B::brow_down_left : B::brow_down_right).brow_raise[e] = -0.004f;
    at(l ? B::brow_down_left : B::brow_down_right).brow_tilt[e] = 0.003f;
    at(l ? B::brow_outer_up_left : B::brow_outer_up_right).brow_raise[e] = 0.004f;
    at(l ? B::brow_outer_up_left : B::brow_outer_up_right).brow_tilt[e] = 0.003f;
    at(l ? B::cheek_squint_left : B::cheek_squint_right).cheek_raise[e] = 0.004f;
    at(l ? B::cheek_squint_left : B::cheek_squint_right).lower_lid[e] = 114.f;
    face_params& blink = at(l ? B::eye_blink_left : B::eye_blink_right);
    blink.upper_lid[e] = blink.lower_lid[e] = k_lids_closed;
    at(l ? B::eye_squint_left : B::eye_squint_right).lower_lid[e] = 110.f;
    at(l ? B::eye_squint_left : B::eye_squint_right).upper_lid[e] = 62.f;
    at(l ? B::eye_wide_left : B::eye_wide_right).upper_lid[e] = 36.f;
    at(l ? B::eye_wide_left : B::eye_wide_right).lower_lid[e] = 132.f;
    at(l ? B::mouth_dimple_left : B::mouth_dimple_right).corner_out[e] = 0.004f;
    at(l ? B::mouth_frown_left : B::mouth_frown_right).smile[e] = -0.006f;
    at(l ? B::mouth_lower_down_left : B::mouth_lower_down_right).lower_lip_down[e] = 0.006f;
    at(l ? B::mouth_press_left : B::mouth_press_right).upper_lip_up[e] = -0.003f;
    at(l ? B::mouth_press_left : B::mouth_press_right).lower_lip_down[e] = -0.003f;
    at(l ? B::mouth_smile_left : B::mouth_smile_right).smile[e] = 0.008f;
    at(l ? B::mouth_smile_left : B::mouth_smile_right).corner_out[e] = 0.002f;
    at(l ? B::mouth_stretch_left : B::mouth_stretch_right).corner_out[e] = 0.005f;
    at(l ? B::mouth_stretch_left : B::mouth_stretch_right).smile[e] = -0.002f;
    at(l ? B::mouth_upper_up_left : B::mouth_upper_up_right).upper_lip_up[e] = 0.005f;
    at(l ? B::nose_sneer_left : B::nose_sneer_right).sneer[e] = 0.004f;
    at(l ? B::nose_sneer_left : B::nose_sneer_right).brow_raise[e] = -0.001f;
  }
  face_params& inner_up = at(B::brow_inner_up);
  inner_up.brow_tilt[0] = inner_up.brow_tilt[1] = -0.004f;
  inner_up.brow_raise[0] = inner_up.brow_raise[1] = 0.002f;
  at(B::cheek_puff).cheek_puff = 0.008f;
  at(B::jaw_forward).jaw_forward = 0.006f;
  at(B::jaw_left).jaw_side = 0.006f;  // the person's left = the avatar's = +X
  at(B::jaw_right).jaw_side = -0.006f;
  at(B::jaw_open).jaw_open = 0.022f;
  // mouthClose: the lips closing over an open jaw (ARKit's meaning: with jawOpen).
  at(B::mouth_close).lower_lip_down[0] = at(B::mouth_close).lower_lip_down[1] = -0.012f;
  at(B::mouth_close).upper_lip_up[0] = at(B::mouth_close).upper_lip_up[1] = -0.002f;
  face_params& funnel = at(B::mouth_funnel);
  funnel.mouth_forward = 0.006f;
  funnel.mouth_width = 0.75f;
  funnel.mouth_open = 0.009f;
  at(B::mouth_left).mouth_shift = 0.008f;
  at(B::mouth_right).mouth_shift = -0.008f;
  face_params& pucker = at(B::mouth_pucker);
  pucker.mouth_forward = 0.008f;
  pucker.mouth_width = 0.55f;
  pucker.mouth_open = 0.003f;
  for (int e = 0; e < 2; ++e) {
    at(B::mouth_roll_lower).lower_lip_down[e] = -0.003f;
    at(B::mouth_roll_upper).upper_lip_up[e] = -0.003f;
    at(B::mouth_shrug_lower).lower_lip_down[e] = -0.004f;
    at(B::mouth_shrug_upper).upper_lip_up[e] = 0.003f;
  }
  at(B::mouth_roll_lower).mouth_forward = at(B::mouth_roll_upper).mouth_forward = -0.002f;
  at(B::mouth_shrug_lower).mouth_forward = at(B::mouth_shrug_upper).mouth_forward = 0.002f;
  at(B::tongue_out).tongue_out = 0.02f;
  at(B::tongue_out).lower_lip_down[0] = at(B::tongue_out).lower_lip_down[1] = 0.008f;
  return out;
}

// The VRM expressions as combinations of the ARKit targets (target t = blendshape t).
struct expression_recipe {
  const char* name;
  bool preset;
  std::vector<std::pair<blendshape, float>> parts;
};

std::vector<expression_recipe> expression_recipes() {
  using B = blendshape;
  return {
      {"blink", true, {{B::eye_blink_left, 1.f}, {B::eye_blink_right, 1.f}}},
      {"blinkLeft", true, {{B::eye_blink_left, 1.f}}},
      {"blinkRight", true, {{B::eye_blink_right, 1.f}}},
      {"aa", true, {{B::jaw_open, 0.75f}}},
      {"ih",
       true,
       {{B::jaw_open, 0.15f}, {B::mouth_stretch_left, 0.6f}, {B::mouth_stretch_right, 0.6f}}},
      {"ou", true, {{B::jaw_open, 0.15f}, {B::mouth_pucker, 0.8f}, {B::mouth_funnel, 0.3f}}},
      {"ee",
       true,
       {{B::jaw_open, 0.35f},
        {B::mouth_stretch_left, 0.4f},
        {B::mouth_stretch_right, 0.4f},
        {B::mouth_upper_up_left, 0.3f},
        {B::mouth_upper_up_right, 0.3f}}},
      {"oh", true, {{B::jaw_open, 0.45f}, {B::mouth_funnel, 0.8f}}},
      {"happy",
       true,
       {{B::mouth_smile_left, 1.f},
        {B::mouth_smile_right, 1.f},
        {B::cheek_squint_left, 0.6f},
        {B::cheek_squint_right, 0.6f},
        {B::eye_squint_left, 0.4f},
        {B::eye_squint_right, 0.4f},
        {B::brow_inner_up, 0.2f}}},
      {"angry",
       true,
       {{B::brow_down_left, 1.f},
        {B::brow_down_right, 1.f},
        {B::mouth_frown_left, 0.6f},
        {B::mouth_frown_right, 0.6f},
        {B::nose_sneer_left, 0.4f},
        {B::nose_sneer_right, 0.4f},
        {B::eye_squint_left, 0.3f},
        {B::eye_squint_right, 0.3f}}},
      {"sad",
       true,
       {{B::brow_inner_up, 1.f},
        {B::mouth_frown_left, 0.8f},
        {B::mouth_frown_right, 0.8f},
        {B::mouth_shrug_lower, 0.4f},
        {B::eye_blink_left, 0.15f},
        {B::eye_blink_right, 0.15f}}},
      {"relaxed",
       true,
       {{B::mouth_smile_left, 0.5f},
        {B::mouth_smile_right, 0.5f},
        {B::eye_blink_left, 0.35f},
        {B::eye_blink_right, 0.35f}}},
      {"surprised",
       true,
       {{B::eye_wide_left, 1.f},
        {B::eye_wide_right, 1.f},
        {B::brow_inner_up, 0.8f},
        {B::brow_outer_up_left, 0.8f},
        {B::brow_outer_up_right, 0.8f},
        {B::jaw_open, 0.5f},
        {B::mouth_funnel, 0.3f}}},
      // The proxy pose's custom brow expressions (expression.hpp).
      {"browUpLeft", false, {{B::brow_outer_up_left, 1.f}, {B::brow_inner_up, 0.3f}}},
      {"browUpRight", false, {{B::brow_outer_up_right, 1.f}, {B::brow_inner_up, 0.3f}}},
      {"browDownLeft", false, {{B::brow_down_left, 1.f}}},
      {"browDownRight", false, {{B::brow_down_right, 1.f}}},
  };
}

status make_impl(const builtin_avatar_options& options, builtin_avatar& out) {
  if (status s = options.validate(); !s) return s;
  out = builtin_avatar{};
  out.options = options;
  out.skeleton = make_proxy_skeleton(options.height);
  proxy_pose rest;
  rest.hips_position = glm::vec3(0.f, standing_hips_height(out.skeleton), 0.f);
  joint_world_positions(out.skeleton, rest, out.joints);

  out.materials = {{"skin", glm::vec4(k_skin_colour, 1.f), 0.7f},
                   {"shirt", glm::vec4(0.09f, 0.30f, 0.48f, 1.f), 0.85f},
                   {"trousers", glm::vec4(0.07f, 0.07f, 0.11f, 1.f), 0.9f},
                   {"shoes", glm::vec4(0.05f, 0.05f, 0.05f, 1.f), 0.5f},
                   {"face", glm::vec4(1.f), 0.7f}};

  body_parts body;
  add_torso(body, out);
  add_limbs(body, out, 1.f);
  add_limbs(body, out, -1.f);
  avatar_mesh body_mesh;
  body_mesh.name = "Body";
  body_mesh.primitives = {body.skin.finish(k_skin, false), body.shirt.finish(k_shirt, false),
                          body.trousers.finish(k_trousers, false),
                          body.shoes.finish(k_shoes, false)};

  avatar_mesh face_mesh;
  face_mesh.name = "Face";
  const mesh_builder neutral = build_face(out, face_params{});
  avatar_primitive face = neutral.finish(k_face, true);
  const std::array<face_params, k_blendshape_count> shapes = arkit_shapes();
  for (int t = 0; t < k_blendshape_count; ++t) {
    mesh_builder moved = build_face(out, shapes[static_cast<std::size_t>(t)]);
    std::vector<glm::vec3> delta(face.positions.size());
    for (std::size_t v = 0; v < delta.size(); ++v)
      delta[v] = moved.positions()[v] - face.positions[v];
    face.targets.push_back(std::move(delta));
    face_mesh.target_names.emplace_back(blendshape_name(static_cast<blendshape>(t)));
  }
  face_mesh.primitives = {std::move(face)};
  out.meshes = {std::move(body_mesh), std::move(face_mesh)};

  // The VRM expressions bind combinations of the ARKit targets (docs/avatar.md).
  for (const expression_recipe& r : expression_recipes()) {
    avatar_expression e{r.name, r.preset, {}};
    for (const auto& [shape, weight] : r.parts) e.binds.push_back({1, idx(shape), weight});
    out.expressions.push_back(std::move(e));
  }
  return {};
}

}  // namespace

status builtin_avatar_options::validate() const {
  if (!(height >= k_builtin_avatar_min_height && height <= k_builtin_avatar_max_height))
    return status::error("height must be in [" + seconds_text(k_builtin_avatar_min_height, 2) +
                         ", " + seconds_text(k_builtin_avatar_max_height, 2) + "] metres, got " +
                         seconds_text(height, 3));
  if (name.empty()) return status::error("name must not be empty (it is the VRM's meta.name)");
  return {};
}

status make_builtin_avatar(const builtin_avatar_options& options, builtin_avatar& out) {
  try {
    return make_impl(options, out);
  } catch (const std::bad_alloc&) {
    return status::out_of_memory("not enough memory to build the built-in avatar");
  }
}

}  // namespace avatarmap
