// Face expressions the proxy pose carries: VRM 1.0 preset names where VRM has one, plus four
// custom brow expressions. Weights are in [0, 1]. "left" is the person's (= avatar's) left.
// The solver derives them from ARKit's 52 blendshapes (skeleton/blendshape.hpp), which the
// proxy pose carries too; docs/expressions.md gives each derivation.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace avatarmap {

enum class expression : std::uint8_t {
  blink,        // both eyes: min(left, right) closure
  blink_left,   // left eye's closure beyond `blink` (so blink + blinkLeft = left closure)
  blink_right,  // right eye's closure beyond `blink`
  aa,
  ih,
  ou,
  ee,
  oh,
  look_up,
  look_down,
  look_left,  // gaze toward the avatar's left
  look_right,
  brow_up_left,  // custom (not a VRM preset): raised left brow
  brow_up_right,
  brow_down_left,  // custom: lowered (frowning) left brow
  brow_down_right,
  happy,  // VRM 1.0 emotion presets (appended in 0.2.0)
  angry,
  sad,
  relaxed,
  surprised,
};

inline constexpr int k_expression_count = 21;

namespace detail {
inline constexpr std::array<std::string_view, k_expression_count> k_expression_names = {
    "blink",      "blinkLeft",   "blinkRight",   "aa",
    "ih",         "ou",          "ee",           "oh",
    "lookUp",     "lookDown",    "lookLeft",     "lookRight",
    "browUpLeft", "browUpRight", "browDownLeft", "browDownRight",
    "happy",      "angry",       "sad",          "relaxed",
    "surprised"};
}

constexpr int idx(expression e) { return static_cast<int>(e); }

/// Name as written in *.pose.jsonl ("blink", "blinkLeft", "aa", ...).
constexpr std::string_view expression_name(expression e) {
  return detail::k_expression_names[idx(e)];
}

inline std::optional<expression> expression_from_name(std::string_view name) {
  for (int i = 0; i < k_expression_count; ++i)
    if (detail::k_expression_names[i] == name) return static_cast<expression>(i);
  return std::nullopt;
}

}  // namespace avatarmap
