// Options of the landmark -> proxy pose solver (frame_solver). Every field has a default
// that works for a non-mirrored camera; validate() names any field out of range.
#pragma once

#include <cmath>
#include <string>

#include "avatarmap/core/status.hpp"

namespace avatarmap {

/// Which parts of the proxy pose to solve. A part that is off keeps its bones at rest
/// (identity) and its expressions at 0.
struct solve_parts {
  bool body = true;              // hips, spine chain, shoulders, arms, legs, feet
  bool hands = true;             // wrists' orientation and all finger bones
  bool face = true;              // neck and head, eyes, expressions
  bool hips_translation = true;  // hips_position (else it stays at X = Z = 0, rest height)
};

/// How confidence (min of a landmark's visibility and presence) gates each bone.
/// A bone is lost when its confidence falls below `lost_below` and found again only when it
/// rises above `found_above` (hysteresis). A lost bone holds its last good rotation for
/// `hold_seconds`, then eases to rest (identity) over `ease_seconds` (smoothstep). A found
/// bone blends from where it was to the measurement over `regain_seconds`. Nothing snaps.
struct confidence_options {
  float lost_below = 0.3f;
  float found_above = 0.5f;
  float hold_seconds = 0.5f;
  float ease_seconds = 1.0f;
  float regain_seconds = 0.15f;
};

struct solver_options {
  /// Mirror the performer: swap left and right and flip X (for mirrored webcam previews).
  bool mirror = false;
  /// Size of the captured image in pixels; image landmarks are scaled by it so that angles
  /// and ratios hold for any aspect ratio. 0 = unknown: square (1:1) pixels are assumed.
  float image_width = 0.f;
  float image_height = 0.f;
  solve_parts parts{};
  confidence_options confidence{};
  /// Share (0..1) of the torso's forward/back lean given to the hips; the rest goes to the
  /// spine chain. Observed bone directions do not depend on it.
  float hips_lean_share = 0.5f;
  /// Share (0..1) of the wrist's twist about the forearm moved from the hand to the lower arm
  /// (the forearm's radius and ulna do most of the turning).
  float forearm_twist_share = 0.6f;
  /// Horizontal field of view of the camera in degrees: it undoes the perspective of a face
  /// seen off the optical axis (the head's rotation) and turns the person's image scale into
  /// depth (hips_position X/Z). 0 (the default) = unknown: estimated over the take from the
  /// pose's image and world points (needs image_width/height; 60 degrees until the pose has
  /// told better, and without a size or world points).
  float horizontal_fov_degrees = 0.f;
  /// Hips height used while the legs have never been seen (metres).
  float rest_hips_height = 0.95f;
  /// Fit each hand's metric landmarks to that hand's shape, learnt over the take: a rigid
  /// palm and fingers of constant length (hand_shape.hpp; docs/solver.md "The hand's shape").
  /// Takes a third of the landmark noise's effect off the fingers and changes nothing on exact
  /// landmarks. false = the hand landmarks as they are.
  bool fit_hand_shape = true;

  status validate() const {
    auto bad01 = [](float v) { return !(v >= 0.f && v <= 1.f); };
    if (!(image_width >= 0.f) || !(image_height >= 0.f) || !std::isfinite(image_width) ||
        !std::isfinite(image_height))
      return status::error("image_width/image_height must be finite and >= 0 (0 = unknown)");
    if ((image_width > 0.f) != (image_height > 0.f))
      return status::error("give both image_width and image_height, or neither");
    if (bad01(confidence.lost_below) || bad01(confidence.found_above) ||
        confidence.found_above < confidence.lost_below)
      return status::error(
          "confidence thresholds must satisfy 0 <= lost_below <= found_above <= 1");
    if (!(confidence.hold_seconds >= 0.f) || !(confidence.ease_seconds >= 0.f) ||
        !(confidence.regain_seconds >= 0.f) || !std::isfinite(confidence.hold_seconds) ||
        !std::isfinite(confidence.ease_seconds) || !std::isfinite(confidence.regain_seconds))
      return status::error("confidence hold/ease/regain seconds must be finite and >= 0");
    if (bad01(hips_lean_share)) return status::error("hips_lean_share must be in [0, 1]");
    if (bad01(forearm_twist_share)) return status::error("forearm_twist_share must be in [0, 1]");
    if (!(horizontal_fov_degrees == 0.f ||
          (horizontal_fov_degrees > 1.f && horizontal_fov_degrees < 179.f)))
      return status::error("horizontal_fov_degrees must be 0 (estimate) or in (1, 179)");
    if (!(rest_hips_height > 0.f && rest_hips_height < 10.f))
      return status::error("rest_hips_height must be in (0, 10) metres");
    return {};
  }
};

}  // namespace avatarmap
