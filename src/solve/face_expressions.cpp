// ARKit's 52 -> the proxy's expressions. See include/avatarmap/solve/face_expressions.hpp.
#include "avatarmap/solve/face_expressions.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace avatarmap {
namespace {

float clamp01(float v) { return v > 0.f ? (v < 1.f ? v : 1.f) : 0.f; }  // NaN -> 0

using bs = blendshape;

constexpr std::pair<bs, bs> k_pairs[] = {
    {bs::brow_down_left, bs::brow_down_right},
    {bs::brow_outer_up_left, bs::brow_outer_up_right},
    {bs::cheek_squint_left, bs::cheek_squint_right},
    {bs::eye_blink_left, bs::eye_blink_right},
    {bs::eye_look_down_left, bs::eye_look_down_right},
    {bs::eye_look_in_left, bs::eye_look_in_right},
    {bs::eye_look_out_left, bs::eye_look_out_right},
    {bs::eye_look_up_left, bs::eye_look_up_right},
    {bs::eye_squint_left, bs::eye_squint_right},
    {bs::eye_wide_left, bs::eye_wide_right},
    {bs::jaw_left, bs::jaw_right},
    {bs::mouth_dimple_left, bs::mouth_dimple_right},
    {bs::mouth_frown_left, bs::mouth_frown_right},
    {bs::mouth_left, bs::mouth_right},
    {bs::mouth_lower_down_left, bs::mouth_lower_down_right},
    {bs::mouth_press_left, bs::mouth_press_right},
    {bs::mouth_smile_left, bs::mouth_smile_right},
    {bs::mouth_stretch_left, bs::mouth_stretch_right},
    {bs::mouth_upper_up_left, bs::mouth_upper_up_right},
    {bs::nose_sneer_left, bs::nose_sneer_right},
};

}  // namespace

void eye_look_blendshapes(bool person_left, float sin_yaw, float sin_pitch,
                          blendshape_weights& out) {
  const float side = clamp01(std::abs(sin_yaw) / k_eye_look_full_side_sin);
  const float vert = clamp01(std::abs(sin_pitch) / k_eye_look_full_vert_sin);
  const bool toward_left = sin_yaw > 0.f, up = sin_pitch > 0.f;
  // The left eye turning toward the person's left looks out; the right eye looks in.
  const bool out_turn = toward_left == person_left;
  out[idx(person_left ? bs::eye_look_out_left : bs::eye_look_out_right)] = out_turn ? side : 0.f;
  out[idx(person_left ? bs::eye_look_in_left : bs::eye_look_in_right)] = out_turn ? 0.f : side;
  out[idx(person_left ? bs::eye_look_up_left : bs::eye_look_up_right)] = up ? vert : 0.f;
  out[idx(person_left ? bs::eye_look_down_left : bs::eye_look_down_right)] = up ? 0.f : vert;
}

void expressions_from_blendshapes(const blendshape_weights& b, expression_weights& out) {
  auto w = [&](bs s) { return clamp01(b[idx(s)]); };
  auto mean = [&](bs l, bs r) { return 0.5f * (w(l) + w(r)); };
  out.fill(0.f);
  const float bl = w(bs::eye_blink_left), br = w(bs::eye_blink_right);
  const float both = std::min(bl, br);
  out[idx(expression::blink)] = both;
  out[idx(expression::blink_left)] = bl - both;
  out[idx(expression::blink_right)] = br - both;

  // The mouth's opening: the jaw's, less what mouthClose keeps the lips together.
  const float o = clamp01(w(bs::jaw_open) - w(bs::mouth_close));
  const float r = std::max(w(bs::mouth_funnel), w(bs::mouth_pucker));
  const float smile = mean(bs::mouth_smile_left, bs::mouth_smile_right);
  const float wide = std::max(mean(bs::mouth_stretch_left, bs::mouth_stretch_right), smile);
  out[idx(expression::aa)] = o * (1.f - r) * (1.f - wide);
  out[idx(expression::ee)] = wide * (1.f - r) * (1.f - o);
  out[idx(expression::ih)] = wide * (1.f - r) * o;
  out[idx(expression::oh)] = r * o;
  out[idx(expression::ou)] = r * (1.f - o);

  out[idx(expression::look_left)] = mean(bs::eye_look_out_left, bs::eye_look_in_right);
  out[idx(expression::look_right)] = mean(bs::eye_look_in_left, bs::eye_look_out_right);
  out[idx(expression::look_up)] = mean(bs::eye_look_up_left, bs::eye_look_up_right);
  out[idx(expression::look_down)] = mean(bs::eye_look_down_left, bs::eye_look_down_right);

  const float inner = w(bs::brow_inner_up);
  out[idx(expression::brow_up_left)] = std::max(inner, w(bs::brow_outer_up_left));
  out[idx(expression::brow_up_right)] = std::max(inner, w(bs::brow_outer_up_right));
  out[idx(expression::brow_down_left)] = w(bs::brow_down_left);
  out[idx(expression::brow_down_right)] = w(bs::brow_down_right);

  const float frown = mean(bs::mouth_frown_left, bs::mouth_frown_right);
  const float cheek = mean(bs::cheek_squint_left, bs::cheek_squint_right);
  const float down = mean(bs::brow_down_left, bs::brow_down_right);
  const float eyes_wide = mean(bs::eye_wide_left, bs::eye_wide_right);
  const float up = std::max(inner, mean(bs::brow_outer_up_left, bs::brow_outer_up_right));
  out[idx(expression::happy)] = clamp01(smile * (0.6f + 0.4f * cheek));
  out[idx(expression::relaxed)] = clamp01(0.6f * smile * (1.f - cheek) * (1.f - o));
  out[idx(expression::angry)] = clamp01(down * (1.f - smile));
  out[idx(expression::sad)] = clamp01(frown * (0.6f + 0.4f * inner) * (1.f - smile));
  out[idx(expression::surprised)] = clamp01(up * std::max(eyes_wide, o));
}

void mirror_blendshapes(blendshape_weights& b) {
  for (const auto& [l, r] : k_pairs) std::swap(b[idx(l)], b[idx(r)]);
}

}  // namespace avatarmap
