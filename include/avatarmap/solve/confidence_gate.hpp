// The solver's confidence gate: how a measurement with a per-frame confidence in [0, 1]
// becomes what is shown. One hysteresis (update_gate), one hold-then-ease to rest
// (hold_and_ease) and one blend back in (blend_in), used by every gated part of the solver:
// each bone's rotation (rotation_gate), the hips height and ground point, the expressions.
// Times are seconds of capture time; options come from solver_options::confidence and must
// satisfy its validate(). Everything here is inline, allocation-free and has no hidden state.
// See docs/solver.md, "Confidence over time".
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/solve/solver_options.hpp"

namespace avatarmap {

/// Hysteresis state of one gated signal. A default-constructed state has never been tracked.
struct gate_state {
  bool tracked = false;       // the measurement is shown
  bool ever_tracked = false;  // tracked at least once since construction / reset
  double lost_at = 0.0;       // capture time (s) when tracking was last lost
  double found_at = 0.0;      // capture time (s) when tracking was last gained
};

/// What update_gate did this frame.
enum class gate_change : unsigned char {
  none,         // no change
  lost,         // was tracked, is not any more (lost_at = t)
  found,        // tracked for the first time (found_at = t)
  found_again,  // tracked again after being lost (found_at = t)
};

/// The one hysteresis of the solver: a tracked signal is lost when `confidence` is below
/// `o.lost_below` or not above 0; an untracked one is found when `confidence` is at least
/// `o.found_above` and above 0. A NaN confidence counts as missing (never found, always
/// lost), so a signal with thresholds at 0 still needs some confidence.
inline gate_change update_gate(gate_state& s, float confidence, double t,
                               const confidence_options& o) {
  const bool seen = confidence > 0.f;  // false for NaN too
  if (s.tracked) {
    if (!seen || confidence < o.lost_below) {
      s.tracked = false;
      s.lost_at = t;
      return gate_change::lost;
    }
  } else if (seen && confidence >= o.found_above) {
    const bool again = s.ever_tracked;
    s.tracked = true;
    s.ever_tracked = true;
    s.found_at = t;
    return again ? gate_change::found_again : gate_change::found;
  }
  return gate_change::none;
}

/// Progress of a timed transition: `progress` is linear in time from 0 to 1 (1 = finished);
/// `weight` is its smoothstep 3p^2 - 2p^3, the share to show of where the transition goes.
struct gate_ramp {
  float progress = 0.f;
  float weight = 0.f;
};

/// Smoothstep of x clamped to [0, 1]: 0 and 1 with zero slope at both ends (nothing snaps).
inline float smooth01(float x) {
  x = glm::clamp(x, 0.f, 1.f);
  return x * x * (3.f - 2.f * x);
}

/// The one hold-then-ease of the solver, `seconds_lost` after a signal was lost: held (progress
/// 0) up to and including `o.hold_seconds`, then easing to rest over `o.ease_seconds`
/// (progress 1 at hold + ease; at once when ease_seconds is 0). Callers show
/// mix(last good value, rest value, weight).
inline gate_ramp hold_and_ease(double seconds_lost, const confidence_options& o) {
  if (seconds_lost <= o.hold_seconds) return {0.f, 0.f};
  if (!(o.ease_seconds > 0.f)) return {1.f, 1.f};
  const float p = float(seconds_lost - o.hold_seconds) * (1.f / o.ease_seconds);
  return p >= 1.f ? gate_ramp{1.f, 1.f} : gate_ramp{p, smooth01(p)};
}

/// The one blend back in, `seconds_found` after a lost signal was found again: from what was
/// shown to the measurement over `o.regain_seconds` (progress 1 at once when it is 0). Callers
/// show mix(value shown when found, measurement, weight).
inline gate_ramp blend_in(double seconds_found, const confidence_options& o) {
  if (!(o.regain_seconds > 0.f)) return {1.f, 1.f};
  const float p = float(seconds_found) * (1.f / o.regain_seconds);
  return p >= 1.f ? gate_ramp{1.f, 1.f} : gate_ramp{p, smooth01(p)};
}

/// One rotation behind the gate (the solver keeps one per bone): while tracked it shows the
/// measurement, blended in from what it showed when it was found again; while lost it holds
/// what it showed last, then eases to rest (identity) by slerp. Rotations are unit
/// quaternions in whatever space the caller uses (the solver: local to the parent bone).
struct rotation_gate {
  gate_state gate;
  bool blending = false;                      // blending in after being found again
  glm::quat output{1.f, 0.f, 0.f, 0.f};       // what is shown
  glm::quat last_good{1.f, 0.f, 0.f, 0.f};    // held while lost: output when lost
  glm::quat regain_from{1.f, 0.f, 0.f, 0.f};  // output when found again

  /// Feeds one frame: `confidence` of the measurement at capture time `t`; `measured()`
  /// returns the measured rotation and is called only when it is shown (tracked), so a
  /// costly measurement is never computed for nothing. Returns the rotation to show.
  template <class Measured>
  const glm::quat& update(float confidence, double t, const confidence_options& o,
                          Measured&& measured) {
    switch (update_gate(gate, confidence, t, o)) {
      case gate_change::lost:
        last_good = output;  // what was last shown: continuous even mid-blend
        break;
      case gate_change::found:
        blending = false;
        regain_from = output;
        break;
      case gate_change::found_again:
        blending = o.regain_seconds > 0.f;
        regain_from = output;
        break;
      case gate_change::none:
        break;
    }
    if (gate.tracked) {
      const glm::quat m = measured();
      output = m;
      if (blending) {
        const gate_ramp r = blend_in(t - gate.found_at, o);
        if (r.progress < 1.f)
          output = slerp_shortest(regain_from, m, r.weight);
        else
          blending = false;
      }
    } else if (gate.ever_tracked) {
      const gate_ramp r = hold_and_ease(t - gate.lost_at, o);
      output = r.progress <= 0.f   ? last_good
               : r.progress >= 1.f ? identity_quat()
                                   : slerp_shortest(last_good, identity_quat(), r.weight);
    }
    return output;
  }
};

}  // namespace avatarmap
