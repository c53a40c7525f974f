// The confidence gate on its own (include/avatarmap/solve/confidence_gate.hpp), driven with
// confidence sequences at irregular times. Every expected value is worked out by hand here
// from the documented rules (docs/solver.md, "Confidence over time"): lost below 0.3, found
// at 0.5 and above; hold 0.5 s, then ease to rest over 1 s; blend back in over 0.15 s; the
// curves are smoothstep 3p^2 - 2p^3, so p = 1/4 -> 5/32, 1/2 -> 1/2, 3/4 -> 27/32.
#include "avatarmap/solve/confidence_gate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace avatarmap {
namespace {

constexpr float k_nan = std::numeric_limits<float>::quiet_NaN();
constexpr float k_deg = k_pi / 180.f;

// Defaults spelled out, so that the test does not move if the defaults do.
confidence_options documented() {
  confidence_options o;
  o.lost_below = 0.3f;
  o.found_above = 0.5f;
  o.hold_seconds = 0.5f;
  o.ease_seconds = 1.0f;
  o.regain_seconds = 0.15f;
  return o;
}

TEST(confidence_gate, hysteresis_enters_at_found_above_and_leaves_below_lost_below) {
  const confidence_options o = documented();
  gate_state s;
  struct step {
    double t;
    float c;
    gate_change change;
    bool tracked;
  };
  const step steps[] = {
      {0.00, 0.49f, gate_change::none, false},        // below found_above: not found
      {0.04, 0.50f, gate_change::found, true},        // found_above itself enters
      {0.05, 0.31f, gate_change::none, true},         // between the thresholds: stays
      {0.11, 0.30f, gate_change::none, true},         // lost_below itself does not leave
      {0.12, 0.299f, gate_change::lost, false},       // below it leaves
      {0.30, 0.45f, gate_change::none, false},        // between the thresholds: stays lost
      {0.31, 0.30f, gate_change::none, false},        //
      {0.70, 0.51f, gate_change::found_again, true},  // found again (not the first time)
      {0.71, 0.00f, gate_change::lost, false},        // 0 = not seen
  };
  for (const step& st : steps) {
    SCOPED_TRACE(testing::Message() << "t = " << st.t << ", c = " << st.c);
    EXPECT_EQ(update_gate(s, st.c, st.t, o), st.change);
    EXPECT_EQ(s.tracked, st.tracked);
  }
  EXPECT_TRUE(s.ever_tracked);
  EXPECT_DOUBLE_EQ(s.found_at, 0.70);
  EXPECT_DOUBLE_EQ(s.lost_at, 0.71);
}

TEST(confidence_gate, nan_and_non_positive_confidence_are_missing) {
  // Thresholds at 0: only "some confidence" separates seen from not seen.
  confidence_options o = documented();
  o.lost_below = 0.f;
  o.found_above = 0.f;
  gate_state s;
  EXPECT_EQ(update_gate(s, k_nan, 0.0, o), gate_change::none);
  EXPECT_EQ(update_gate(s, 0.f, 0.1, o), gate_change::none);
  EXPECT_EQ(update_gate(s, -1.f, 0.2, o), gate_change::none);
  EXPECT_FALSE(s.ever_tracked);
  EXPECT_EQ(update_gate(s, 1e-6f, 0.3, o), gate_change::found);
  EXPECT_EQ(update_gate(s, k_nan, 0.4, o), gate_change::lost);
  EXPECT_DOUBLE_EQ(s.lost_at, 0.4);
  EXPECT_EQ(update_gate(s, 1e-6f, 0.5, o), gate_change::found_again);
  EXPECT_EQ(update_gate(s, -0.5f, 0.6, o), gate_change::lost);
  // With the documented thresholds a NaN never enters either.
  gate_state d;
  EXPECT_EQ(update_gate(d, k_nan, 0.0, documented()), gate_change::none);
  EXPECT_FALSE(d.tracked);
}

TEST(confidence_gate, hold_then_ease_known_answers) {
  const confidence_options o = documented();
  struct point {
    double age;
    float progress, weight;
  };
  const point points[] = {
      {0.0, 0.f, 0.f},         {0.3, 0.f, 0.f},   {0.5, 0.f, 0.f},  // the hold includes its end
      {0.75, 0.25f, 5.f / 32}, {1.0, 0.5f, 0.5f}, {1.25, 0.75f, 27.f / 32},
      {1.5, 1.f, 1.f},  // hold + ease: at rest
      {7.0, 1.f, 1.f},
  };
  for (const point& p : points) {
    SCOPED_TRACE(testing::Message() << "seconds lost = " << p.age);
    const gate_ramp r = hold_and_ease(p.age, o);
    EXPECT_NEAR(r.progress, p.progress, 1e-6f);
    EXPECT_NEAR(r.weight, p.weight, 1e-6f);
  }
  // No ease: straight to rest once the hold is over; no hold: easing from the start.
  confidence_options snap = o;
  snap.ease_seconds = 0.f;
  EXPECT_EQ(hold_and_ease(0.5, snap).weight, 0.f);
  EXPECT_EQ(hold_and_ease(0.5001, snap).weight, 1.f);
  confidence_options no_hold = o;
  no_hold.hold_seconds = 0.f;
  EXPECT_NEAR(hold_and_ease(0.5, no_hold).weight, 0.5f, 1e-6f);
}

TEST(confidence_gate, blend_in_known_answers) {
  const confidence_options o = documented();
  EXPECT_EQ(blend_in(0.0, o).weight, 0.f);
  EXPECT_NEAR(blend_in(0.0375, o).weight, 5.f / 32, 1e-6f);
  EXPECT_NEAR(blend_in(0.075, o).weight, 0.5f, 1e-6f);
  EXPECT_NEAR(blend_in(0.1125, o).weight, 27.f / 32, 1e-6f);
  EXPECT_EQ(blend_in(0.16, o).progress, 1.f);
  EXPECT_EQ(blend_in(0.4, o).weight, 1.f);
  confidence_options eighth = o;
  eighth.regain_seconds = 0.125f;  // exact in binary: the end itself is done
  EXPECT_EQ(blend_in(0.125, eighth).progress, 1.f);
  EXPECT_LT(blend_in(0.124, eighth).progress, 1.f);
  confidence_options snap = o;
  snap.regain_seconds = 0.f;
  EXPECT_EQ(blend_in(0.0, snap).progress, 1.f);
}

// Angle (degrees) and axis of a unit quaternion, for the checks below.
float angle_deg(const glm::quat& q) {
  return 2.f * std::acos(std::min(1.f, std::abs(q.w))) / k_deg;
}
float axis_component(const glm::quat& q, int i) {
  const glm::vec3 v(q.x, q.y, q.z);
  const float n = glm::length(v);
  return n > 0.f ? (q.w < 0.f ? -v[i] : v[i]) / n : 0.f;
}

// Times where a boundary is tested are binary fractions, so that "0.5 s later" is exact.
TEST(confidence_gate, rotation_holds_eases_and_blends_back_at_irregular_times) {
  const confidence_options o = documented();
  const glm::quat a = axis_angle(glm::vec3(0.f, 0.f, 1.f), 90.f * k_deg);
  const glm::quat b = axis_angle(glm::vec3(1.f, 0.f, 0.f), 60.f * k_deg);
  rotation_gate g;
  int measured_calls = 0;
  auto feed = [&](double t, float c, const glm::quat& m) {
    return g.update(c, t, o, [&] {
      ++measured_calls;
      return m;
    });
  };
  // Never seen: rest, and the measurement is not even computed.
  EXPECT_EQ(feed(0.0, 0.2f, a), identity_quat());
  EXPECT_EQ(measured_calls, 0);
  // First found: shown at once, no blend.
  EXPECT_EQ(feed(0.03125, 0.9f, a), a);
  EXPECT_EQ(measured_calls, 1);
  // Lost at t = 0.125: held for 0.5 s (inclusive), measurement not computed meanwhile.
  EXPECT_EQ(feed(0.125, 0.1f, b), a);
  EXPECT_EQ(feed(0.4, 0.f, b), a);
  EXPECT_EQ(feed(0.625, 0.2f, b), a);
  EXPECT_EQ(measured_calls, 1);
  // Easing along the 90-degree turn about Z: p = 0.5 -> 45 degrees left, p = 0.75 -> 90 * 5/32.
  glm::quat q = feed(1.125, k_nan, b);
  EXPECT_NEAR(angle_deg(q), 45.f, 1e-3f);
  EXPECT_NEAR(axis_component(q, 2), 1.f, 1e-5f);
  EXPECT_NEAR(angle_deg(feed(1.375, 0.4f, b)), 90.f * 5.f / 32.f, 1e-3f);
  // At hold + ease (t = 1.625) and after: rest exactly.
  EXPECT_EQ(feed(1.625, 0.f, b), identity_quat());
  EXPECT_EQ(feed(1.9, 0.f, b), identity_quat());
  EXPECT_FALSE(g.gate.tracked);
  // Found again at t = 2: blends from rest to the 60-degree turn about X over 0.15 s.
  EXPECT_LT(std::abs(feed(2.0, 0.6f, b).w - 1.f), 1e-6f);
  q = feed(2.075, 0.6f, b);
  EXPECT_NEAR(angle_deg(q), 30.f, 1e-3f);
  EXPECT_NEAR(axis_component(q, 0), 1.f, 1e-5f);
  EXPECT_NEAR(angle_deg(feed(2.1125, 0.35f, b)), 60.f * 27.f / 32.f, 1e-3f);  // still tracked
  EXPECT_EQ(feed(2.16, 0.6f, b), b);                                          // blend over
  EXPECT_FALSE(g.blending);
  EXPECT_EQ(measured_calls, 1 + 4);
}

TEST(confidence_gate, lost_mid_blend_holds_what_was_shown) {
  const confidence_options o = documented();
  const glm::quat a = axis_angle(glm::vec3(0.f, 1.f, 0.f), 80.f * k_deg);
  rotation_gate g;
  auto feed = [&](double t, float c) { return g.update(c, t, o, [&] { return a; }); };
  feed(0.0, 1.f);                              // found: a
  feed(0.125, 0.f);                            // lost
  EXPECT_EQ(feed(3.0, 0.f), identity_quat());  // one late frame: past hold + ease at once
  feed(3.0, 1.f);                              // found again: blends in from rest
  const glm::quat mid = feed(3.075, 1.f);
  EXPECT_NEAR(angle_deg(mid), 40.f, 1e-3f);
  // Lost half-way in: the 40 degrees shown are held (no jump to the old 80 or to rest).
  EXPECT_EQ(feed(3.125, 0.1f), mid);
  EXPECT_EQ(feed(3.625, 0.1f), mid);
  EXPECT_NEAR(angle_deg(feed(4.125, 0.1f)), 20.f, 1e-3f);  // half-way to rest
}

TEST(confidence_gate, no_regain_time_shows_the_measurement_at_once) {
  confidence_options o = documented();
  o.regain_seconds = 0.f;
  const glm::quat a = axis_angle(glm::vec3(0.f, 1.f, 0.f), 50.f * k_deg);
  rotation_gate g;
  auto feed = [&](double t, float c) { return g.update(c, t, o, [&] { return a; }); };
  feed(0.0, 1.f);
  feed(0.1, 0.f);
  feed(5.0, 0.f);  // at rest
  EXPECT_EQ(feed(5.1, 1.f), a);
  EXPECT_FALSE(g.blending);
}

}  // namespace
}  // namespace avatarmap
