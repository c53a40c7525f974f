// Options of the landmark -> proxy pose solver (frame_solver). Every field has a default
// that works for a non-mirrored camera; k_solver_option_table declares each field's range and
// help once (core/option_table.hpp): validate(), the CLI's flags and the C API's checks come
// from it.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include "avatarmap/core/option_table.hpp"
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

/// Where the lower body is held while the body's points are not a person's or the legs are not
/// seen (solve/body_plausibility.hpp; docs/solver.md, "Bodies that are not followed").
enum class body_rest : int {
  standing = 0,  ///< hips upright at rest_hips_height, legs straight down
  sitting = 1,   ///< thighs forward, shins down, hips at 0.52 rest_hips_height
  off = 2,       ///< never held: every measured body is followed (before 0.1.0's rule)
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
  /// Fit the body's metric points to its image points through the camera (docs/solver.md,
  /// "The body in the world"): segments turn in depth as their foreshortening says, with the
  /// lengths learnt over the take, and the body is turned upright by the camera's pitch and
  /// roll learnt from the standing body. Needs image_width/height; false = BlazePose's world
  /// points as they are (they lean toward the camera) in the camera's axes.
  bool fit_body_to_image = true;
  /// The rest the lower body (hips, legs, feet, root) is held at on frames whose body is not
  /// plausible (legs above the hips, a torso larger than the image, bones no person has) or
  /// whose lower body is not seen (a desk webcam's framing), decided with a few frames of
  /// hysteresis; the arms (when the torso is plausible), hands and face keep driving.
  body_rest lower_body_rest = body_rest::standing;

  /// Checks every field against k_solver_option_table (the message names the field and its
  /// range), then image_width and image_height both given or neither, and lost_below <=
  /// found_above.
  status validate() const;
};

/// The solver's options, one row per field, in the order (and with the names) of
/// avm_solver_options' solver fields.
inline constexpr option_row<solver_options> k_solver_option_table[] = {
    option_row<solver_options>("mirror", AVATARMAP_OPTION_FIELD(solver_options, mirror))
        .boolean()
        .cli("--mirror")
        .help("mirror the performer: swap left and right and flip X (mirrored webcam "
              "recordings)"),
    option_row<solver_options>("image_width", AVATARMAP_OPTION_FIELD(solver_options, image_width))
        .number(0, std::numeric_limits<double>::infinity())
        .help("image width in pixels; 0 = unknown (square pixels assumed)"),
    option_row<solver_options>("image_height", AVATARMAP_OPTION_FIELD(solver_options, image_height))
        .number(0, std::numeric_limits<double>::infinity())
        .help("image height in pixels; 0 = unknown"),
    option_row<solver_options>("solve_body", AVATARMAP_OPTION_FIELD(solver_options, parts.body))
        .boolean()
        .help("solve the body (hips, spine, arms, legs)"),
    option_row<solver_options>("solve_hands", AVATARMAP_OPTION_FIELD(solver_options, parts.hands))
        .boolean()
        .help("solve the wrists and fingers"),
    option_row<solver_options>("solve_face", AVATARMAP_OPTION_FIELD(solver_options, parts.face))
        .boolean()
        .help("solve the neck, head, eyes and expressions"),
    option_row<solver_options>("solve_hips_translation",
                               AVATARMAP_OPTION_FIELD(solver_options, parts.hips_translation))
        .boolean()
        .help("move the hips (root motion)"),
    option_row<solver_options>("confidence_lost_below",
                               AVATARMAP_OPTION_FIELD(solver_options, confidence.lost_below))
        .number(0, 1)
        .help("a bone is lost when its confidence falls below this"),
    option_row<solver_options>("confidence_found_above",
                               AVATARMAP_OPTION_FIELD(solver_options, confidence.found_above))
        .number(0, 1)
        .help("a lost bone is found again above this (>= confidence_lost_below)"),
    option_row<solver_options>("confidence_hold_seconds",
                               AVATARMAP_OPTION_FIELD(solver_options, confidence.hold_seconds))
        .number(0, std::numeric_limits<double>::infinity())
        .help("seconds a lost bone holds its last good rotation"),
    option_row<solver_options>("confidence_ease_seconds",
                               AVATARMAP_OPTION_FIELD(solver_options, confidence.ease_seconds))
        .number(0, std::numeric_limits<double>::infinity())
        .help("seconds a lost bone then eases to rest"),
    option_row<solver_options>("confidence_regain_seconds",
                               AVATARMAP_OPTION_FIELD(solver_options, confidence.regain_seconds))
        .number(0, std::numeric_limits<double>::infinity())
        .help("seconds a found bone blends back to the measurement"),
    option_row<solver_options>("hips_lean_share",
                               AVATARMAP_OPTION_FIELD(solver_options, hips_lean_share))
        .number(0, 1)
        .help("share of the torso's lean given to the hips"),
    option_row<solver_options>("forearm_twist_share",
                               AVATARMAP_OPTION_FIELD(solver_options, forearm_twist_share))
        .number(0, 1)
        .help("share of the wrist's twist moved to the lower arm"),
    option_row<solver_options>("horizontal_fov_degrees",
                               AVATARMAP_OPTION_FIELD(solver_options, horizontal_fov_degrees))
        .number(1, 179, true, true)
        .or_zero()
        .cli("--fov", "DEG")
        .help("camera's horizontal field of view (head under perspective, root motion); 0: "
              "estimated from the pose's image and world points when they form one pinhole "
              "view, else 60"),
    option_row<solver_options>("rest_hips_height",
                               AVATARMAP_OPTION_FIELD(solver_options, rest_hips_height))
        .number(0, 10, true, true)
        .help("hips height while the legs have never been seen (metres)"),
    option_row<solver_options>("fit_hand_shape",
                               AVATARMAP_OPTION_FIELD(solver_options, fit_hand_shape))
        .boolean()
        .cli(nullptr, nullptr, "--no-hand-fit")
        .help("--no-hand-fit: use the hand landmarks as they are (default: each hand's points "
              "fitted to its shape learnt over the take, a rigid palm and fingers of constant "
              "length; docs/solver.md)"),
    option_row<solver_options>("fit_body_to_image",
                               AVATARMAP_OPTION_FIELD(solver_options, fit_body_to_image))
        .boolean()
        .cli(nullptr, nullptr, "--no-body-fit")
        .help("--no-body-fit: use the pose's world points as they are, in the camera's axes "
              "(default: the body fitted to the image points through the camera, with the "
              "take's bone lengths, and turned upright by the camera's pitch and roll; "
              "docs/solver.md)"),
    option_row<solver_options>("lower_body_rest",
                               AVATARMAP_OPTION_FIELD(solver_options, lower_body_rest))
        .choices("standing|sitting|off")
        .cli("--lower-body-rest")
        .help("where the hips and legs are held while the body's points are not a person's "
              "(legs above the hips, a torso larger than the image, impossible bone lengths) "
              "or the legs are not seen (upper-body framing): standing, sitting, or off "
              "(always follow them); arms, hands and face still drive (docs/solver.md)"),
};

inline status solver_options::validate() const {
  if (status st = check_options(k_solver_option_table, *this, ""); !st.ok()) return st;
  if ((image_width > 0.f) != (image_height > 0.f))
    return status::error("give both image_width and image_height, or neither");
  if (confidence.found_above < confidence.lost_below)
    return status::error("confidence thresholds must satisfy 0 <= lost_below <= found_above <= 1");
  return {};
}

}  // namespace avatarmap
